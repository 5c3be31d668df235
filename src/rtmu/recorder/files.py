"""Where recordings live, what they are called, and forgetting old ones.

``$XDG_DATA_HOME/rtmu/recordings/`` (``~/.local/share/…`` when unset), one file per
session named by its UTC start and its robot: ``20261125T041500Z_lab-robot_7272.mcap``.
"""

from __future__ import annotations

import contextlib
import re
import time
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path

from ..base.xdg import DATA, xdg_home

SUFFIX = ".mcap"
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


def recordings_dir(env: Mapping[str, str] | None = None) -> Path:
    """``$XDG_DATA_HOME/rtmu/recordings`` (an unset or relative value means ``~/.local/share``)."""
    return xdg_home(DATA, env) / "rtmu" / "recordings"


def file_name(robot: str, when: float | None = None) -> str:
    """``<UTC start>_<robot>.mcap``; the robot's name kept to safe characters (it may be a host name)."""
    stamp = datetime.fromtimestamp(time.time() if when is None else when, UTC).strftime("%Y%m%dT%H%M%SZ")
    safe = _UNSAFE.sub("-", robot).strip("-.")[:80] or "robot"
    return f"{stamp}_{safe}{SUFFIX}"


def new_path_name(directory: Path, robot: str, when: float | None = None) -> Path:
    """The path a new recording of ``robot`` gets (no disk access: the writer thread makes it)."""
    return directory / file_name(robot, when)


def variant(path: Path, n: int) -> Path:
    """``name-N.mcap``: the N-th choice when ``path`` exists already (same robot, same second)."""
    return path if n <= 1 else path.with_name(f"{path.name.removesuffix(SUFFIX)}-{n}{SUFFIX}")


def prune(directory: Path, keep_days: float, now: float | None = None) -> list[Path]:
    """Delete recordings older than ``keep_days`` (by modification time); the deleted paths.

    Only ``*.mcap`` files directly in ``directory`` are touched; ``keep_days <= 0`` keeps all.
    """
    if keep_days <= 0 or not directory.is_dir():
        return []
    limit = (time.time() if now is None else now) - keep_days * 86400.0
    gone: list[Path] = []
    for path in directory.glob(f"*{SUFFIX}"):
        with contextlib.suppress(OSError):
            if path.is_file() and not path.is_symlink() and path.stat().st_mtime < limit:
                path.unlink()
                gone.append(path)
    return gone
