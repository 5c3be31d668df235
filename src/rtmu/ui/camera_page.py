"""The camera page, and where the robot's pictures go: the page, the map's inset and the split pane.

One part of the window (``ui.window`` composes it): the camera view with its pan-tilt-zoom bar and
live-video controls, the header's camera button, the switch between the map and this page, and the
way a picture travels — the model's camera part is decoded on the JPEG thread
(:class:`~rtmu.ui.camera.PictureDecoder`), then shown on the page, in the inset over the map and in
the split view's pane, and only then is the next live frame asked for (after the window painted
this one). Looking at the camera never stops a navigation: the controller's ``look`` ends a held
drive only. What it asks of a robot goes as intents through the selected robot
(:class:`~rtmu.fleet.selected.SelectedRobot`), so after a switch of robot the head, the video and
the pictures are the new robot's.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..control.commands import CommandState  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..model.observables import CameraImage, ConnectionState, Phase, RobotModel  # noqa: E402
from ..values.intents import PauseVideo, StartVideo, StopVideo, VideoShown  # noqa: E402
from . import accessible  # noqa: E402
from .banners import BannerStack  # noqa: E402
from .camera import CameraView, PictureDecoder  # noqa: E402
from .live_video import LiveVideoControls  # noqa: E402
from .motion import MotionIndicator, held_by  # noqa: E402
from .pip import PictureInPicture  # noqa: E402
from .ptz_controls import PtzControls  # noqa: E402
from .split_view import SplitView  # noqa: E402
from .state_words import reason_words  # noqa: E402

PAGE = "camera"
"""The camera page's name in the window's stack (the map's is ``map``)."""
BUTTON_TIP = N_("Camera picture (Esc)")


class CameraPage:
    """See the module notes. ``page_changed`` tells the window the page shown changed (its actions
    follow). The header's camera button activates the window's ``win.camera`` (as Esc does)."""

    def __init__(
        self,
        model: RobotModel,
        robot: SelectedRobot,
        banners: BannerStack,
        *,
        stack: Gtk.Stack,
        inset: PictureInPicture,
        split: SplitView,
        command_state: Callable[[str], CommandState],
        page_changed: Callable[[], None],
        clock: Callable[[], float],
    ) -> None:
        self.model, self.robot, self.banners = model, robot, banners
        self.stack, self.inset, self.split = stack, inset, split
        self._command_state, self._page_changed = command_state, page_changed
        self.view = CameraView(on_request=self.request_picture, on_back=self.show_map, clock=clock)
        self.ptz = PtzControls(model, robot.ask, on_moved=self.request_picture)
        self.ptz.attach_drag(self.view.picture)
        self.view.append(self.ptz)
        self.live = LiveVideoControls(
            self.view, start=lambda fps, quality: robot.ask(StartVideo(fps, quality)),
            stop=lambda: robot.ask(StopVideo()), pause=lambda on: robot.ask(PauseVideo(on)),
            tell=lambda level, text: banners.tell("camera", level, text, timeout=5.0),
        )  # fmt: skip
        # The motion pill here too (top right: the video's caption has the top left): looking at the
        # camera never hides that the robot is navigating or driven.
        self.motion = MotionIndicator(model, held=lambda: held_by(robot.session.controller, False))
        self.motion.set_halign(Gtk.Align.END)
        self.view.overlay.add_overlay(self.motion)
        self.decoder = PictureDecoder(self.picture_decoded)
        self.button = Gtk.ToggleButton(icon_name="camera-photo-symbolic")
        """The header's camera button: pressed while the page shows."""
        self.button.set_focusable(False)
        self.button.set_tooltip_text(_(BUTTON_TIP))
        accessible.name(self.button, _("Camera picture"))
        self.button.connect("clicked", self._button_clicked)
        # What the page holds on a robot (the head polled, the video playing) moves with the selection.
        robot.on_switch(self.ptz.follow_selection)
        robot.on_switch(self.live.follow_selection)
        self._unobserve = model.camera.observe(self._on_camera)

    @property
    def showing(self) -> bool:
        """The camera page is the one on screen."""
        return self.stack.get_visible_child_name() == PAGE

    # -- the page ------------------------------------------------------------------------------
    def show_camera(self, request: bool = False) -> None:
        """Show the page (``request``: with a new picture); refused with the reason while no camera."""
        state = self._command_state("request_image")
        if request and not state.enabled:
            self.banners.tell(
                "camera",
                "warning",
                _("Camera picture: {reason}").format(reason=reason_words(state.reason)),
                timeout=4.0,
            )
            self.button.set_active(False)
            return
        self.robot.session.controller.look(_("the camera page"))  # a held drive ends; a navigation goes on
        self.stack.set_visible_child_name(PAGE)
        self.button.set_active(True)
        if (request or self.view.image is None) and not self.live.live:
            self.request_picture()  # (live video is the picture: no "Requesting…" over it)

    def show_map(self) -> None:
        self.stack.set_visible_child_name("map")
        self.button.set_active(False)
        self._page_changed()

    def toggle(self) -> None:
        """Camera ⇄ map (Esc, the header button)."""
        if self.showing:
            self.show_map()
        else:
            self.show_camera(request=True)

    def _button_clicked(self, button: Gtk.ToggleButton) -> None:
        if button.get_active() != self.showing:
            button.activate_action("win.camera", None)

    def request_picture(self) -> None:
        if self.robot.session.controller.run("request_image"):
            self.view.requesting()

    def commands_changed(self, states: dict[str, CommandState]) -> None:
        """The camera's command state: the button (usable on the page to go back) and the page's own."""
        state = states.get("request_image")
        if state is None:
            return
        self.button.set_sensitive(state.enabled or self.showing)
        self.button.set_tooltip_text(
            _(BUTTON_TIP)
            if state.enabled
            else _("Camera picture: {reason}").format(reason=reason_words(state.reason))
        )
        self.view.set_available(state.enabled, reason_words(state.reason))

    # -- keys ----------------------------------------------------------------------------------
    def live_key(self) -> None:
        """V: live video on (where the server has a camera) or off, from any page."""
        camera = self._command_state("request_image")
        if reason := self.live.toggle(camera.enabled, camera.reason):
            self.banners.tell(
                "camera", "warning", _("Live video: {reason}").format(reason=reason), timeout=4.0
            )

    def ptz_key(self, name: str) -> None:
        """A pan-tilt-zoom move (``ptz_left`` …); the reason it cannot go, as a banner."""
        if reason := self.ptz.key(name):
            self.banners.tell("ptz", "warning", _("Camera head: {reason}").format(reason=reason), timeout=4.0)

    def set_split(self, on: bool) -> None:
        """Map and video side by side: the split starts live video (the pane would show nothing else)."""
        self.split.set_split(on)
        self.inset.set_beside(on)
        if on and not self.live.live and self._command_state("request_image").enabled:
            self.live.set_live(True)

    # -- pictures ------------------------------------------------------------------------------
    def _on_camera(self, _old: CameraImage | None, new: CameraImage | None) -> None:
        if new is not None:
            self.decoder.decode(new)

    def picture_decoded(
        self, image: CameraImage, textures: tuple[Gdk.Texture, Gdk.Texture] | None, error: str
    ) -> None:
        """A decoded picture (GTK thread): onto every view of it that still shows the newest."""
        current = self.model.camera.value
        frame = image.frame
        if frame is not None:  # the next frame only once this one is painted
            shows = (self.view.picture, self.inset, self.split.pane)
            seen = textures is not None and image is current and any(w.get_mapped() for w in shows)
            self.live.when_painted(lambda: self.robot.ask(VideoShown(frame)), seen)
        if current is None or image is not current:
            return  # a newer picture (or a disconnect) overtook this one
        self.view.show_picture(image, None if textures is None else textures[0], error)
        if textures is not None:
            self.inset.show_texture(self.inset.texture_for(*textures), image.received_at)
            self.live.shown(image)
            self.split.show_picture(textures[0], image)

    def connection_changed(self, old: ConnectionState, new: ConnectionState) -> None:
        """A picture from an earlier connection is not the robot's view: forgotten, or greyed while lost."""
        phase = new.phase
        if phase is Phase.DISCONNECTED or (phase is Phase.CONNECTING and old.phase is not Phase.RECONNECTING):
            self.view.clear()
            self.live.connection_lost()
            self.split.show_picture(None, None)
            if self.showing:
                self.show_map()
        # The inset is a glance at the robot's view: greyed (with its age) while the link is lost,
        # gone once a new connection is made.
        if phase in (Phase.DISCONNECTED, Phase.CONNECTING) or (
            phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED
        ):
            self.inset.show_texture(None)
        elif phase in (Phase.RECONNECTING, Phase.FAILED):
            self.inset.set_live(False)

    def robot_shown(self) -> None:
        """Another robot is shown: no picture of the one before stays on screen."""
        self.view.clear()
        self.inset.show_texture(None)

    def tick(self) -> None:
        """Ages on the page and the inset, the page's motion pill (the window's slow timer)."""
        self.view.tick()
        self.inset.tick()
        if self.showing:
            self.motion.refresh()

    def close(self) -> None:
        self._unobserve()
        self.motion.close()
        self.ptz.close()
        self.decoder.close()
