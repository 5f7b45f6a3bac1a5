"""The light view from meshes: soft shadow maps against Mitsuba, and the
rasterizer seen through its depth maps."""
