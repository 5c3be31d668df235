"""Desktop notifications (``Gio.Notification``) for what an operator in another window must not miss.

While the window is not focused, the robot shown arriving, failing to arrive, docking, its battery
falling to low, its link being lost and a server popup waiting are sent to the desktop — each kind
switched off in View ▸ Desktop notifications (remembered in the settings' ``[notifications]``). The
server's own words (a failure's reason, a popup's title) are marked as the robot's and escaped. They
are withdrawn when the window is focused again: the operator is back, the window says the rest.
The decisions (``*_note``) are plain functions of old and new state; :class:`DesktopNotifier` sends.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GLib, Gtk  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..model.observables import ConnectionState, NavState, Phase, PopupsState, RobotModel, RobotState  # noqa: E402
from ..settings.notifications import NOTIFICATION_KINDS  # noqa: E402
from ..values.state import NavOutcome  # noqa: E402
from .nav_text import where  # noqa: E402

LABELS = {
    "arrived": N_("Arrived"),
    "failed": N_("Did not arrive"),
    "docked": N_("Docked"),
    "battery_low": N_("Battery low"),
    "link_lost": N_("Link lost"),
    "popup": N_("Server message waiting"),
}
URGENT = {"failed", "battery_low", "link_lost"}
MAX_WORDS = 200
"""A server's words in a notification are cut here (a desktop shows a few lines)."""


@dataclass(frozen=True, slots=True)
class Note:
    kind: str
    title: str
    body: str


def robot_words(text: str) -> str:
    return _("The robot says: “{value}”").format(value=visible(text)[:MAX_WORDS])


def nav_note(old: NavState, new: NavState, robot: str) -> Note | None:
    if new.outcome == old.outcome:
        return None
    if new.outcome is NavOutcome.ARRIVED:
        return Note(
            "arrived",
            _("{robot} arrived").format(robot=robot),
            _("At {visible}.").format(visible=visible(where(new.target))),
        )
    if new.outcome is NavOutcome.DOCKED:
        return Note("docked", _("{robot} docked").format(robot=robot), _("It is on its charger."))
    if new.outcome is NavOutcome.FAILED:
        why = new.outcome_text or new.reason
        return Note(
            "failed",
            _("{robot} did not arrive").format(robot=robot),
            robot_words(why) if why else _("No reason given."),
        )
    return None


def battery_note(old: RobotState, new: RobotState, robot: str) -> Note | None:
    low = ("low", "critical")
    if new.battery_state in low and old.battery_state not in low and old.battery_v is not None:
        unit = "%" if new.battery_is_soc else "V"
        level = _("at its shutdown level") if new.battery_state == "critical" else "low"
        return Note(
            "battery_low",
            _("{robot}: battery {level}").format(robot=robot, level=level),
            _("{battery_v:g} {unit}. Send it to charge.").format(battery_v=new.battery_v, unit=unit),
        )
    return None


def link_note(old: ConnectionState, new: ConnectionState, robot: str) -> Note | None:
    if old.phase is Phase.CONNECTED and new.phase in (Phase.RECONNECTING, Phase.FAILED):
        return Note(
            "link_lost",
            _("{robot}: link lost").format(robot=robot),
            visible(new.error) or _("The connection ended."),
        )
    return None


def popup_note(old: PopupsState, new: PopupsState, robot: str) -> Note | None:
    seen = {p.popup_id for p in old.open}
    fresh = [p for p in new.open if p.popup_id not in seen]
    if not fresh:
        return None
    return Note(
        "popup",
        _("{robot}: a message waits for an answer").format(robot=robot),
        robot_words(fresh[-1].title or fresh[-1].message),
    )


class DesktopNotifier:
    """See the module notes; ``sent`` lists the notes sent (for tests), ``choices`` what is on."""

    def __init__(self, window: Gtk.ApplicationWindow, model: RobotModel, view_menu: Gio.Menu) -> None:
        self.window, self.model = window, model
        self.choices: dict[str, bool] = {kind: True for kind in NOTIFICATION_KINDS}
        self.on_change: Callable[[dict[str, bool]], None] | None = None
        self.sent: list[Note] = []
        self._ids: set[str] = set()
        self.actions: dict[str, Gio.SimpleAction] = {}
        submenu = Gio.Menu()
        for kind in NOTIFICATION_KINDS:
            action = Gio.SimpleAction.new_stateful(
                f"notify-{kind.replace('_', '-')}", None, GLib.Variant.new_boolean(True)
            )
            action.connect("activate", lambda a, _p, k=kind: self.set(k, not a.get_state().get_boolean()))
            window.add_action(action)
            self.actions[kind] = action
            submenu.append(_(LABELS[kind]), f"win.{action.get_name()}")
        view_menu.append_submenu(_("Desktop notifications"), submenu)
        m = model
        self._unobserve = [
            m.navigation.observe(lambda o, n: self._maybe(nav_note(o, n, self._robot()))),
            m.robot.observe(lambda o, n: self._maybe(battery_note(o, n, self._robot()))),
            m.connection.observe(lambda o, n: self._maybe(link_note(o, n, self._robot()))),
            m.popups.observe(lambda o, n: self._maybe(popup_note(o, n, self._robot()))),
        ]
        self._active = window.connect("notify::is-active", self._focus_changed)

    def use(
        self, choices: Mapping[str, bool], on_change: Callable[[dict[str, bool]], None] | None = None
    ) -> None:
        """The remembered choices (the app's, at start) and the hook that remembers new ones."""
        for kind in NOTIFICATION_KINDS:
            self.choices[kind] = bool(choices.get(kind, True))
            self.actions[kind].set_state(GLib.Variant.new_boolean(self.choices[kind]))
        self.on_change = on_change

    def set(self, kind: str, on: bool) -> None:
        self.choices[kind] = on
        self.actions[kind].set_state(GLib.Variant.new_boolean(on))
        if self.on_change is not None:
            self.on_change({k: v for k, v in self.choices.items() if not v})

    def _robot(self) -> str:
        conn = self.model.connection.value
        return visible(conn.profile) if conn.profile and conn.profile != "default" else _("The robot")

    def _maybe(self, note: Note | None) -> None:
        if note is None or not self.choices.get(note.kind, True) or self.window.is_active():
            return
        app = self.window.get_application()
        if app is None:
            return
        notification = Gio.Notification.new(note.title)
        notification.set_body(note.body)
        if note.kind in URGENT:
            notification.set_priority(Gio.NotificationPriority.HIGH)
        ident = f"rtmu-{note.kind}"
        app.send_notification(ident, notification)
        self._ids.add(ident)
        self.sent.append(note)

    def _focus_changed(self, *_a: object) -> None:
        app = self.window.get_application()
        if self.window.is_active() and app is not None:
            for ident in self._ids:
                app.withdraw_notification(ident)
            self._ids.clear()

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        if self._active:
            self.window.disconnect(self._active)
            self._active = 0
