"""The measured window of ``bench_fleet_scale``'s central rows: the application on a central server.

``python -m bench.central_window MODE SECONDS HOST:PORT`` opens the window on the robots the central
server lists (``MODE``: ``bounded`` — the window as shipped, at most ``connect_at_most`` robots
connected, one guardian — or ``unbounded``: every listed robot connected, a guardian process per
robot, as the window was). From the moment the window is mapped, for SECONDS, an X client thread
presses Space (STOP) every :data:`PRESS_EVERY` s through XTEST and the time from each press to the
controller's ``stop`` is taken — the list pouring in meanwhile. Prints one JSON line (``key_ms``,
``connected``) and keeps running until a signal ends it: the bench times SIGTERM to exit.
"""

from __future__ import annotations

import ctypes
import json
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("GdkX11", "4.0")
from gi.repository import GdkX11, GLib  # noqa: E402

from rtmu.control.controller import Controller  # noqa: E402
from rtmu.ui.application import RtmuApplication  # noqa: E402
from rtmu.ui.options import GuiOptions  # noqa: E402

PRESS_EVERY = 0.2
STOPS: list[float] = []


def _timed_stop(original):  # type: ignore[no-untyped-def]
    def stop(self: Controller) -> None:
        STOPS.append(time.monotonic())
        original(self)

    return stop


Controller.stop = _timed_stop(Controller.stop)  # type: ignore[method-assign]


class Presser(threading.Thread):
    """Presses and releases Space through XTEST, as a keyboard would; keeps each press's time."""

    def __init__(self, seconds: float) -> None:
        super().__init__(name="bench-presser", daemon=True)
        self.seconds = seconds
        self.pressed: list[float] = []
        self.done = threading.Event()

    def run(self) -> None:
        x11 = ctypes.cdll.LoadLibrary("libX11.so.6")
        xtst = ctypes.cdll.LoadLibrary("libXtst.so.6")
        x11.XOpenDisplay.restype = ctypes.c_void_p
        display = ctypes.c_void_p(x11.XOpenDisplay(None))
        code = x11.XKeysymToKeycode(display, x11.XStringToKeysym(b"space"))
        end = time.monotonic() + self.seconds
        while time.monotonic() < end:
            self.pressed.append(time.monotonic())
            xtst.XTestFakeKeyEvent(display, code, True, 0)
            x11.XFlush(display)
            time.sleep(0.03)
            xtst.XTestFakeKeyEvent(display, code, False, 0)
            x11.XFlush(display)
            time.sleep(PRESS_EVERY - 0.03)
        time.sleep(1.0)  # the last press's stop
        self.done.set()


def latencies(pressed: list[float], stops: list[float]) -> list[float]:
    """Each press's time to the first stop after it (ms); a press never answered counts as 10 s."""
    out = []
    for t0 in pressed:
        later = [t for t in stops if t >= t0]
        out.append((min(later) - t0) * 1000.0 if later else 10_000.0)
    return out


def main(mode: str, seconds: float, central: str) -> int:
    config = Path(tempfile.mkdtemp(prefix="rtmu-bench-central-")) / "settings.toml"
    options = GuiOptions(
        central=central,
        settings_path=config,
        persist=False,
        connect_at_most=1000 if mode == "unbounded" else None,
        guardian_per_robot=mode == "unbounded",
    )
    app = RtmuApplication(options)
    presser = Presser(seconds)

    def start() -> bool:
        window = app.window
        if window is None or not window.get_mapped():
            return True
        xid = GdkX11.X11Surface.get_xid(window.get_surface())
        subprocess.run(["xdotool", "windowfocus", "--sync", str(xid)], timeout=15, check=False)
        presser.start()
        GLib.timeout_add(100, report)
        return False

    def report() -> bool:
        if not presser.done.is_set():
            return True
        key_ms = latencies(presser.pressed, STOPS)
        out = {"mode": mode, "presses": len(key_ms), "key_ms": key_ms, "connected": len(app.fleet),
               "listed": len(app.fleet.listed.value)}  # fmt: skip
        print("RESULT " + json.dumps(out), flush=True)
        return False

    GLib.timeout_add(50, start)
    return int(app.run([sys.argv[0]]))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], float(sys.argv[2]), sys.argv[3]))
