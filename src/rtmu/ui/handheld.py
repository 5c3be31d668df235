"""The window's handheld parts in one place: gamepad, alarms and the phone layout.

The window creates one :class:`Handheld` after its own widgets and actions and
calls :meth:`close` when it shuts down; everything else hooks itself on:

* the gamepad mapping (``rtmu.control.gamepad``) on the window's controller, fed by
  libmanette (``ui.gamepad``), its status pill over the map, its own 10 Hz timer
  (silence, rate limit) and the window's focus (connected after the window's own
  focus handler, so the controller has already stopped when the pad hears of it);
* the alarms (``ui.alarm_view``) into the window's banners, with the display's
  bell, and the ``win.alarm-sound`` toggle (View menu), remembered in settings
  through ``on_mute``;
* the phone layout (``ui.layout``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GLib  # noqa: E402

from ..control.controller import Controller  # noqa: E402
from ..control.gamepad import Gamepad, PadState  # noqa: E402
from ..control.held_drive import TICK  # noqa: E402
from .alarm_view import AlarmView  # noqa: E402
from .gamepad import ManettePads  # noqa: E402
from .gamepad_status import GamepadStatus  # noqa: E402
from .layout import PhoneLayout  # noqa: E402

MainWindow = Any
"""``ui.window.MainWindow``, which imports this module: named, not imported (no import cycle)."""

PILL_BELOW_MOTION = 76
"""The pad pill's top margin on a phone: under the three-line motion pill."""


class Handheld:
    """See the module notes."""

    def __init__(self, window: MainWindow, *, muted: bool = False) -> None:
        self.window = window
        self.on_mute: Callable[[bool], None] | None = None
        """Told when the operator switches the alarm sound (the app saves it)."""
        self.pad = Gamepad(window.controller, window.clock)
        self.pad_status = GamepadStatus()
        self.pad.on_change = self._pad_changed
        window.map_page.add_overlay(self.pad_status)
        self.pads = ManettePads(self.pad)
        self.alarms = AlarmView(window.model, window.banners, window.get_display().beep, muted=muted)
        self.layout = PhoneLayout(window)
        self.layout.on_change = self._layout_changed
        self._layout_changed(self.layout.narrow)  # a phone's layout is chosen before the window shows
        self.sound_action = Gio.SimpleAction.new_stateful(
            "alarm-sound", None, GLib.Variant.new_boolean(not muted)
        )
        self.sound_action.connect("activate", self._toggle_sound)
        window.add_action(self.sound_action)
        self._focus_handler = window.connect("notify::is-active", self._on_active)
        self._tick = 0
        """The pad's timer (stick pushes held back, a silent pad): runs only while a pad is connected."""

    def set_muted(self, muted: bool) -> None:
        self.alarms.muted = muted
        self.sound_action.set_state(GLib.Variant.new_boolean(not muted))

    def _toggle_sound(self, action: Gio.SimpleAction, _param: object) -> None:
        state = action.get_state()
        muted = state is not None and state.get_boolean()  # sound was on: now muted
        self.set_muted(muted)
        if self.on_mute is not None:
            self.on_mute(muted)

    def _layout_changed(self, narrow: bool) -> None:
        """On a phone the motion pill (top left) and the pad pill cannot share a row: the pad's goes under."""
        self.pad_status.set_margin_top(PILL_BELOW_MOTION if narrow else 8)

    def show_controller(self, controller: Controller) -> None:
        """The window shows another robot: the pad drives its controller, after a fresh dead-man press."""
        self.pad.retarget(controller)

    def _on_active(self, *_a: object) -> None:
        self.pad.focus(self.window.is_active())

    def _pad_changed(self, state: PadState) -> None:
        self.pad_status.show_state(state)
        if self.pad.present and not self._tick:
            self._tick = GLib.timeout_add(int(TICK * 1000), self._on_tick)

    def _on_tick(self) -> bool:
        self.pad.tick()
        if self.pad.present:
            return True
        self._tick = 0
        return False

    def close(self) -> None:
        """Release a pad that drove, stop timers and observers (idempotent)."""
        if self._tick:
            GLib.source_remove(self._tick)
            self._tick = 0
        if self._focus_handler:
            self.window.disconnect(self._focus_handler)
            self._focus_handler = 0
        self.pads.close()
        self.alarms.close()
        self.layout.close()
