"""The drive soak through the real window: Xvfb, the ``rtmu`` app, real key events from xdotool.

The same cycle as :mod:`bench.soak` (hold a turning key 0.3–1.5 s, release, rest), but the key
goes through X, GTK's key router, the controller's 10 Hz lease renewals and the network thread of
the real app — the path an operator's finger takes. Release→stop runs from just before
``xdotool keyup`` starts to the simulator decoding the stop (so it includes xdotool's start-up);
resident memory is the app's (``/proc/PID/statm``); slow handlers are
the app's own warnings on stderr ("the handler for … took N ms").
"""

from __future__ import annotations

import os
import random
import re
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from bench.common import end_process, start_xvfb
from bench.soak import HOLD, REST, RSS_EVERY, STOP_WAIT, _pct, _Server, drive_figures

KEY = "Left"
"""Turning in place: the robot never reaches a wall, so every stop is the release's."""
SLOW = re.compile(r"the handler for (\S+) took (\d+) ms")


def _xdotool(env: dict[str, str], *args: str) -> str:
    return subprocess.run(
        ["xdotool", *args], env=env, capture_output=True, text=True, timeout=15, check=True
    ).stdout


def _rss_mb(pid: int) -> float:
    with open(f"/proc/{pid}/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def soak_window(
    seconds: float, *, seed: int = 1, progress: Callable[[str], None] | None = None
) -> dict[str, Any]:
    """Run the window soak for ``seconds``; the same raw figures as :func:`bench.soak.soak`."""
    rng = random.Random(seed)
    server = _Server()
    xvfb, display = start_xvfb()
    config = tempfile.mkdtemp(prefix="rtmu-soak-")
    env = dict(
        os.environ,
        DISPLAY=display,
        GDK_BACKEND="x11",
        GSK_RENDERER="cairo",
        NO_AT_BRIDGE="1",
        GSETTINGS_BACKEND="memory",
        XDG_CONFIG_HOME=config,
    )
    env.pop("WAYLAND_DISPLAY", None)
    app = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(server.port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    slow: list[tuple[str, int]] = []

    def read_stderr() -> None:
        assert app.stderr is not None
        for line in app.stderr:
            if m := SLOW.search(line):
                slow.append((m.group(1), int(m.group(2))))

    threading.Thread(target=read_stderr, daemon=True).start()
    try:
        window = _xdotool(env, "search", "--sync", "--onlyvisible", "--pid", str(app.pid), "--name", "RTMU")
        window = window.split()[0]
        _xdotool(env, "windowfocus", "--sync", window)
        # A press that beats "connected" to the window is refused: press until one drives.
        deadline = time.monotonic() + 30
        while True:
            _xdotool(env, "keydown", KEY)
            moved = server.first_drive_after(time.monotonic() - 0.01, 1.0)
            _xdotool(env, "keyup", KEY)
            server.first_stop_after(time.monotonic() - 0.01, STOP_WAIT)
            if moved:
                break
            if time.monotonic() > deadline:
                raise RuntimeError("the window never drove the robot")
        time.sleep(1.0)
        start = time.monotonic()
        warmup = min(120.0, seconds / 5)
        latencies: list[float] = []
        rss: list[tuple[float, float]] = []
        next_rss = start
        next_report = start + 60
        while (now := time.monotonic()) - start < seconds:
            if now >= next_rss:
                rss.append((now - start, _rss_mb(app.pid)))
                next_rss += RSS_EVERY
            _xdotool(env, "keydown", KEY)
            time.sleep(rng.uniform(*HOLD))
            # Stamped before xdotool runs: the app can stop the robot before xdotool has exited,
            # so the figure includes xdotool's own start-up (an upper bound, a few ms).
            released = time.monotonic()
            _xdotool(env, "keyup", KEY)
            stopped = server.first_stop_after(released, STOP_WAIT)
            latencies.append(STOP_WAIT if stopped is None else stopped - released)
            time.sleep(rng.uniform(*REST))
            if progress is not None and time.monotonic() >= next_report:
                next_report += 60
                progress(
                    f"window soak {time.monotonic() - start:5.0f} s: {len(latencies)} cycles, "
                    f"release→stop p99 {_pct(latencies, 0.99) * 1e3:.1f} ms, "
                    f"rss {_rss_mb(app.pid):.1f} MB, slow handlers {len(slow)}"
                )
        rss.append((time.monotonic() - start, _rss_mb(app.pid)))
        return {
            **drive_figures(start, latencies, rss, warmup),
            "slow_handlers": len(slow),
            "slow_handler_list": slow,
        }
    finally:
        end_process(app)
        xvfb.terminate()
        xvfb.wait(5)
        server.close()
        for path in sorted(Path(config).rglob("*"), reverse=True):
            path.rmdir() if path.is_dir() else path.unlink()
        Path(config).rmdir()
