"""``rtmu --demo`` as the README runs it: a real process, the bundled simulator, a clean exit on SIGTERM."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading

from rtmu.cli import build_parser


def test_help_lists_the_window_options() -> None:
    text = build_parser().format_help()
    for option in ("--demo", "--host", "--port", "--user", "--fullscreen", "--profile"):
        assert option in text


def test_rtmu_demo_shows_the_office_map_and_exits_cleanly(tmp_path) -> None:  # type: ignore[no-untyped-def]
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--demo", "--report-first-frame"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    seen = threading.Event()

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            if "first map frame" in line:
                seen.set()

    threading.Thread(target=read, daemon=True).start()
    try:
        assert seen.wait(60), "the demo never showed the map"
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(15) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)
    assert not list(tmp_path.rglob("settings.toml")), "the demo's throw-away profile is not saved"
