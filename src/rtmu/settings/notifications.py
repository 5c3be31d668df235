"""Which desktop notifications the operator wants: the settings' optional ``[notifications]`` table.

The window (``ui.desktop_notify``) sends each kind while it is not focused unless it is switched off
here or in View ▸ Desktop notifications::

    [notifications]
    battery_low = false
"""

from __future__ import annotations

from collections.abc import Mapping

NOTIFICATION_KINDS = ("arrived", "failed", "docked", "battery_low", "link_lost", "popup")


def parse_notifications(raw: object) -> dict[str, bool]:
    """The table as read; ValueError for anything but known kinds set to true or false."""
    if not isinstance(raw, dict):
        raise ValueError("'notifications' must be a table")
    for key, value in raw.items():
        if key not in NOTIFICATION_KINDS:
            raise ValueError(f"notifications: unknown kind {key!r} (known: {', '.join(NOTIFICATION_KINDS)})")
        if type(value) is not bool:
            raise ValueError(f"notifications: {key} must be true or false, not {value!r}")
    return dict(raw)


def notification_lines(choices: Mapping[str, bool]) -> list[str]:
    """The table's lines for the file: only the kinds switched off (none: no table)."""
    off = [kind for kind in NOTIFICATION_KINDS if not choices.get(kind, True)]
    return ["", "[notifications]", *(f"{kind} = false" for kind in off)] if off else []
