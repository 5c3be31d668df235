"""What a stop key does wherever the keyboard is, and when the drive keys can reach the robot (GTK-free).

The window gives every surface that can hold the keyboard — itself, each dialog, the palette, the
configuration page, every open menu and popover — the same stop keys (``ui.stop_keys``); this module is
the rule they apply, so it is tested without a display:

* Space and the keypad's 5 (the registry's ``stop`` keys) stop the robot, whatever has the focus.
* In a text field Space still stops — a stop must never depend on where the focus happens to be —
  and **Shift+Space** types the space; the keypad's 5 types its digit there (a number field takes it).
  Every field says so (:data:`FIELD_HINT`).
* Ctrl+Space stops everywhere too (the chord some operators reach for in a field).
* Alt+Space is the window manager's: it is left alone.
"""

from __future__ import annotations

from enum import Enum

from ..base.i18n import N_, _
from .commands import COMMANDS, CommandRegistry


class KeyAction(Enum):
    STOP = "stop"
    """Stop the robot; the key is used up."""
    TYPE = "type"
    """Let the focused text field have it."""
    PASS = "pass"
    """Not a stop key: whoever handles it next."""


FIELD_HINT = N_("Space stops the robot · Shift+Space types a space")
"""What every text field says (placeholder and tooltip) while a stop key is one key away."""

TYPING_KEYS = frozenset({"KP_5"})
"""Stop keys that type their own character in a text field (a digit): Space never does."""


def stop_key_names(registry: CommandRegistry = COMMANDS) -> frozenset[str]:
    """The stop command's plain keys (GTK key names: ``space``, ``KP_5``), from the one registry."""
    return frozenset(k for k in registry.get("stop").keys if "<" not in k)


def stop_key_action(
    key: str,
    *,
    shift: bool = False,
    ctrl: bool = False,
    alt: bool = False,
    in_text: bool = False,
    stop_keys: frozenset[str] | None = None,
) -> KeyAction:
    """What the key ``key`` (a GTK key name) does with these modifiers, the focus in a text field or not."""
    keys = stop_key_names() if stop_keys is None else stop_keys
    if key not in keys or alt:
        return KeyAction.PASS
    if ctrl:
        return KeyAction.STOP
    if in_text and (key in TYPING_KEYS or shift):
        return KeyAction.TYPE
    return KeyAction.STOP


KEYS_INACTIVE = N_("Keys inactive — click the map")
"""What the window says while the keyboard is elsewhere (another program, or nowhere)."""


def keys_note(*, window_active: bool, connected: bool, dialog: str = "") -> str:
    """The note over the map while the drive keys cannot reach the window ("" while they can).

    ``dialog`` is the title of one of the window's own dialogs that has the keyboard: it carries the
    stop keys, so the note says that Space still stops there.
    """
    if window_active or not connected:
        return ""
    if dialog:
        return _("Drive keys go to “{dialog}” · Space stops the robot there").format(dialog=dialog)
    return _(KEYS_INACTIVE)
