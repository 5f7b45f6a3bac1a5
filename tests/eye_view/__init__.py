"""The eye view (softshadow.render): the camera, the images against Mitsuba and
by their properties, the shaded images."""
