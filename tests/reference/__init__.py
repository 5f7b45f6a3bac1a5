"""The Mitsuba references (softshadow.reference) and the metrics
(softshadow.metrics)."""
