"""``python -m rtmu``: the same as the ``rtmu`` command."""

from rtmu.cli import main

raise SystemExit(main())
