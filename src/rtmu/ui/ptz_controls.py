"""Pan-tilt-zoom controls for the camera page: buttons, a drag on the picture, and keys.

The head's limits and position come from the model (``RobotState.ptz``, read by
``client.ptz``); the controls only ask the server to move it and never guess where
it went. The position is polled only while this bar is on screen (``map``/``unmap``
call ``watch_ptz``). Where the server has no movable head every control is greyed and
the bar says why. Buttons never take the keyboard focus, so drive keys keep driving;
the keys (Ctrl+arrows, Page Up/Down) are routed here by the window's key table.
Moving the camera head is not robot motion: it needs no drive lease.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..base.units import quantity  # noqa: E402
from ..control.commands import action_name  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import RobotModel, RobotState  # noqa: E402
from ..values.intents import Intent, PtzMove, WatchPtz  # noqa: E402
from ..values.state import PtzState  # noqa: E402
from . import accessible  # noqa: E402

PAN_STEP = 10.0
"""Degrees per button press or key (ARIA scales relative moves down as the camera zooms in)."""
TILT_STEP = 5.0
ZOOM_STEP = 10.0
"""Points of the zoom range per press."""
DRAG_PAN_DEG = 48.0
"""Degrees of pan for a drag across the whole picture (the simulated VC-C4's wide view)."""
DRAG_TILT_DEG = 36.0
DRAG_MIN_PX = 4.0
"""A shorter drag is a click, not a move."""
PICTURE_AFTER_MS = 400
"""After a move, ask for a new picture this much later (the head has turned by then)."""

KEY_STEPS: dict[str, tuple[float, float, float | None]] = {
    "ptz_left": (-PAN_STEP, 0.0, None),
    "ptz_right": (PAN_STEP, 0.0, None),
    "ptz_up": (0.0, TILT_STEP, None),
    "ptz_down": (0.0, -TILT_STEP, None),
    "ptz_zoom_in": (0.0, 0.0, ZOOM_STEP),
    "ptz_zoom_out": (0.0, 0.0, -ZOOM_STEP),
}
"""Key intent → relative (pan, tilt, zoom): pan is positive to the right (ARIA's camera handler turns
a look-at heading into ``-delta``), tilt positive up."""


def position_text(state: PtzState | None) -> str:
    """The head's settled position; while it turns, "moving" and where to (never a mid-turn reading
    as if the head were there)."""
    if state is None or not state.camera:
        return _("Camera head")
    name = state.display_name or state.camera
    if state.moving:
        if state.goal:
            return _("{name}: moving to {where}…").format(name=name, where=_angles(state, state.goal))
        return _("{name}: moving…").format(name=name)
    if state.position is None:
        return _("{name}: position not read yet").format(name=name)
    return f"{name}: {_angles(state, state.position)}"


def _signed_degrees(value: float) -> str:
    """``+90°``, ``-10°``, ``+0°``: the sign always shown, as a head's pan and tilt are read."""
    text = quantity(value, "deg")
    return text if text.startswith("-") else "+" + text


def _angles(state: PtzState, where: tuple[float, float, float]) -> str:
    pan, tilt, zoom = where
    text = _("pan {pan}  tilt {tilt}").format(pan=_signed_degrees(pan), tilt=_signed_degrees(tilt))
    return text + _("  zoom {zoom}").format(zoom=quantity(zoom, "%")) if state.zoom_available else text


def disabled_reason(state: PtzState | None, connected: bool) -> str:
    """Why the head cannot be moved now ("" when it can)."""
    if not connected:
        return _("not connected")
    if state is None:
        return _("reading the camera list…")
    if state.reason:
        return state.reason
    if not state.movable:
        return _("this camera cannot be moved")
    return ""


class PtzControls(Gtk.Box):
    """A bar of pan/tilt/zoom buttons and the head's position; ``attach_drag`` adds the picture drag."""

    def __init__(
        self, model: RobotModel, ask: Callable[[Intent], object], on_moved: Callable[[], None] | None = None
    ) -> None:
        super().__init__(orientation=Gtk.Orientation.HORIZONTAL, spacing=4)
        self.add_css_class("camera-bar")  # the camera page's own bar style
        self.add_css_class("ptz-bar")
        for side in ("start", "end"):
            getattr(self, f"set_margin_{side}")(8)
        self.set_margin_bottom(4)
        self.model = model
        self._ask = ask
        """The selected robot's intents (``SelectedRobot.ask``): the head of the robot being shown."""
        self._on_moved = on_moved
        self._picture_timer = 0
        self._closed = False
        self.watching = False
        self.buttons: dict[str, Gtk.Button] = {}
        self._tips: dict[str, str] = {}
        self.label = Gtk.Label(xalign=0.0, hexpand=True)
        self.label.set_use_markup(False)
        self.label.set_ellipsize(Pango.EllipsizeMode.END)  # a long camera name must not widen the window
        self.label.set_wrap_mode(Pango.WrapMode.WORD_CHAR)
        self.append(self.label)
        self.row = Gtk.Box(spacing=4, halign=Gtk.Align.END)
        """The buttons: beside the label, or under it on a phone (:meth:`set_compact`)."""
        self.append(self.row)
        for intent, icon, tip in (
            ("ptz_left", "go-previous-symbolic", _("Pan left (Ctrl+Left)")),
            ("ptz_up", "go-up-symbolic", _("Tilt up (Ctrl+Up)")),
            ("ptz_down", "go-down-symbolic", _("Tilt down (Ctrl+Down)")),
            ("ptz_right", "go-next-symbolic", _("Pan right (Ctrl+Right)")),
            ("ptz_zoom_out", "zoom-out-symbolic", _("Zoom out (Page Down)")),
            ("ptz_zoom_in", "zoom-in-symbolic", _("Zoom in (Page Up)")),
            ("ptz_home", "go-home-symbolic", _("Point straight ahead")),
        ):
            button = Gtk.Button.new_from_icon_name(icon)
            button.set_focusable(False)
            self._tips[intent] = tip
            accessible.name(button, accessible.spoken(tip))
            # The window's action (``win.ptz-left`` …), as the key's: a refusal is said the same way.
            button.connect("clicked", lambda b, i=intent: b.activate_action(f"win.{action_name(i)}", None))
            self.buttons[intent] = button
            self.row.append(button)
        self._unobserve = [
            model.robot.observe(self._on_robot),
            model.connection.observe(lambda _o, _n: self._show(self.model.robot.value)),
        ]
        self.connect("map", lambda _w: self._set_watching(True))
        self.connect("unmap", lambda _w: self._set_watching(False))
        self._show(model.robot.value)

    # -- state ---------------------------------------------------------------------------------
    @property
    def state(self) -> PtzState | None:
        return self.model.robot.value.ptz

    @property
    def reason(self) -> str:
        return disabled_reason(self.state, self.model.connection.value.connected)

    def set_compact(self, on: bool) -> None:
        """A phone: the position on a line of its own above the buttons, where it fits whole (beside
        seven buttons on 360 px it was cut to "Ca…")."""
        self.set_orientation(Gtk.Orientation.VERTICAL if on else Gtk.Orientation.HORIZONTAL)
        # The whole width is the label's there: a longer text ("moving to …") wraps, never cut.
        self.label.set_wrap(on)
        self.label.set_ellipsize(Pango.EllipsizeMode.NONE if on else Pango.EllipsizeMode.END)

    def close(self) -> None:
        """The window is going: unhook, and ask the runner for nothing more (it may be closed)."""
        self._closed = True
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        if self._picture_timer:
            GLib.source_remove(self._picture_timer)
            self._picture_timer = 0

    def _set_watching(self, on: bool) -> None:
        if on != self.watching and not self._closed:
            self.watching = on
            self._ask(WatchPtz(on))

    def follow_selection(self, old: RobotSession, new: RobotSession) -> None:
        """Another robot is shown: its head is polled while the page is, the old one's no longer."""
        if self.watching and not self._closed:
            old.controller.ask(WatchPtz(False))
            new.controller.ask(WatchPtz(True))

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        if old.ptz != new.ptz:
            self._show(new)

    def _show(self, robot: RobotState) -> None:
        state, reason = robot.ptz, self.reason
        self.label.set_text(
            position_text(state) if not reason else _("Camera head: {reason}").format(reason=reason)
        )
        for intent, button in self.buttons.items():
            ok = not reason and self._can(intent)
            button.set_sensitive(ok)
            why = _("Camera head: {value}").format(value=reason or _("not offered by this camera"))
            button.set_tooltip_text(self._tips[intent] if ok else why)
        self.label.set_tooltip_text(reason or None)

    def _can(self, intent: str) -> bool:
        state = self.state
        if state is None:
            return False
        if intent == "ptz_home":
            return state.can_abs
        if intent.startswith("ptz_zoom"):
            return state.can_rel and state.zoom_available
        return state.can_rel

    # -- moving --------------------------------------------------------------------------------
    def key(self, intent: str) -> str:
        """Run a PTZ intent (a button or a key); the reason it was refused, "" when sent."""
        reason = self.reason
        if reason:
            return reason
        if not self._can(intent):
            return _("this camera does not offer that move")
        if intent == "ptz_home":
            self._ask(PtzMove(0.0, 0.0, None, relative=False))
        else:
            pan, tilt, zoom = KEY_STEPS[intent]
            self._ask(PtzMove(pan, tilt, zoom))
        self._moved()
        return ""

    def attach_drag(self, widget: Gtk.Widget) -> None:
        """Dragging on ``widget`` (the picture) turns the head the way the drag goes."""
        drag = Gtk.GestureDrag()
        drag.connect("drag-end", self._drag_end)
        widget.add_controller(drag)

    def _drag_end(self, gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        widget = gesture.get_widget()
        width = max(widget.get_width(), 1) if widget is not None else 1
        height = max(widget.get_height(), 1) if widget is not None else 1
        pan, tilt = drag_to_move(dx, dy, width, height)
        if (pan, tilt) == (0.0, 0.0) or self.reason or not self._can("ptz_left"):
            return
        self._ask(PtzMove(pan, tilt, None))
        self._moved()

    def _moved(self) -> None:
        if self._on_moved is None:
            return
        if self._picture_timer:
            GLib.source_remove(self._picture_timer)

        def later() -> bool:
            self._picture_timer = 0
            if self._on_moved is not None and self.get_mapped():
                self._on_moved()
            return False

        self._picture_timer = GLib.timeout_add(PICTURE_AFTER_MS, later)


def drag_to_move(dx: float, dy: float, width: int, height: int) -> tuple[float, float]:
    """A drag of (dx, dy) px on a (width × height) picture → (pan, tilt) degrees; (0, 0) for a click.

    Right is a positive pan (ARIA's pan is clockwise positive); up is a positive tilt.
    """
    if (dx * dx + dy * dy) ** 0.5 < DRAG_MIN_PX:
        return (0.0, 0.0)
    pan = dx / max(width, 1) * DRAG_PAN_DEG
    tilt = -dy / max(height, 1) * DRAG_TILT_DEG
    return (round(pan, 1), round(tilt, 1))
