"""A reader that goes away (`rtmu mapinfo MAP | head -1`) ends the command quietly, without a traceback."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

from rtmu.package_data import project_map

MAP = project_map("office.map")


def test_a_closed_stdout_pipe_is_exit_141_without_a_traceback() -> None:
    read_end, write_end = os.pipe()
    os.close(read_end)  # closed before the child writes: its first write meets EPIPE, every time
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "rtmu", "mapinfo", str(MAP)],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            timeout=60,
            check=False,
        )
    finally:
        os.close(write_end)
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.returncode == 128 + signal.SIGPIPE
