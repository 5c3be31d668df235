"""The map page: the map stage and everything over it; going to a point and setting the position.

One part of the window (``ui.window`` composes it), a ``Gtk.Overlay`` whose child is the map
stage (:class:`~rtmu.ui.mapview.MapStage`) and whose overlays are, bottom to top: the zoom / fit /
follow buttons, the touch D-pad, the camera inset, the motion pill, the pose bar of a pick mode,
the server's popup cards, the layers panel and the note under the map (not connected, no map …);
``dpad_place`` keeps the D-pad in its corner, on the page shown and clear of the rest.
Other parts add their own overlays to it (the gamepad's pill). A pick mode (Go to point, Set
position) is started here and confirmed by its bar; the intents go to the selected robot. The
D-pad drives only while Space can stop it (``Controller.pointer_may_drive``); it lets go of a
finger on STOP, on a switch of robot and when the window loses the keys. The zoom, fit and follow
buttons activate the window's actions (``win.zoom-in`` …, ``win.follow``), as their keys do;
``on_follow`` keeps the follow action's check in step with the map (a drag turns following off).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
gi.require_version("Graphene", "1.0")
from gi.repository import Gdk, Graphene, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..base.notices import Kind, Notice  # noqa: E402
from ..control.commands import COMMANDS, CommandState  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..model.observables import ConnectionState, MapModel, OperatorState, RobotModel  # noqa: E402
from ..values.intents import AnswerPopup, GotoGoal, GotoPose, Localize  # noqa: E402
from . import accessible  # noqa: E402
from .dpad import DPad  # noqa: E402
from .dpad_place import DPadPlacement  # noqa: E402
from .layers import LayersPanel  # noqa: E402
from .mapview import MapStage  # noqa: E402
from .motion import MotionIndicator, held_by  # noqa: E402
from .nav_draw import Marker, MarkerKind  # noqa: E402
from .notes import map_note  # noqa: E402
from .pip import PictureInPicture  # noqa: E402
from .popups import PopupStack  # noqa: E402
from .pose_bar import PoseBar, pose_words  # noqa: E402
from .pose_pick import PosePicker  # noqa: E402
from .state_words import reason_words  # noqa: E402
from .viewport import zoom_label  # noqa: E402

ROBOT_CLEAR_PX = 24
"""Half the square around the robot's drawn centre that banners keep clear of (the body at Fit and a
margin)."""


def touch_only(display: Gdk.Display | None = None) -> bool:
    """True when the only pointing device is a touchscreen (a tablet): then the D-pad shows by default."""
    display = display or Gdk.Display.get_default()
    seat = display.get_default_seat() if display is not None else None
    if seat is None:
        return False
    caps = seat.get_capabilities()
    if not caps & Gdk.SeatCapabilities.TOUCH:
        return False
    pointers = [
        d
        for d in seat.get_devices(Gdk.SeatCapabilities.POINTER)
        if d.get_source() in (Gdk.InputSource.MOUSE, Gdk.InputSource.TOUCHPAD, Gdk.InputSource.TRACKPOINT)
    ]
    return not pointers


class MapPage(Gtk.Overlay):
    """See the module notes. ``show_camera`` opens the camera page (a click on the inset),
    ``show_map`` brings this page back (a pick mode starts on it), ``hide_inset`` is the inset's ×."""

    def __init__(
        self,
        model: RobotModel,
        operator: OperatorState,
        robot: SelectedRobot,
        *,
        clock: Callable[[], float],
        status_age: Callable[[], float | None],
        show_camera: Callable[[], None],
        show_map: Callable[[], None],
        hide_inset: Callable[[], None],
    ) -> None:
        super().__init__()
        self.model, self.robot, self._show_map = model, robot, show_map
        self.on_follow: Callable[[bool], None] = lambda _on: None
        """Told whether the map follows the robot after every change of view (the window's action)."""
        self.stage = MapStage(model, operator, clock=clock, status_age=status_age)
        self.stage.on_view_changed = self._view_changed
        self.stage.limits = lambda: robot.session.controller.limits  # the stopping distance drawn ahead
        self.dpad = DPad(hold=self._hold, release=self._release, stop=self._stop)
        self.inset = PictureInPicture(show_camera, clock=clock, on_hide=hide_inset)
        self.set_child(self.stage)
        self.osd = self._osd()
        self.add_overlay(self.osd)
        self.add_overlay(self.dpad)
        self.add_overlay(self.inset)
        self.motion = MotionIndicator(model, held=self._drive_held)
        self.add_overlay(self.motion)
        self.picker = PosePicker(self.stage, changed=lambda: self.pose_bar.update())
        self.pose_bar = PoseBar(self.picker, self._pose_confirmed)
        self.add_overlay(self.pose_bar)
        # Server popups: cards over the map above the zoom buttons, never focusable (STOP is in the header).
        self.popup_stack = PopupStack(model.popups, self._answer_popup, clock=clock)
        self.add_overlay(self.popup_stack)
        self.layers = LayersPanel(model.drawings, model.connection, robot.ask)  # View → Layers…
        self.add_overlay(self.layers)
        self.note = self._note()
        self.add_overlay(self.note)
        self.dpad.set_visible(touch_only())
        self.inset.place(corner_free=not self.dpad.get_visible())
        # The D-pad in a corner, on the page shown, clear of the zoom row, the pick bar and (Fit) the robot.
        self.dpad_place = DPadPlacement(
            self.dpad, self, osd=self.osd, pose_bar=self.pose_bar, refit=self.stage.refit
        )
        self.stage.fit_room = self.dpad_place.fit_room
        self.stage.fit_floor = self.dpad_place.fit_floor
        self.stage.connect("resize", lambda *_a: self.dpad_place.queue())
        self.stage.connect("resize", lambda _s, width, _h: self.inset.fit_to(width))

    def _osd(self) -> Gtk.Widget:
        """Zoom −/label/+, Fit and Follow: big enough for a thumb, over the map's bottom right."""
        osd = Gtk.Box(spacing=2, halign=Gtk.Align.END, valign=Gtk.Align.END)
        osd.add_css_class("map-osd")
        osd.set_margin_end(10)
        osd.set_margin_bottom(10)

        def button(icon: str, tip: str, action: str, toggle: bool = False) -> Gtk.Button:
            b = (Gtk.ToggleButton if toggle else Gtk.Button)(icon_name=icon, tooltip_text=tip)
            b.add_css_class("flat")
            b.set_focusable(False)
            b.set_action_name(action)  # the window's action, as the key's
            accessible.name(b, accessible.spoken(tip))
            return b

        osd.append(button("zoom-out-symbolic", _("Zoom out (Ctrl+minus)"), "win.zoom-out"))
        self.zoom_label = Gtk.Label(label="100 %")
        self.zoom_label.add_css_class("zoom-label")
        osd.append(self.zoom_label)
        osd.append(button("zoom-in-symbolic", _("Zoom in (Ctrl+plus)"), "win.zoom-in"))
        osd.append(button("zoom-fit-best-symbolic", _("Fit map (Ctrl+0)"), "win.zoom-fit"))
        self.follow_button = button(
            "find-location-symbolic", _("Follow the robot (F)"), "win.follow", toggle=True
        )
        osd.append(self.follow_button)
        return osd

    def _note(self) -> Gtk.Label:
        """The note under the map (``notes.map_note``): plain text, never in the way of a click."""
        note = Gtk.Label(halign=Gtk.Align.CENTER, valign=Gtk.Align.END, visible=False)
        note.add_css_class("map-note")
        note.set_margin_bottom(62)  # above the zoom buttons, which a narrow window puts under it
        note.set_margin_start(12)
        note.set_margin_end(12)
        note.set_wrap(True)
        note.set_max_width_chars(60)
        note.set_justify(Gtk.Justification.CENTER)
        note.set_use_markup(False)
        note.set_can_target(False)
        return note

    # -- the view --------------------------------------------------------------------------------
    def _view_changed(self) -> None:
        label = _("Fit") if self.stage.fitted else ""
        zoom = zoom_label(self.stage.viewport.zoom)
        self.zoom_label.set_text(f"{label} {zoom}" if label else zoom)
        self.on_follow(self.stage.follow)  # the follow action's check (a drag turns following off)

    def toggle_follow(self) -> None:
        """F and the follow button (``win.follow``)."""
        self.stage.set_follow(not self.stage.follow)

    def update_note(self, connection: ConnectionState, map_model: MapModel) -> None:
        """The note under the map, from the connection phase and the map."""
        text = map_note(connection, map_model)
        if self.note.get_text() != text:
            self.note.set_text(text)
        self.note.set_visible(bool(text))

    def banner_room(self, ancestor: Gtk.Widget) -> tuple[tuple[float, float, float, float] | None, int]:
        """What the banners keep clear of on a phone, in ``ancestor``'s terms: the robot as drawn (None
        when the map is not shown), and how far above the page's bottom a column may end instead —
        above the thumb's D-pad and the server's cards (0 when there is no such place)."""
        robot, box = self.model.robot.value, None
        if self.get_mapped() and robot.numbers_at is not None:
            sx, sy = self.stage.viewport.to_screen(robot.x, robot.y)
            ok, point = self.stage.compute_point(ancestor, Graphene.Point().init(sx, sy))
            if ok:
                half = ROBOT_CLEAR_PX
                box = (point.x - half, point.y - half, point.x + half, point.y + half)
        bottom = 0
        if self.get_mapped() and self.dpad.get_mapped() and self.dpad.get_halign() == Gtk.Align.CENTER:
            cards = self.popup_stack
            if cards.get_mapped():  # the server's cards sit above the D-pad: above them
                bottom = cards.get_margin_bottom() + cards.get_height() + 8
            else:  # just above the D-pad (its measure counts its margin above the zoom row)
                bottom = self.dpad.measure(Gtk.Orientation.VERTICAL, -1)[1] + 8
        return box, bottom

    def set_dpad(self, on: bool) -> None:
        self.dpad.set_visible(on)
        self.inset.place(corner_free=not on)  # the D-pad takes the bottom-left corner

    def set_fov(self, on: bool) -> None:
        self.stage.show_fov = on
        self.stage.queue_draw()

    def refresh(self) -> None:
        """The window's timers: the motion pill; a redraw only when the robot went stale (or came
        back) without a new status — an unchanged frame is never drawn again."""
        self.motion.refresh()
        if self.stage.robot_is_stale() != self.stage.drawn_stale:
            self.stage.queue_draw()

    # -- the D-pad -------------------------------------------------------------------------------
    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        for name, state in states.items():
            label = _(COMMANDS.get(name).label) if name in COMMANDS else name
            self.dpad.set_command_state(name, state.enabled, reason_words(state.reason), label)

    def _hold(self, name: str) -> None:
        """A D-pad hold: only while Space can stop it (the controller says why not)."""
        controller = self.robot.session.controller
        if controller.pointer_may_drive():
            controller.run(name)

    def _release(self, name: str) -> None:
        self.robot.session.controller.release_command(name)

    def _stop(self) -> None:
        self.robot.session.controller.run("stop")

    def _drive_held(self) -> str:
        """What holds a live drive (``motion.held_by``)."""
        return held_by(self.robot.session.controller, bool(self.dpad.held))

    def let_go(self) -> None:
        """STOP, a switch of robot: a finger on the D-pad is let go of and a pick mode ends."""
        self.dpad.release_all()
        self.picker.cancel()

    # -- going somewhere -------------------------------------------------------------------------
    def goto_goal(self, goal: str) -> None:
        self.robot.ask(GotoGoal(goal))

    def start_pick(self, kind: MarkerKind) -> None:
        """Go to a point / set robot position: a map mode; the pose bar confirms (``pose_bar``)."""
        self._show_map()
        self.picker.start(kind)

    def _pose_confirmed(self, marker: Marker) -> None:
        if marker.kind is MarkerKind.GOTO:
            self.robot.ask(GotoPose(marker.x, marker.y, marker.th))
        else:
            th = self.model.robot.value.th if marker.th is None else marker.th
            if self.robot.ask(Localize(marker.x, marker.y, th)) is not None:  # (a refusal is said)
                placed = replace(marker, th=th)
                self.robot.session.controller.view.notify(  # the operator sees the pick was taken
                    Notice.info(
                        Kind.NAVIGATION, _("Position set: {lower}").format(lower=pose_words(placed).lower())
                    )
                )

    def _answer_popup(self, popup_id: int, button: int) -> None:
        self.robot.ask(AnswerPopup(popup_id, button))

    def close(self) -> None:
        self.dpad_place.close()
        self.stage.close()
        self.layers.unobserve()
        self.motion.close()
