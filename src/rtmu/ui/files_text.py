"""What the robot's file page says, in words: sizes, dates, transfers, and why a feature is greyed.

GTK-free so the words are tested without a window. The features and their reasons are the client's
own (:data:`rtmu.client.remote_files.FEATURES`: the same words ``rtmu files`` prints), judged from
what the server lists to this user.
"""

from __future__ import annotations

import datetime
from collections.abc import Collection

from ..base.i18n import _
from ..base.units import file_size
from ..values.commission import Direction, Transfer

PAGE_FEATURES = ("list", "download", "upload", "delete")
"""What the page offers, each greyed on its own."""


def human_size(size: int) -> str:
    """``1234567`` → ``1.2 MB`` (decimal units, as file managers show them)."""
    return file_size(size)


def when(seconds: int) -> str:
    """A listed modification time in the local time zone (ARIA sends Unix seconds); "" for none."""
    if seconds <= 0:
        return ""
    try:
        return datetime.datetime.fromtimestamp(seconds).strftime("%Y-%m-%d %H:%M")
    except (OverflowError, OSError, ValueError):
        return ""


def greyed(offers: Collection[str], connected: bool) -> dict[str, str]:
    """Feature → why it cannot be used now (absent: it can), for each of :data:`PAGE_FEATURES`."""
    from ..client.remote_files import FEATURES  # with the files page, not at every launch

    out: dict[str, str] = {}
    for feature in PAGE_FEATURES:
        names, reason = FEATURES[feature]
        if not connected:
            out[feature] = _("not connected to a robot")
        elif not any(name in offers for name in names):
            out[feature] = reason + _(" — or this user may not use it")
    return out


def transfer_text(t: Transfer) -> str:
    """``Downloading maps/big.map — 1.2 of 50 MB`` (the total only when known)."""
    verb = _("Downloading") if t.direction is Direction.DOWNLOAD else _("Uploading")
    total = _(" of {human_size}").format(human_size=human_size(t.total)) if t.total else ""
    return f"{verb} {t.remote} — {human_size(t.done)}{total}"


def remote_join(folder: str, name: str) -> str:
    """A name in a remote folder as RTMU sends it (``a/b``; the shared folder itself is "")."""
    return f"{folder}/{name}" if folder else name


def parent_of(folder: str) -> str:
    return folder.rpartition("/")[0]
