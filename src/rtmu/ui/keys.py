"""Every key RTMU answers to, in one table — key → action — and the capture-phase router.

The commands' keys come from the command registry (``rtmu.control.commands``: the only
place a command is defined): a command's keys activate its ``win.<name>`` action, a held
command's keys drive while held. This module adds only the window's own keys, each naming
the ``win.*`` action it activates (zoom, follow, the camera page, live video, the camera
head, the fleet …; ``ui.actions`` defines them). The keys window (``ui.keys_window``, through
``ui.keys_sheet``) and the menu's key labels (:func:`menu_item`) read the same table.

Why capture phase: GtkWindow consumes Space and Return (button activation) and
the arrow keys (focus moves) before a normal bubble-phase controller sees them;
a teleoperation window must get them first. The router hands held keys to the
controller's press/release (tracked by hardware keycode, so a release whose
keyval changed — Shift let go first, Caps Lock — still releases), swallows
auto-repeat, and leaves everything it does not know to the application
accelerators (F11, Ctrl+T, Ctrl+Q …: bindings marked ``accelerator``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Gio, GLib, Gtk  # noqa: E402

from ..base.i18n import N_  # noqa: E402
from ..control.commands import COMMANDS, CommandRegistry, action_name  # noqa: E402


@dataclass(frozen=True, slots=True)
class Binding:
    """Keys (GTK accelerator strings) and what they do: activate a window action, or drive while held."""

    accels: tuple[str, ...]
    title: str
    group: str
    action: str = ""
    """The action the keys activate, with its target where it takes one: ``win.zoom-in``,
    ``win.select-robot(3)``, ``app.quit`` ("" for a held drive key)."""
    held: str = ""
    """A held drive command (``drive_forward`` …): it drives while the key is down, stops on release."""
    accelerator: bool = False
    """GTK's application accelerators carry these keys (``set_accels_for_action``); the router leaves
    them alone."""


def _ptz(keys: str, title: str, move: str) -> Binding:
    return Binding((keys,), title, N_("Camera head"), f"win.{move}")


WINDOW_BINDINGS: tuple[Binding, ...] = (
    Binding(("<Control>plus", "<Control>equal", "<Control>KP_Add"), N_("Zoom in"), N_("Map"), "win.zoom-in"),
    Binding(("<Control>minus", "<Control>KP_Subtract"), N_("Zoom out"), N_("Map"), "win.zoom-out"),
    Binding(("<Control>0",), N_("Fit map"), N_("Map"), "win.zoom-fit"),
    Binding(("f",), N_("Follow the robot on/off"), N_("Map"), "win.follow"),
    Binding(("Escape",), N_("Camera picture ⇄ map"), N_("Window"), "win.camera"),
    Binding(("F10", "Menu", "<Shift>F10"), N_("Open the menu"), N_("Window"), "win.open-menu"),
    Binding(("<Control>g",), N_("Go to: goals, a point, home, dock"), N_("Navigation"), "win.goto-panel"),
    *(
        Binding(
            (f"<Alt>{n}",),
            N_("Select robot 1 … 9 of the list"),
            N_("Fleet"),
            f"win.select-robot({n})",
        )
        for n in range(1, 10)
    ),
    Binding(("<Alt>Page_Down",), N_("Next robot"), N_("Fleet"), "win.next-robot"),
    Binding(("<Alt>Page_Up",), N_("Previous robot"), N_("Fleet"), "win.previous-robot"),
    Binding(("v",), N_("Live video on/off"), N_("Window"), "win.live-video"),
    Binding(("question",), N_("Why won't it move?"), N_("Window"), "win.why"),
    _ptz("<Control>Left", N_("Pan the camera left"), "ptz-left"),
    _ptz("<Control>Right", N_("Pan the camera right"), "ptz-right"),
    _ptz("<Control>Up", N_("Tilt the camera up"), "ptz-up"),
    _ptz("<Control>Down", N_("Tilt the camera down"), "ptz-down"),
    _ptz("Page_Up", N_("Zoom the camera in"), "ptz-zoom-in"),
    _ptz("Page_Down", N_("Zoom the camera out"), "ptz-zoom-out"),
    Binding(("F11",), N_("Full screen"), N_("Window"), "win.fullscreen", accelerator=True),
    Binding(("<Control>t",), N_("Status toolbar"), N_("Window"), "win.toolbar", accelerator=True),
    Binding(
        ("<Control>comma",), N_("Connection settings"), N_("Connection"), "win.settings", accelerator=True
    ),
    Binding(
        ("<Control>question", "F1"),
        N_("Keyboard shortcuts"),
        N_("Application"),
        "win.show-keys",
        accelerator=True,
    ),
    Binding(("<Control>q",), N_("Quit"), N_("Application"), "app.quit", accelerator=True),
)
"""The window's own keys, each naming the action it activates (no robot command: those are the
registry's)."""


def bindings(registry: CommandRegistry = COMMANDS) -> tuple[Binding, ...]:
    """The whole key table: every command's keys from the registry, then the window's own.

    A command's keys activate its action (``win.<name>``); a held command's keys drive while held.
    """
    commands = tuple(
        Binding(c.keys, c.label, c.group, held=c.name)
        if c.hold
        else Binding(c.keys, c.label, c.group, f"win.{action_name(c.name)}")
        for c in registry
        if c.keys
    )
    return commands + WINDOW_BINDINGS


def accelerated() -> tuple[Binding, ...]:
    """The bindings GTK's application accelerators carry (the app sets them at start-up)."""
    return tuple(b for b in WINDOW_BINDINGS if b.accelerator)


def menu_accel(action: str, registry: CommandRegistry = COMMANDS) -> str | None:
    """The key a menu row shows for ``action`` (detailed, as in the table): its binding's first key."""
    return next((b.accels[0] for b in bindings(registry) if b.action == action), None)


def menu_item(label: str, action: str) -> Gio.MenuItem:
    """A menu row for ``action`` (detailed: ``win.select-robot(3)``) showing its key from the table."""
    _ok, name, target = Gio.Action.parse_detailed_name(action)
    item = Gio.MenuItem.new(label, None)
    item.set_action_and_target_value(name, target)
    accel = menu_accel(action)
    if accel is not None:
        item.set_attribute_value("accel", GLib.Variant.new_string(accel))
    return item


MODS = Gdk.ModifierType.CONTROL_MASK | Gdk.ModifierType.SHIFT_MASK | Gdk.ModifierType.ALT_MASK


def _parse(accel: str) -> tuple[int, Gdk.ModifierType]:
    ok, keyval, mods = Gtk.accelerator_parse(accel)
    if not ok:
        raise ValueError(f"bad accelerator {accel!r}")
    return keyval, mods


class KeyRouter:
    """Capture-phase key handling: a held key calls ``hold``/``release`` with its command, any other
    key of the table ``activate`` with its action (``win.zoom-in``).

    Shift matters only where the table says so (``<Shift>Up`` is a move, plain
    ``Up`` drives); for ``plus``/``equal`` Shift is part of typing the key and is
    ignored. Control and Alt combinations not in the table pass through.
    """

    def __init__(
        self,
        *,
        hold: Callable[[str], None],
        release: Callable[[str], None],
        activate: Callable[[str], object],
        registry: CommandRegistry = COMMANDS,
    ) -> None:
        self._hold = hold
        self._release = release
        self._activate = activate
        self._held: dict[int, str] = {}
        """keycode → hold command name, for the keys now down."""
        self._table: dict[tuple[int, int], Binding] = {}
        for b in bindings(registry):
            if b.accelerator:
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
            if found is not None and found.action.startswith(("win.turn", "win.move")):
                found = None  # Shift+arrow is a move of its own; not a turn or move without Shift
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
        if binding.held:
            self._held[keycode] = binding.held
            self._hold(binding.held)
        else:
            self._activate(binding.action)
        return True

    def _released(
        self, _c: Gtk.EventControllerKey, _keyval: int, keycode: int, _state: Gdk.ModifierType
    ) -> None:
        name = self._held.pop(keycode, None)
        if name is not None:
            self._release(name)
