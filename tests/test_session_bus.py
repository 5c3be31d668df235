"""``scripts/with-session-bus.sh`` (what ``./rtmu-dev demo`` runs through): a session bus where none is.

Without one GTK warned "Unable to acquire session bus" on every start under Xvfb or a kiosk X server.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "with-session-bus.sh"
# Connects to the session bus the way GTK does (GLib's GDBus) and prints the address and its own name.
PROBE = (
    "import os\nfrom gi.repository import Gio\n"
    "bus = Gio.bus_get_sync(Gio.BusType.SESSION, None)\n"
    "print(os.environ.get('DBUS_SESSION_BUS_ADDRESS', ''))\nprint(bus.get_unique_name())\n"
)


def run(env: dict[str, str], *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["bash", str(SCRIPT), *argv], env=env, capture_output=True, text=True, timeout=60)


def bare_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DBUS_SESSION_BUS_ADDRESS", "XDG_RUNTIME_DIR")}
    env.pop("DISPLAY", None)  # and no X server for GLib to autolaunch a bus on
    return env


def test_without_a_bus_the_command_gets_a_private_one_that_ends_with_it() -> None:
    done = run(bare_env(), sys.executable, "-c", PROBE)
    assert done.returncode == 0, done.stderr
    address, name = done.stdout.split()
    assert address.startswith("unix:") and name.startswith(":")
    socket = re.search(r"path=([^,]+)", address)
    if socket:  # an abstract socket leaves no file; a path one must be gone with the bus
        assert not Path(socket.group(1)).exists()


def test_a_desktop_bus_is_used_as_it_is() -> None:
    env = dict(bare_env(), DBUS_SESSION_BUS_ADDRESS="unix:path=/nonexistent/rtmu-test-bus")
    done = run(env, "bash", "-c", 'echo "$DBUS_SESSION_BUS_ADDRESS"')
    assert done.returncode == 0 and done.stdout.strip() == "unix:path=/nonexistent/rtmu-test-bus"


def test_the_exit_status_is_the_commands() -> None:
    assert run(bare_env(), "bash", "-c", "exit 7").returncode == 7
    assert run(bare_env()).returncode == 2


def test_rtmu_dev_demo_runs_the_window_through_it() -> None:
    text = (ROOT / "rtmu-dev").read_text()
    assert re.search(r'demo\) exec bash scripts/with-session-bus\.sh "\$BIN/rtmu" --demo "\$@"', text)
