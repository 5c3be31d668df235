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
import time
from pathlib import Path

from bench.common import end_process, start_xvfb
from bench.links_rig import RigProcess, env_for
from bench.soak_window import _xdotool

KEY = "Left"


def window_false_stops(rig: RigProcess, seconds: float, fixed: bool) -> tuple[int, float, list[str]]:
    """(false stops, seconds held, who sent each) for the real window through ``rig``'s proxy."""
    xvfb, display = start_xvfb()
    config = tempfile.mkdtemp(prefix="rtmu-links-")
    env = env_for(fixed)
    env.update(DISPLAY=display, GDK_BACKEND="x11", GSK_RENDERER="cairo", NO_AT_BRIDGE="1")
    env.update(GSETTINGS_BACKEND="memory", XDG_CONFIG_HOME=config, XDG_DATA_HOME=config)
    env.pop("WAYLAND_DISPLAY", None)
    app = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(rig.port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
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
        start = time.monotonic()
        seen = len(rig.stops)
        false: list[str] = []
        events = 0
        while time.monotonic() - start < seconds:
            if len(rig.stops) > seen:
                events += 1
                false.append(",".join(who for _t, who in rig.stops[seen:]))
                _xdotool(env, "keyup", KEY)
                time.sleep(0.5)
                seen = len(rig.stops)  # the release's own stop is not counted
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
