"""Per-method behaviour (softshadow.methods): the typed configs and capabilities,
then one file per method family or option (ssm's closed form, bitmask and its
gaps, exact, layers, the hierarchy, Auto's planner, shadow mapping and
Smoothies)."""
