"""The real window against the heaviest well-formed data a server may send: does it still drive?

The app runs under its own Xvfb (as ``bench.soak_window``), connected to ``bench.heavy_server`` in
its own process: 256 drawings × 3 998 points resent every 1 ms (``drawings``), a 632-byte JPEG
declaring 4096×4096 for every picture of live video (``frames``, V pressed), or 200 popups a second
of 31.8 KB each (``popups``). The baseline is the same window against the same server sending
nothing heavy (``plain``), in the same run. Each cycle: ``xdotool keydown Up``, hold 1 s, keyup;
the server stamps every drive packet (one monotonic clock for all processes).

* ``heavy.key_to_drive_ms.<kind>`` p50/p95/max — key down to the first ``ratioDrive`` at the server
  (the window answering a key; includes xdotool's own start-up, a few ms);
* ``heavy.drive_hz.<kind>`` — ``ratioDrive`` a second while held; ``heavy.drive_max_gap_ms.<kind>``;
* ``heavy.release_to_stop_ms.<kind>.p95``; ``heavy.rss_mb.<kind>`` — the app's resident memory at the end.

``RTMU_HEAVY_SECONDS`` (default 20) per kind. Run alone: ``python -m bench.bench_heavy``.
"""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from bench.common import Result, end_process, start_xvfb
from bench.soak import STOP_WAIT, _Server
from bench.soak_window import _rss_mb, _xdotool

SECONDS = float(os.environ.get("RTMU_HEAVY_SECONDS", "20"))
KINDS = ("plain", "drawings", "frames", "popups")
HOLD = 1.0


def _pct(values: list[float], q: float) -> float:
    v = sorted(values)
    return v[min(len(v) - 1, round(q * (len(v) - 1)))] if v else float("nan")


def window_under(kind: str, seconds: float) -> dict[str, Any]:
    server = _Server("bench.heavy_server", kind)
    xvfb, display = start_xvfb()
    config = tempfile.mkdtemp(prefix="rtmu-heavy-")
    env = dict(os.environ, DISPLAY=display, GDK_BACKEND="x11", GSK_RENDERER="cairo", NO_AT_BRIDGE="1")
    env.update(GSETTINGS_BACKEND="memory", XDG_CONFIG_HOME=config, XDG_DATA_HOME=config)
    env.pop("WAYLAND_DISPLAY", None)
    app = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(server.port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        window = _xdotool(env, "search", "--sync", "--onlyvisible", "--pid", str(app.pid), "--name", "RTMU")
        window = window.split()[0]
        _xdotool(env, "windowfocus", "--sync", window)
        deadline = time.monotonic() + 30
        while True:  # a press that beats "connected" is refused: press until one drives
            _xdotool(env, "keydown", "Up")
            moved = server.first_drive_after(time.monotonic() - 0.01, 1.0)
            _xdotool(env, "keyup", "Up")
            server.first_stop_after(time.monotonic() - 0.01, STOP_WAIT)
            if moved:
                break
            if time.monotonic() > deadline:
                raise RuntimeError("the window never drove the robot")
        if kind == "frames":
            _xdotool(env, "key", "v")  # live video: picture after picture
        time.sleep(2.0)  # the flood is on
        press: list[float] = []
        release: list[float] = []
        rates: list[float] = []
        gaps: list[float] = []
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            down = time.monotonic()
            _xdotool(env, "keydown", "Up")
            first = server.first_drive_after(down, 3.0)
            press.append(3.0 if first is None else first - down)
            time.sleep(max(0.0, down + HOLD - time.monotonic()))
            up = time.monotonic()
            _xdotool(env, "keyup", "Up")
            with server._cond:
                held = [t for t in server.drives if down <= t <= up]
            stopped = server.first_stop_after(up, STOP_WAIT)
            release.append(STOP_WAIT if stopped is None else stopped - up)
            if len(held) > 2:
                rates.append((len(held) - 1) / (held[-1] - held[0]))
                gaps += [b - a for a, b in itertools.pairwise(held)]
            time.sleep(0.5)
        return {
            "press": press,
            "release": release,
            "hz": sorted(r for r in rates if r == r),
            "max_gap": max(gaps, default=float("nan")),
            "rss": _rss_mb(app.pid),
        }
    finally:
        end_process(app)
        xvfb.terminate()
        xvfb.wait(5)
        server.close()
        for path in sorted(Path(config).rglob("*"), reverse=True):
            path.rmdir() if path.is_dir() else path.unlink()
        Path(config).rmdir()


def run() -> list[Result]:
    figures = {kind: window_under(kind, SECONDS) for kind in KINDS}
    plain = figures["plain"]
    out: list[Result] = []
    for kind, f in figures.items():
        print(f"# heavy {kind}: {f}", flush=True)
        if kind == "plain":
            continue
        for label, q in (("p50", 0.5), ("p95", 0.95), ("max", 1.0)):
            out.append(
                Result(
                    f"heavy.key_to_drive_ms.{kind}.{label}",
                    _pct(f["press"], q) * 1e3,
                    "ms",
                    _pct(plain["press"], q) * 1e3,
                )
            )
        out.append(Result(f"heavy.drive_hz.{kind}", _pct(f["hz"], 0.5), "Hz", _pct(plain["hz"], 0.5)))
        out.append(
            Result(
                f"heavy.drive_hz_min.{kind}", min(f["hz"], default=0.0), "Hz", min(plain["hz"], default=0.0)
            )
        )
        out.append(Result(f"heavy.drive_max_gap_ms.{kind}", f["max_gap"] * 1e3, "ms", plain["max_gap"] * 1e3))
        out.append(
            Result(
                f"heavy.release_to_stop_ms.{kind}.p95",
                _pct(f["release"], 0.95) * 1e3,
                "ms",
                _pct(plain["release"], 0.95) * 1e3,
            )
        )
        out.append(Result(f"heavy.rss_mb.{kind}", f["rss"], "MB", plain["rss"]))
    return out


if __name__ == "__main__":
    kinds = [a for a in sys.argv[1:] if a in KINDS]
    if kinds:
        for kind in kinds:
            print(kind, window_under(kind, SECONDS))
    else:
        for r in run():
            print(f"{r.name:45s} {r.value:10.1f} {r.unit:4s} baseline={r.baseline}")
