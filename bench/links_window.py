"""The real window held driving through the fault proxy, for ``bench_links``' false-stop rows.

The app runs under its own Xvfb (as ``bench.soak_window``) with ``RTMU_LINK_TIMING`` as asked,
connected through a :class:`~bench.links_rig.RigProcess`'s proxy to the simulator; ``xdotool keydown
Left`` turns the robot in place (it never reaches a wall, so every stop is one of ours). Every
stop that reaches the simulator while the key is held is a false one: it is counted, the key is
let go and pressed again, and the hold goes on until the time is up.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import IO

from bench.common import end_process, start_xvfb
from bench.links_rig import RigProcess, env_for
from bench.soak_window import _xdotool

KEY = "Left"


class StopLog:
    """The app's stderr read as it comes; the stop lines (sent, or the guardian's) and the lease keeper's
    account of a lapse kept until taken."""

    def __init__(self, stream: IO[str] | None) -> None:
        self._lines: list[str] = []
        self._lock = threading.Lock()
        if stream is not None:
            threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream: IO[str]) -> None:
        for line in stream:
            if "stop" in line or "lease" in line:
                with self._lock:
                    self._lines.append(line.strip())

    def take(self) -> list[str]:
        with self._lock:
            lines, self._lines = self._lines, []
        return lines


def window_false_stops(rig: RigProcess, seconds: float, fixed: bool) -> tuple[int, float, list[str]]:
    """(false stops, seconds held, who sent each) for the real window through ``rig``'s proxy."""
    xvfb, display = start_xvfb()
    config = tempfile.mkdtemp(prefix="rtmu-links-")
    env = env_for(fixed)
    env.update(DISPLAY=display, GDK_BACKEND="x11", GSK_RENDERER="cairo", NO_AT_BRIDGE="1")
    env.update(GSETTINGS_BACKEND="memory", XDG_CONFIG_HOME=config, XDG_DATA_HOME=config)
    env.pop("WAYLAND_DISPLAY", None)
    env["RTMU_LOG"] = "info"  # each stop's measured cause (``DriveFeed.send_stop``) on its stderr
    app = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(rig.port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    said = StopLog(app.stderr)
    try:
        window = _xdotool(env, "search", "--sync", "--onlyvisible", "--pid", str(app.pid), "--name", "RTMU")
        _xdotool(env, "windowfocus", "--sync", window.split()[0])

        def press() -> bool:
            for _ in range(30):  # a press that beats "connected" is refused: press until one drives
                _xdotool(env, "keydown", KEY)
                if rig.wait(rig.turning, 2.0):
                    return True
                _xdotool(env, "keyup", KEY)
                time.sleep(0.5)
            return False

        if not press():
            raise RuntimeError("the window never drove the robot")
        said.take()
        start = time.monotonic()
        seen = len(rig.stops)
        false: list[str] = []
        events = 0
        while time.monotonic() - start < seconds:
            if len(rig.stops) > seen:
                events += 1
                time.sleep(0.2)  # its log line follows the stop
                why = " | ".join(said.take()) or "no cause logged"
                false.append(
                    ",".join(who for _t, who in rig.stops[seen:])
                    + f" at {time.monotonic() - start:.1f} s: {why}"
                )
                _xdotool(env, "keyup", KEY)
                time.sleep(0.5)
                seen = len(rig.stops)  # the release's own stop is not counted
                said.take()
                if not press():
                    break
            time.sleep(0.05)
        held = time.monotonic() - start
        _xdotool(env, "keyup", KEY)
        return events, held, false
    finally:
        end_process(app)
        xvfb.terminate()
        xvfb.wait(5)
        for path in sorted(Path(config).rglob("*"), reverse=True):
            path.rmdir() if path.is_dir() else path.unlink()
        Path(config).rmdir()
