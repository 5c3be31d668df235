"""``python -m rtmu.guardian``: started by :class:`rtmu.guardian.handle.GuardianHandle`, not by hand."""

import sys

from .child import main

sys.exit(main())
