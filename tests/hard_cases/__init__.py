"""Hard cases of issue 4: geometry near the method's singularities, bad
input, properties over random scenes. One theme per file."""
