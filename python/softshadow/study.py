"""``python -m softshadow.study``: the study (``softshadow.experiments.study``).

What accuracy costs in time, in light view and eye view, for every method
family against Mitsuba, and the papers' experiments; see that module.
"""

import sys

from .experiments.study import main

if __name__ == "__main__":
    sys.exit(main())
