"""``rtmu --robots N`` belongs to ``--demo``; ``--central`` needs a HOST[:PORT] and no ``--host``/``--demo``.

Alone, or with an impossible value, each is a usage error (exit 2).
"""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--robots", "2"], "--robots N goes with --demo"),
        (["--demo", "--robots", "0"], "--robots 0 is not 1…50"),
        (["--demo", "--robots", "51"], "--robots 51 is not 1…50"),
        (["--central", "hq:notaport"], "--central: central server 'hq:notaport' is not HOST:PORT"),
        (["--central", "127.0.0.1:7272", "--host", "127.0.0.1"], "--central goes without --host and --demo"),
    ],
)
def test_robots_without_demo_or_out_of_range_is_a_usage_error(args: list[str], said: str) -> None:
    out = subprocess.run([sys.executable, "-m", "rtmu", *args], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and said in out.stderr
