"""Research commands: the study, the FP16 experiment and the demo.

These are scripts run as ``python -m softshadow.experiments.<name>``, not the
library API: nothing here is re-exported by ``softshadow``, ``import
softshadow`` never imports this package, and their options and output may
change between releases.

``study``
    What accuracy costs in time, in light view and eye view, and the papers'
    experiments, against Mitsuba references (``python -m softshadow.experiments.study``;
    needs the ``reference`` and ``study`` extras).
``eye_plane``, ``scherzer``
    The study's eye-view measurements (every family against Mitsuba's whole
    eye-view job; Scherzer 2005's bias, aliasing and blur experiments and
    Smoothies' width), shared with ``benchmarks/bench_eye.py`` and
    ``benchmarks/bench_shadow_mapping.py``.
``fp16``
    The paper's FP16 study, Figure 14 and Appendix A
    (``python -m softshadow.experiments.fp16``; needs nothing extra).
``demo``
    The main job: the bunny's soft shadow map, its timings and its error
    against Mitsuba (``python -m softshadow.experiments.demo``; needs the
    ``io`` extra, and ``reference`` for the error).
"""
