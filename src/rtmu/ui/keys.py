"""Every key RTMU answers to, in one table, and the capture-phase controller that routes them.

The commands' keys come from the command registry (``rtmu.control.commands``: the only
place a command is defined); this module adds only the window's own keys (zoom,
follow, the camera page) and the application actions, listed for the help.

Why capture phase: GtkWindow consumes Space and Return (button activation) and
the arrow keys (focus moves) before a normal bubble-phase controller sees them;
a teleoperation window must get them first. The router hands held keys to the
controller's press/release (tracked by hardware keycode, so a release whose
keyval changed — Shift let go first, Caps Lock — still releases), swallows
auto-repeat, and leaves everything it does not know to the application
accelerators (F11, Ctrl+T, Ctrl+Q …, listed here too for the shortcuts window).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402

from ..control.commands import COMMANDS, CommandRegistry  # noqa: E402


@dataclass(frozen=True, slots=True)
class Binding:
    """Keys (GTK accelerator strings) that trigger one intent; ``intent`` is (kind, argument)."""

    accels: tuple[str, ...]
    title: str
    group: str
    kind: str
    """``hold`` (a hold command), ``command`` (run a registry command), ``view`` (a window intent),
    ``action`` (an application/window action, handled by accelerators, listed for the help only)."""
    target: str
    help: str | None = None
    """What the shortcuts window prints instead of the keys ("" leaves the line out)."""


WINDOW_BINDINGS: tuple[Binding, ...] = (
    Binding(("<Control>plus", "<Control>equal", "<Control>KP_Add"), "Zoom in", "Map", "view", "zoom_in"),
    Binding(("<Control>minus", "<Control>KP_Subtract"), "Zoom out", "Map", "view", "zoom_out"),
    Binding(("<Control>0",), "Fit map", "Map", "view", "zoom_fit"),
    Binding(("f",), "Follow the robot on/off", "Map", "view", "follow"),
    Binding(("Escape",), "Camera picture ⇄ map", "Window", "view", "toggle_camera"),
    Binding(("F10", "Menu", "<Shift>F10"), "Open the menu", "Window", "view", "open_menu"),
    Binding(("<Control>g",), "Go to: goals, a point, home, dock", "Navigation", "view", "goto_panel"),
    *(
        Binding(
            (f"<Alt>{n}",),
            "Select robot 1 … 9 of the list",
            "Fleet",
            "view",
            f"robot_{n}",
            "<Alt>1...<Alt>9" if n == 1 else "",
        )
        for n in range(1, 10)
    ),
    Binding(("<Alt>Page_Down",), "Next robot", "Fleet", "view", "next_robot"),
    Binding(("<Alt>Page_Up",), "Previous robot", "Fleet", "view", "previous_robot"),
    Binding(("v",), "Live video on/off", "Window", "view", "live_video"),
    Binding(("<Control>Left",), "Pan the camera left", "Camera head", "view", "ptz_left"),
    Binding(("<Control>Right",), "Pan the camera right", "Camera head", "view", "ptz_right"),
    Binding(("<Control>Up",), "Tilt the camera up", "Camera head", "view", "ptz_up"),
    Binding(("<Control>Down",), "Tilt the camera down", "Camera head", "view", "ptz_down"),
    Binding(("Page_Up",), "Zoom the camera in", "Camera head", "view", "ptz_zoom_in"),
    Binding(("Page_Down",), "Zoom the camera out", "Camera head", "view", "ptz_zoom_out"),
    Binding(("F11",), "Full screen", "Window", "action", "win.fullscreen"),
    Binding(("<Control>t",), "Status toolbar", "Window", "action", "win.toolbar"),
    Binding(("<Control>comma",), "Connection settings", "Connection", "action", "win.settings"),
    Binding(
        ("<Control>question", "F1"), "Keyboard shortcuts", "Application", "action", "win.show-help-overlay"
    ),
    Binding(("<Control>q",), "Quit", "Application", "action", "app.quit"),
)
"""The window's own keys: view intents and application actions (no robot command)."""


def bindings(registry: CommandRegistry = COMMANDS) -> tuple[Binding, ...]:
    """The whole key table: every command's keys from the registry, then the window's own.

    Groups are small (at most 6) so the shortcuts window fits an 800×480 screen in pages of columns.
    """
    commands = tuple(
        Binding(c.keys, c.label, c.group, "hold" if c.hold else "command", c.name) for c in registry if c.keys
    )
    return commands + WINDOW_BINDINGS


MODS = Gdk.ModifierType.CONTROL_MASK | Gdk.ModifierType.SHIFT_MASK | Gdk.ModifierType.ALT_MASK


def _parse(accel: str) -> tuple[int, Gdk.ModifierType]:
    ok, keyval, mods = Gtk.accelerator_parse(accel)
    if not ok:
        raise ValueError(f"bad accelerator {accel!r}")
    return keyval, mods


def accels_for(target: str) -> list[str]:
    """The accelerators of an ``action`` binding (for ``Gtk.Application.set_accels_for_action``)."""
    return [a for b in WINDOW_BINDINGS if b.target == target for a in b.accels]


class KeyRouter:
    """Capture-phase key handling ; ``hold``/``release``/``command``/``view`` are callbacks.

    Shift matters only where the table says so (``<Shift>Up`` is a move, plain
    ``Up`` drives); for ``plus``/``equal`` Shift is part of typing the key and is
    ignored. Control and Alt combinations not in the table pass through.
    """

    def __init__(
        self,
        *,
        hold: Callable[[str], None],
        release: Callable[[str], None],
        command: Callable[[str], None],
        view: Callable[[str], None],
        registry: CommandRegistry = COMMANDS,
    ) -> None:
        self._hold = hold
        self._release = release
        self._command = command
        self._view = view
        self._held: dict[int, str] = {}
        """keycode → hold command name, for the keys now down."""
        self._table: dict[tuple[int, int], Binding] = {}
        for b in bindings(registry):
            if b.kind == "action":
                continue
            for accel in b.accels:
                keyval, mods = _parse(accel)
                self._table[(Gdk.keyval_to_lower(keyval), int(mods & MODS))] = b
        self.controller = Gtk.EventControllerKey()
        self.controller.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)
        self.controller.connect("key-pressed", self._pressed)
        self.controller.connect("key-released", self._released)

    def lookup(self, keyval: int, state: Gdk.ModifierType) -> Binding | None:
        key = Gdk.keyval_to_lower(keyval)
        mods = int(state & MODS)
        found = self._table.get((key, mods))
        if found is None and mods & int(Gdk.ModifierType.SHIFT_MASK):
            # Shift typed the key itself (plus on most layouts, a capital W): try without it.
            found = self._table.get((key, mods & ~int(Gdk.ModifierType.SHIFT_MASK)))
            if found is not None and found.kind == "command" and found.target.startswith(("turn", "move")):
                found = None
        return found

    @property
    def held(self) -> dict[int, str]:
        return dict(self._held)

    def release_all(self) -> None:
        """Forget every held key (focus left the window; the controller stops the robot itself)."""
        for name in set(self._held.values()):
            self._release(name)
        self._held.clear()

    def _pressed(
        self, _c: Gtk.EventControllerKey, keyval: int, keycode: int, state: Gdk.ModifierType
    ) -> bool:
        if keycode in self._held:
            return True  # auto-repeat of a held key
        binding = self.lookup(keyval, state)
        if binding is None:
            return False
        if binding.kind == "hold":
            self._held[keycode] = binding.target
            self._hold(binding.target)
        elif binding.kind == "command":
            self._command(binding.target)
        else:
            self._view(binding.target)
        return True

    def _released(
        self, _c: Gtk.EventControllerKey, _keyval: int, keycode: int, _state: Gdk.ModifierType
    ) -> None:
        name = self._held.pop(keycode, None)
        if name is not None:
            self._release(name)
