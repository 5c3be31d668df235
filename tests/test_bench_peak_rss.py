"""bench_decode's peak-memory figures measure the decoding child, not the benchmark process.

Linux carries ``ru_maxrss`` across fork and exec, so a child started by a big parent reported the
parent's peak (every ``decode.*_peak_rss_mb`` figure came out equal). The child now reads its own
``VmHWM``; here the benchmark process first grows well past anything the child needs.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from testdata import CAPTURES

ROOT = Path(__file__).resolve().parents[1]
STRINGS = CAPTURES / "strings.pcap"
BIG_PARENT = """
import sys
from bench.bench_decode import _peak_mb
ballast = bytearray(300 * 1024 * 1024)
for i in range(0, len(ballast), 4096):  # touch every page so it is resident
    ballast[i] = 1
print(_peak_mb(["decode", "--json", sys.argv[1]]))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM is Linux's")
def test_child_peak_ignores_a_big_parent() -> None:
    done = subprocess.run(
        [sys.executable, "-c", BIG_PARENT, str(STRINGS)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    peak = float(done.stdout)
    assert 5 < peak < 200, f"child peak {peak:.1f} MiB: the 300 MiB parent leaked into it"
