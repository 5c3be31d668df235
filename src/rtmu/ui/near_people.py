"""View ▸ Near people: the operator's speed cap for attended work, a switch in the View menu.

On, every held drive (keys, D-pad, gamepad) of every robot the window shows goes no faster than
the cap (250 mm/s unless the settings say otherwise): the controller lowers the ``ratioDrive``
throttle from the robot's top speed (``control.motion_limits``). The switch, the banner it raises
("Near people: at most 250 mm/s …", with the throttle that gives and where the top speed came from)
and the settings file (``near_people = true``) all say the same. Autonomous navigation keeps the
server's own speeds: the cap is on what the operator drives.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GLib  # noqa: E402

from ..base.i18n import _, words  # noqa: E402
from ..base.units import quantity  # noqa: E402
from ..control.motion_limits import capped_throttle  # noqa: E402
from ..model.observables import NearPeople  # noqa: E402

MainWindow = Any
"""``ui.window.MainWindow`` (which imports this module): named, not imported."""


def label(setting: NearPeople) -> str:
    return _("Near people: at most {mm_s} mm/s").format(mm_s=setting.mm_s)


class NearPeopleSwitch:
    """The View menu's switch; ``on_change(setting)`` is the app's hook to remember it."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window
        self.on_change: Callable[[NearPeople], None] | None = None
        operator = window.operator
        self.action = Gio.SimpleAction.new_stateful(
            "near-people", None, GLib.Variant.new_boolean(operator.near_people.value.on)
        )
        self.action.connect("activate", lambda *_a: self.set(not operator.near_people.value.on))
        window.add_action(self.action)
        window.view_menu.insert(0, label(operator.near_people.value), "win.near-people")
        self._unobserve = operator.near_people.observe(self._changed)

    def set(self, on: bool) -> None:
        setting = self.window.operator.near_people.value
        self.window.operator.near_people.set(NearPeople(on, setting.mm_s))

    def use(self, setting: NearPeople) -> None:
        """The remembered setting (the app's, at start): no banner."""
        self.window.operator.near_people.set(setting)

    def close(self) -> None:
        self._unobserve()

    def _changed(self, old: NearPeople, new: NearPeople) -> None:
        self.action.set_state(GLib.Variant.new_boolean(new.on))
        if new.mm_s != old.mm_s:
            menu = self.window.view_menu
            menu.remove(0)
            menu.insert(0, label(new), "win.near-people")
        if self.on_change is not None:
            self.on_change(new)
        if new.on == old.on:
            return
        if new.on:
            limits = self.window.controller.limits
            throttle = capped_throttle(100.0, new.mm_s, limits)
            text = _("{label}: a full drive is {throttle} of this robot's {speed} — {source}").format(
                label=label(new),
                throttle=quantity(throttle, "%"),
                speed=quantity(limits.max_speed / 1000, "m/s", 1),
                source=words(limits.source),
            )
        else:
            text = _("Near-people cap off: the speed steps go up to the robot's full speed again")
        self.window.banners.tell("speed", "info", text, timeout=5.0)
