"""``python -m softshadow.dataset``: the ``softshadow-dataset`` command."""

from .cli import main

raise SystemExit(main())
