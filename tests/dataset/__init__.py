"""The dataset command (softshadow.dataset): determinism, resume, Dask, and
faults."""
