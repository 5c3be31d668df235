"""``python -m bench.fixed_limits ARGS…``: ``rtmu ARGS…`` with the fixed link limits RTMU had before
it learned them (``rtmu.client.link_timing.LEARNING`` off): the baseline the link benches compare."""

from __future__ import annotations

import sys

from rtmu.client import link_timing

link_timing.LEARNING = False

from rtmu.cli import main  # noqa: E402

if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
