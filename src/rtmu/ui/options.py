"""The window's start-up options and application id: plain data, shared by the entry point and the app.

Kept apart from ``app`` (the entry point) and ``application`` (the GTK application) so
that neither needs the other's module to know what the options are.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..package_data import APP_ID
from ..settings.store import DirectRobot

__all__ = ["APP_ID", "GuiOptions"]


@dataclass
class GuiOptions:
    host: str | None = None
    port: int | None = None
    user: str | None = None
    profile: str | None = None
    central: str | None = None
    """``--central HOST[:PORT]``: the window on every robot this central server lists (this run only)."""
    fullscreen: bool = False
    connect: bool | None = None
    """None: connect when a profile was given or saved before; False: never at start."""
    demo: bool = False
    settings_path: Path | None = None
    """None: the user's settings file; tests point it into a temporary directory."""
    persist: bool = True
    report_first_frame: bool = False
    protocol: str | None = None
    """Protocol string to log in with (None: the profile's; by default the server's own)."""
    replay: Path | None = None
    """``rtmu replay FILE.mcap``: show this recording instead of connecting to a robot."""
    replay_conn: int = 1
    """Which of the recording's connections (``--conn``)."""
    fleet: tuple[DirectRobot, ...] = ()
    """Robots to open the window on at once (``--demo --robots N``); empty: the profile's."""
    guardian: bool = True
    """Start the window's guardian process (``rtmu.guardian``); off only to measure without it."""
    guardian_per_robot: bool = False
    """One guardian process per robot connection, as before the window shared one: a benchmark's
    baseline only (``bench/bench_fleet_scale.py``)."""
    connect_at_most: int | None = None
    """How many robots of a fleet to keep connected at once (None: the profile's ``connect_at_most``)."""
