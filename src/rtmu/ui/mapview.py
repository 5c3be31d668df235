"""The map stage: a ``Gtk.DrawingArea`` that shows cached map tiles and draws the robot on top.

Per frame it shows the background, the visible tiles from :class:`TileCache`
(or the stretched overview where a tile is still being rendered, or a metric
grid when the server has no map), then cairns, trail, sonar and the robot —
nothing that scales with the map's size — as render nodes (``stage_nodes``) in
place of the drawing area's own picture, so GTK repaints only where they changed.
It reads the model and never writes the network; zoom and follow are view state,
remembered in the operator's ``view``; the trail is the robot's (``RobotModel.trail``),
so it survives the view.

Input: drag to pan (turns Follow off), scroll or pinch to zoom about the
pointer, and the zoom/fit/follow methods the window binds to keys and buttons.
Follow keeps the robot inside the middle of the view (a dead zone, so the map
does not slide on every status update).
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable, Sequence

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..control.motion_limits import RobotLimits  # noqa: E402
from ..model.observables import LinkHealth, LinkLevel, MapModel, OperatorState, RobotModel, RobotState  # noqa: E402
from . import accessible, overlays  # noqa: E402
from .fleet_draw import FleetMark  # noqa: E402
from .fov_draw import Wedge, camera_aim  # noqa: E402
from .frame import Scene  # noqa: E402
from .map_layer import MapLayer  # noqa: E402
from .map_words import MapDescription  # noqa: E402
from .nav_draw import Marker, MarkerKind  # noqa: E402
from .stage_nodes import StageNodes  # noqa: E402
from .stop_draw import stop_reach  # noqa: E402
from .tiles import TileCache  # noqa: E402
from .viewport import ZOOM_MAX, ZOOM_MIN, Insets, Viewport, best_fit, nearest_step, step_zoom  # noqa: E402

FOLLOW_BOX = 0.3
"""Follow pans when the robot leaves the middle (1 − 2 × 0.3 = 40 %) of the view."""
FOLLOW_BOX_FITTED = 0.04
"""…or, while the whole map is fitted, only when it is about to leave the view."""
STALE_AFTER = 1.0
"""Seconds without a pose update after which the robot is drawn as stale."""
FRAME_LOG = 240
DRAWINGS_WAIT_MS = 150
"""New server drawings wait this long for a frame something else asks for (the robot's status,
10 Hz) before asking for one themselves. Redrawing the map for each drawings update on its own
(up to 20 a second, between the status frames) made every such frame repaint the whole map
while live video played: the window's frame time p95 went from ~6 ms to 21–24 ms. Drawings
refresh at 5 Hz, so riding on the status frames loses nothing visible."""


class MapStage(Gtk.DrawingArea):
    """See the module notes. ``on_view_changed`` tells the window zoom/follow changed (to update controls)."""

    def __init__(
        self,
        model: RobotModel,
        operator: OperatorState,
        *,
        clock: Callable[[], float] = time.monotonic,
        status_age: Callable[[], float | None] | None = None,
    ) -> None:
        super().__init__(accessible_role=Gtk.AccessibleRole.IMG)  # a drawing: "image" to a screen reader
        self.model = model
        self.operator = operator
        accessible.name(self, _("Map"))
        self.words = MapDescription(model, lambda text: accessible.describe(self, text))
        """The map in words (``map_words``): its description, said again when it changes materially."""
        self.clock = clock
        self.status_age = status_age
        self.show_fov = True
        """Draw the camera's field of view (View ▸ Camera field of view) where the server has a camera."""
        self.add_css_class("map-stage")
        self.set_hexpand(True)
        self.set_vexpand(True)
        self.set_focusable(False)
        self.viewport = Viewport(800, 480, 1.0, 0.0, 0.0)
        self.follow = operator.view.value.follow_robot
        self.fitted = operator.view.value.zoom == 0.0
        """The zoom is "fit the map" (re-fitted when the widget is resized or a map arrives)."""
        self.fit_room: Callable[[int, int], tuple[Insets, ...]] = lambda _w, _h: ()
        self.fit_floor: Callable[[int, int], tuple[Insets, ...]] = lambda _w, _h: ()
        """Ways for Fit to keep clear of an overlay at this size (``dpad_place``): none by default."""
        self.on_view_changed: Callable[[], None] | None = None
        self.on_first_map_frame: Callable[[float], None] | None = None
        """Called once per map with the time of the first frame that showed it completely."""
        self.frame_times: deque[float] = deque(maxlen=FRAME_LOG)
        """Seconds spent in each recent draw (the benchmark and the GUI tests read them)."""
        self.frames = 0
        self.last_frame_complete = False
        """The last frame showed a map with every visible tile ready."""
        self.drawn_stale = True
        """The last frame drew the robot greyed (or not at all): the window's timer redraws only when
        :meth:`robot_is_stale` no longer says the same."""
        self.labels = overlays.LabelCache()
        self.tiles = TileCache(self._tiles_ready_from_worker)
        self.layer = MapLayer()
        """The static map's picture for the current view: a frame that only moves the robot paints it."""
        self.nodes = StageNodes()
        """The frame's render nodes: the static map's node kept while its picture is (``stage_nodes``)."""
        self._tiles_pending = False
        self._map_shown_generation = -1
        self._objects: list[object] = []
        self._map_generation = -1
        self._drag_start: Viewport | None = None
        self._dragged = False
        self._pinch_start: Viewport | None = None
        self._pinch_anchor: tuple[float, float] | None = None
        self._pointer: tuple[float, float] | None = None
        self._scroll_accum = 0.0
        self.marker: Marker | None = None
        """A pose the operator is picking (``pose_pick`` sets it); drawn over the map."""
        self.draft_objects: list[object] | None = None
        """A map draft's objects, drawn instead of the map's own while it has edits (``map_edit_window``)."""
        self.fleet: Callable[[], tuple[Sequence[FleetMark], tuple[float, float, float]]] | None = None
        self.limits: Callable[[], RobotLimits] = RobotLimits
        """The shown robot's speed and braking (the window hands over its controller's)."""
        """In a fleet (``fleet_bind``): the other robots to draw and the selected robot's colour."""
        self._install_input()
        self._unobserve = [
            model.robot.observe(self._on_robot),
            model.map.observe(self._on_map),
            operator.view.observe(self._on_view_options),
            model.health.observe(self._on_health),
            model.trail.observe(self.queue_draw),
            model.navigation.observe(lambda old, new: self.queue_draw()),
            model.drawings.observe(self._on_drawings),
        ]
        self._drawings_source = 0
        self.drawings_wait_ms = DRAWINGS_WAIT_MS
        """How long new drawings wait for another frame (a test on a busy machine sets it longer)."""
        self.drawings_redraws = 0
        """Frames asked for by new drawings alone (none while status frames show them)."""
        self.connect("resize", self._on_resize)
        self._on_map(MapModel(), model.map.value)

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        self.words.close()
        self._cancel_drawings_redraw()
        self.tiles.close()
        self.layer.forget()
        self.nodes.forget()

    # -- model -------------------------------------------------------------------------------
    @property
    def map_data(self) -> object | None:
        m = self.model.map.value
        return m.data if m.state == "ready" else None

    def _on_map(self, old: MapModel, new: MapModel) -> None:
        if new.state == "ready" and new.data is not None:
            if new.generation != self._map_generation:
                self._map_generation = new.generation
                data = new.data
                self.tiles.set_map(getattr(data, "points", None), getattr(data, "segments", None))
                self._objects = list(getattr(data, "objects", []))
                if self.fitted:
                    self._fit_to_map(data)
                self._keep_robot_visible(centre=not self.fitted)
        elif new.state != old.state or new.state != "ready":
            if old.state == "ready" or self._map_generation != -1:
                self._map_generation = -1
                self.tiles.set_map(None, None)
                self._objects = []
                self.layer.forget()
                self.nodes.forget()
            if new.state in ("none", "unsupported", "unknown") and self.fitted:
                self._fit_no_map()
        self.queue_draw()

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        if new.numbers_at is not None and (new.x, new.y) != (old.x, old.y) and self.follow:
            self._keep_robot_visible()
        if self._drawn_of(old) != self._drawn_of(new) or self.robot_is_stale() != self.drawn_stale:
            self.queue_draw()

    def _drawn_of(self, r: RobotState) -> tuple[object, ...]:
        """What a frame shows of the robot's state: a change to anything else redraws nothing (the
        sonar comes as the server's drawings where it draws them; a status only restates the pose;
        the speed shows only as the stopping strip of a robot that moves)."""
        own_sonar = self.operator.view.value.show_sonar and not self.model.drawings.value.offered
        return (
            r.numbers_at is None,
            r.x,
            r.y,
            r.th,
            (r.sonar, r.laser) if own_sonar else None,
            r.ptz if self.show_fov else None,
            stop_reach(r.x, r.y, r.th, r.vel, self.limits()),  # the strip ahead of a moving robot
        )

    def _on_drawings(self, old: object, new: object) -> None:
        """Show new drawings with the next frame; ask for one only if none comes in time."""
        if not self._drawings_source:
            self._drawings_source = GLib.timeout_add(self.drawings_wait_ms, self._drawings_due)

    def _drawings_due(self) -> bool:
        self._drawings_source = 0
        self.drawings_redraws += 1
        self.queue_draw()
        return False

    def _cancel_drawings_redraw(self) -> None:
        if self._drawings_source:
            GLib.source_remove(self._drawings_source)
            self._drawings_source = 0

    def _on_view_options(self, old, new) -> None:
        """A profile switch (or the controller) changed zoom/follow: apply what differs from ours."""
        if new.follow_robot != self.follow:
            self.set_follow(new.follow_robot)
        if new.zoom == 0.0 and not self.fitted:
            self.fit()
        elif new.zoom and abs(new.zoom - self.viewport.zoom) > 1e-6:
            self.set_zoom(new.zoom)
        self.queue_draw()

    def _on_health(self, old: LinkHealth, new: LinkHealth) -> None:
        """The map shows the link's level only (a stale robot): a new round-trip time is no redraw."""
        if old.level is not new.level:
            self.queue_draw()

    def robot_is_stale(self) -> bool:
        r = self.model.robot.value
        if r.numbers_at is None:
            return True
        if self.model.health.value.level is not LinkLevel.OK:
            return True
        age = self.status_age() if self.status_age is not None else None
        return (age if age is not None else self.clock() - r.numbers_at) > STALE_AFTER

    # -- view state --------------------------------------------------------------------------
    def _publish_view(self) -> None:
        self.operator.view.update(zoom=0.0 if self.fitted else self.viewport.zoom, follow_robot=self.follow)
        if self.on_view_changed is not None:
            self.on_view_changed()

    def set_zoom(self, zoom: float, anchor: tuple[float, float] | None = None) -> None:
        if self.follow and anchor is None and self.model.robot.value.numbers_at is not None:
            r = self.model.robot.value
            anchor = self.viewport.to_screen(r.x, r.y)
        self.viewport = self.viewport.zoomed(zoom, anchor)
        self.fitted = False
        if self.follow:
            self._keep_robot_visible()
        self._publish_view()
        self.queue_draw()

    def zoom_in(self, anchor: tuple[float, float] | None = None) -> None:
        self.set_zoom(step_zoom(self.viewport.zoom, +1), anchor)

    def zoom_out(self, anchor: tuple[float, float] | None = None) -> None:
        self.set_zoom(step_zoom(self.viewport.zoom, -1), anchor)

    def fit(self) -> None:
        """Show the whole map (or 10 m around the robot without one); Follow stays as it is."""
        self.fitted = True
        data = self.map_data
        if data is not None:
            self._fit_to_map(data)
        else:
            self._fit_no_map()
        self._publish_view()
        self.queue_draw()

    def refit(self) -> None:
        """Fit again if fitted (an overlay that asks for room came or went)."""
        if self.fitted:
            self.fit()

    def set_follow(self, on: bool) -> None:
        self.follow = on
        if on:
            self._keep_robot_visible(centre=True)
        self._publish_view()
        self.queue_draw()

    def _fit_to_map(self, data: object) -> None:
        """Fit to the map's true extent, which the tile worker measures (not on this thread)."""
        bounds = self.tiles.bounds
        if bounds is None:
            return  # the index is being built; _tiles_ready fits again when it is

        self.viewport = self._fit_view(bounds)
        self._view_moved()

    def _fit_no_map(self) -> None:
        r = self.model.robot.value
        self.viewport = self._fit_view((r.x - 5000, r.y - 5000, r.x + 5000, r.y + 5000))
        self._view_moved()

    def _fit_view(self, bounds: tuple[float, float, float, float]) -> Viewport:
        """Fit ``bounds`` clear of the overlays that ask for room (``fit_room``: the D-pad and the zoom
        row; ``fit_floor``: the zoom row, kept even when the D-pad's room would shrink the map too far)."""
        width, height = self._size()
        return best_fit(bounds, width, height, self.fit_room(width, height), self.fit_floor(width, height))

    def _view_moved(self) -> None:
        """Zoom or centre changed without the operator: let the window's zoom label follow."""
        if self.on_view_changed is not None:
            self.on_view_changed()

    def _size(self) -> tuple[int, int]:
        return self.viewport.width, self.viewport.height

    def _keep_robot_visible(self, *, centre: bool = False) -> None:
        r = self.model.robot.value
        if r.numbers_at is None or not self.follow:
            return
        vp = self.viewport
        sx, sy = vp.to_screen(r.x, r.y)
        # A fitted map shows everything: move only when the robot is about to leave the view.
        box = FOLLOW_BOX_FITTED if self.fitted else FOLLOW_BOX
        mx, my = vp.width * box, vp.height * box
        outside = not (mx <= sx <= vp.width - mx and my <= sy <= vp.height - my)
        if self.fitted and self.map_data is None:
            if outside or centre:
                self._fit_no_map()  # "fit" without a map = the 10 m around the robot
            return
        if centre or outside:
            # Re-centre on the robot (one jump, rather than creeping along the edge every update).
            self.viewport = vp.centred(r.x, r.y)
            if self.fitted:
                self.fitted = False
                if self.on_view_changed is not None:
                    self.on_view_changed()

    def _on_resize(self, _area: Gtk.DrawingArea, width: int, height: int) -> None:
        self.viewport = self.viewport.sized(width, height)
        if self.fitted:
            data = self.map_data
            if data is not None:
                self._fit_to_map(data)
            else:
                self._fit_no_map()
            if self.on_view_changed is not None:
                self.on_view_changed()
        elif self.follow:
            self._keep_robot_visible(centre=True)

    # -- tiles -------------------------------------------------------------------------------
    def _tiles_ready_from_worker(self) -> None:
        """Worker thread: new tiles; ask for one redraw on the GTK thread."""
        GLib.idle_add(self._tiles_ready)

    def _tiles_ready(self) -> bool:
        if self.map_data is not None and self.fitted and self.tiles.bounds is not None:
            # The index knows the true bounds now (the header's may lie): fit again once.
            vp = self._fit_view(self.tiles.bounds)
            if abs(vp.zoom - self.viewport.zoom) > 1e-9 or (vp.cx, vp.cy) != (
                self.viewport.cx,
                self.viewport.cy,
            ):
                self.viewport = vp
                if self.on_view_changed is not None:
                    self.on_view_changed()
        self.queue_draw()
        return False

    # -- drawing -----------------------------------------------------------------------------
    def do_snapshot(self, snapshot: Gtk.Snapshot) -> None:
        """The frame as render nodes (``stage_nodes``): GTK repaints only where they changed."""
        started = time.perf_counter()
        self._cancel_drawings_redraw()  # this frame shows the latest drawings
        width, height = self.get_width(), self.get_height()
        if (width, height) != self._size():
            self.viewport = self.viewport.sized(width, height)
        complete = self.nodes.snapshot(snapshot, self.viewport, self.scene())
        elapsed = time.perf_counter() - started
        self.frame_times.append(elapsed)
        self.frames += 1
        self.last_frame_complete = complete
        if complete and self._map_shown_generation != self._map_generation:
            self._map_shown_generation = self._map_generation
            if self.on_first_map_frame is not None:
                self.on_first_map_frame(time.perf_counter())

    def scene(self) -> Scene:
        """What the next frame shows, read from the model and the view options."""
        r = self.model.robot.value
        has_map = self.model.map.value.state == "ready"
        stale = self.drawn_stale = self.robot_is_stale()
        drawings = self.model.drawings.value
        scene = Scene(
            labels=self.labels,
            tiles=self.tiles if has_map else None,
            objects=self._objects if self.draft_objects is None else self.draft_objects,
            robot=(r.x, r.y, r.th) if r.numbers_at is not None else None,
            stale=stale,
            trail=self.model.trail.points,
            sonar=r.sonar if self.operator.view.value.show_sonar and not drawings.offered else (),
            laser=r.laser if self.operator.view.value.show_sonar and not drawings.offered else (),
            drawings=drawings.layers,  # the server's own sonar/laser drawings replace RTMU's colours
            layer=self.layer,
        )
        self.layer.scale = self.get_scale_factor()
        if self.fleet is not None:  # the fleet's other robots and the selected one's colour
            scene.others, scene.robot_rgb = self.fleet()
        self._add_navigation(scene)
        if self.show_fov and scene.robot is not None and self._has_camera():
            scene.fov = Wedge(*scene.robot, *camera_aim(self.model.robot.value.ptz))
        if scene.robot is not None:
            scene.stop_reach = stop_reach(r.x, r.y, r.th, r.vel, self.limits())
        return scene

    def _has_camera(self) -> bool:
        offers = self.model.connection.value.offers
        return "sendVideo" in offers or any(name.startswith("getPicture") for name in offers)

    def _add_navigation(self, scene: Scene) -> None:
        """While the server navigates: its path, and the goal ringed (or the point marked)."""
        scene.marker = self.marker
        nav = self.model.navigation.value
        if not nav.navigating:
            return
        scene.path = nav.path
        if nav.target_pose is not None:
            x, y, th = nav.target_pose
            if nav.target == "point":
                scene.marker = scene.marker or Marker(MarkerKind.GOTO, x, y, th)
            else:
                scene.goal = (x, y)

    # -- input -------------------------------------------------------------------------------
    def _install_input(self) -> None:
        drag = Gtk.GestureDrag()
        drag.connect("drag-begin", self._drag_begin)
        drag.connect("drag-update", self._drag_update)
        drag.connect("drag-end", self._drag_end)
        self.add_controller(drag)

        motion = Gtk.EventControllerMotion()
        motion.connect("motion", lambda _c, x, y: setattr(self, "_pointer", (x, y)))
        motion.connect("leave", lambda _c: setattr(self, "_pointer", None))
        self.add_controller(motion)

        scroll = Gtk.EventControllerScroll.new(Gtk.EventControllerScrollFlags.VERTICAL)
        scroll.connect("scroll", self._scroll)
        self.add_controller(scroll)

        pinch = Gtk.GestureZoom()
        pinch.connect("begin", self._pinch_begin)
        pinch.connect("scale-changed", self._pinch_changed)
        pinch.connect("end", self._pinch_end)
        self.add_controller(pinch)
        drag.group(pinch)

    def _drag_begin(self, _g: Gtk.GestureDrag, _x: float, _y: float) -> None:
        self._drag_start = self.viewport
        self._dragged = False

    def _drag_update(self, _g: Gtk.GestureDrag, dx: float, dy: float) -> None:
        if self._drag_start is None or self._pinch_start is not None:
            return
        if not self._dragged and math.hypot(dx, dy) < 6:
            return
        if not self._dragged:
            self._dragged = True
            self.fitted = False
            if self.follow:
                self.follow = False
                self._publish_view()
        self.viewport = self._drag_start.panned(dx, dy)
        self.queue_draw()

    def _drag_end(self, _g: Gtk.GestureDrag, _dx: float, _dy: float) -> None:
        if self._dragged:
            self._publish_view()
        self._drag_start = None

    def _scroll(self, _c: Gtk.EventControllerScroll, _dx: float, dy: float) -> bool:
        self._scroll_accum += dy
        steps = int(self._scroll_accum)
        if steps == 0:
            return True
        self._scroll_accum -= steps
        anchor = None if self.follow else self._pointer
        self.set_zoom(step_zoom(self.viewport.zoom, -steps), anchor)
        return True

    def _pinch_begin(self, _g: Gtk.GestureZoom, _seq: object) -> None:
        self._pinch_start = self.viewport
        self._pinch_anchor = None

    def _pinch_changed(self, g: Gtk.GestureZoom, scale: float) -> None:
        start = self._pinch_start
        if start is None:
            return
        ok, cx, cy = g.get_bounding_box_center()
        anchor = (cx, cy) if ok and not self.follow else None
        self._pinch_anchor = anchor
        low = min(ZOOM_MIN, start.zoom)  # a "fit" below 10 % may stay there, but a pinch goes no lower
        self.viewport = start.zoomed(min(ZOOM_MAX, max(low, start.zoom * scale)), anchor)
        self.fitted = False
        self.queue_draw()

    def _pinch_end(self, _g: Gtk.GestureZoom, _seq: object) -> None:
        if self._pinch_start is not None:
            zoom = self.viewport.zoom
            if zoom >= ZOOM_MIN:  # end on a stop (tiles reused), about the fingers' point so it stays put
                self.viewport = self.viewport.zoomed(nearest_step(zoom), self._pinch_anchor)
            self._pinch_start = None
            self._pinch_anchor = None
            self._publish_view()
            self.queue_draw()
