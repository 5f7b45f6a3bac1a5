"""Mitsuba 3's ``perspective`` sensor for a :class:`softshadow.Camera`.

The camera's conventions (``src/geom/camera.rs``) are Mitsuba's with
``fov_axis="y"`` and ``look_at(origin=eye, target=eye + forward, up)``. A
principal point off the image's centre becomes Mitsuba's
``principal_point_offset_x/y``, fractions of the film's width and height
with the opposite sign: OpenCV's ``cx`` sits ``cx - (W - 1)/2`` pixels right
of the centre, which is an offset of ``((W - 1)/2 - cx)/W`` in Mitsuba's
terms (its offset moves the image, not the principal point; measured
against ``sensor.sample_ray`` in tests/eye_view/test_camera.py). The film samples pixel centres (a box
filter, a stratified sampler without jitter, float32 output), so
``sensor.sample_ray`` at ``((i + 1/2)/W, (j + 1/2)/H)`` is the ray through
pixel ``[j, i]``.
"""

from __future__ import annotations

from typing import Any

from ._mitsuba import _mitsuba


def camera_sensor(camera: Any, *, samples: int = 1) -> dict[str, Any]:
    """The sensor dict (for ``mi.load_dict``) of ``camera``, ``samples``
    per pixel."""
    mi, _ = _mitsuba()
    w, h = camera.resolution
    k = camera.K
    eye = [float(c) for c in camera.eye]
    target = [e + float(f) for e, f in zip(eye, camera.forward, strict=True)]
    return {
        "type": "perspective",
        "fov": float(camera.fov_y),
        "fov_axis": "y",
        "principal_point_offset_x": float(((w - 1) / 2 - k[0, 2]) / w),
        "principal_point_offset_y": float(((h - 1) / 2 - k[1, 2]) / h),
        "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=[float(c) for c in camera.up]),
        "sampler": {"type": "stratified", "sample_count": samples, "jitter": False},
        "film": {
            "type": "hdrfilm",
            "width": w,
            "height": h,
            "rfilter": {"type": "box"},
            "component_format": "float32",
        },
    }
