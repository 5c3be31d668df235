"""Where the files RTMU ships inside its package live: its own maps and the desktop integration.

They sit in ``rtmu/data`` so that a wheel (``pipx install``) carries them and a checkout runs from the
same files: ``maps/`` (``arena.map``, ``office.map``: the simulator's and ``--demo``'s worlds, made by
``rtmu.sim.project_maps``) and ``desktop/`` (the desktop entry, its icon and the AppStream metainfo,
copied into place only by ``rtmu --install-desktop``). Nothing in it is third-party.
"""

from __future__ import annotations

from pathlib import Path

APP_ID = "io.github.rtmu.Rtmu"
"""The application's id: its D-Bus name, desktop file, icon and AppStream component are named after it."""
DATA_DIR = Path(__file__).resolve().parent / "data"
MAPS_DIR = DATA_DIR / "maps"
DESKTOP_DIR = DATA_DIR / "desktop"
LOCALE_DIR = DATA_DIR / "locale"
"""Compiled message catalogues (``<lang>/LC_MESSAGES/rtmu.mo``), shipped with the package."""


def project_map(name: str) -> Path:
    """One of the project's own maps (``arena.map``, ``office.map``) as shipped in the package."""
    return MAPS_DIR / name
