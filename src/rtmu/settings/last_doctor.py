"""``rtmu doctor``'s last report, kept for the window's About ▸ debug information.

Support asks "what did the doctor say?"; the window shows the last answer without running it again.
One small text file, ``$XDG_DATA_HOME/rtmu/last-doctor.txt`` (beside the recordings, under the data
home the test suite keeps out of the real home), replaced whole on every run; nothing else reads it.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Mapping
from pathlib import Path

from ..base.xdg import DATA, xdg_home

MAX_BYTES = 16_000
"""A report is a few hundred bytes; a file grown past this is not ours and is not shown whole."""


def last_doctor_path(env: Mapping[str, str] | None = None) -> Path:
    return xdg_home(DATA, env) / "rtmu" / "last-doctor.txt"


def save_last_doctor(lines: list[str], env: Mapping[str, str] | None = None) -> None:
    """Keep ``lines`` with the time they were made; a home that cannot be written loses only this."""
    path = last_doctor_path(env)
    stamp = time.strftime("%Y-%m-%d %H:%M:%S %z")
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(f"({stamp})\n" + "\n".join(lines) + "\n", encoding="utf-8")
        tmp.replace(path)


def load_last_doctor(env: Mapping[str, str] | None = None) -> str:
    """The last report, or a sentence saying there is none."""
    try:
        with last_doctor_path(env).open("rb") as f:
            data = f.read(MAX_BYTES)
    except OSError:
        return "rtmu doctor has not been run on this computer (as this user)."
    return data.decode("utf-8", errors="replace").rstrip()
