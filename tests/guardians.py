"""What a test sees of a guardian: the stops it sent and the logins as the simulator saw them, and its
processes — shared by the fleet-parent tests (tests/client) and the window's (tests/gui)."""

from __future__ import annotations

from pathlib import Path

from rtmu.guardian.halt import IDENTIFIER
from rtmu.sim import SimThread


def guardian_stops(sim: SimThread) -> int:
    """``stop`` requests the simulator took from a guardian's connection (its self identifier)."""
    return sum(1 for _t, _ident, who in sim.call(lambda: list(sim.server.stop_log)) if who == IDENTIFIER)


def logins(sim: SimThread) -> int:
    """Clients logged in to the simulator now (a window and its guardian are two)."""
    return len(sim.call(lambda: list(sim.server.sessions)))


def guardians_of(pid: int) -> list[int]:
    """Live guardian processes whose parent is ``pid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            cmdline = (entry / "cmdline").read_bytes()
        except (OSError, ValueError, IndexError):
            continue
        if ppid == pid and b"rtmu.guardian" in cmdline:
            found.append(int(entry.name))
    return found
