"""The map stage's frame as render nodes, so that GTK repaints only what changed.

Why: a ``Gtk.DrawingArea`` hands GTK one new picture of its whole area every frame, so while the robot
drives (10 frames a second) GTK composited the whole map again and sent all of it to the display, though
only the robot and what moves with it had changed — most of the window's CPU while following (issue
28). GTK compares each frame's render nodes with the last frame's and repaints only where they differ,
and a node that is the very object of the last frame costs nothing. So :class:`StageNodes` turns the
stored picture of the static map (:class:`~rtmu.ui.map_layer.MapLayer`) into one node kept for as long
as that picture is, and records the overlays into a node no bigger than their ink: a frame that moves
the robot repaints where the overlays were and where they are now.

While there is no stored picture (no map, tiles still coming, no layer) the frame is one node of the
whole area drawn directly, as a drawing area would. Either way it draws what ``frame.draw_frame``
draws, with the same functions in the same order.
"""

from __future__ import annotations

import math

import cairo
import gi

gi.require_version("Gsk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Graphene, Gsk, Gtk  # noqa: E402

from .frame import Scene, base_drawer, draw_base, draw_overlays, shown_tiles  # noqa: E402
from .viewport import Viewport  # noqa: E402


def _rect(x: float, y: float, width: float, height: float) -> Graphene.Rect:
    return Graphene.Rect().init(x, y, width, height)


class StageNodes:
    """Builds each frame's nodes; keeps the static map's node between frames."""

    def __init__(self) -> None:
        self._picture: cairo.ImageSurface | None = None
        self._static: Gsk.RenderNode | None = None
        self.static_nodes = 0
        """Static-map nodes made so far (a test reads it: one per stored picture, not per frame)."""
        self.overlay_area = 0
        """The last frame's overlay node in logical pixels² (0: none); a test reads it."""

    def forget(self) -> None:
        """Drop the kept node (and with it the picture it shows)."""
        self._picture, self._static = None, None

    def snapshot(self, snapshot: Gtk.Snapshot, vp: Viewport, scene: Scene) -> bool:
        """Append one frame of ``scene`` at ``vp``; True when a map is shown with every visible tile ready."""
        if vp.width <= 0 or vp.height <= 0:  # not laid out yet: nothing to show
            return False
        tiles = shown_tiles(scene)
        robot_xy = scene.robot[:2] if scene.robot is not None else None
        picture = None
        if tiles is not None and scene.layer is not None:
            picture = scene.layer.picture(vp, tiles, scene.objects, robot_xy, base_drawer(scene))
        if picture is None:
            self.forget()
            ctx = snapshot.append_cairo(_rect(0, 0, vp.width, vp.height))
            ctx.new_path()
            complete = draw_base(ctx, vp, scene, robot_xy)
            draw_overlays(ctx, vp, scene)
            self.overlay_area = vp.width * vp.height
            return complete
        snapshot.append_node(self._static_node(picture, vp))
        self._append_overlays(snapshot, vp, scene)
        return True

    def _static_node(self, picture: cairo.ImageSurface, vp: Viewport) -> Gsk.RenderNode:
        if self._static is None or picture is not self._picture:  # a new view is a new picture (its size too)
            node = Gsk.CairoNode.new(_rect(0, 0, vp.width, vp.height))
            ctx = node.get_draw_context()  # records: replayed at the display's scale, sharp on HiDPI
            ctx.set_source_surface(picture, 0, 0)
            ctx.rectangle(0, 0, vp.width, vp.height)
            ctx.fill()
            del ctx
            self._picture, self._static = picture, node
            self.static_nodes += 1
        return self._static

    def _append_overlays(self, snapshot: Gtk.Snapshot, vp: Viewport, scene: Scene) -> None:
        # Bounded by the stage, as the window's own surface is: geometry far outside (a hostile pose, a
        # trail across the building) is clipped as it is recorded, and the ink is measured inside only.
        stage = cairo.Rectangle(0, 0, vp.width, vp.height)
        recording = cairo.RecordingSurface(cairo.CONTENT_COLOR_ALPHA, stage)
        ctx = cairo.Context(recording)
        draw_overlays(ctx, vp, scene)
        del ctx
        x, y, width, height = recording.ink_extents()
        left, top = max(0, math.floor(x)), max(0, math.floor(y))
        right, bottom = min(vp.width, math.ceil(x + width)), min(vp.height, math.ceil(y + height))
        if right <= left or bottom <= top:
            self.overlay_area = 0
            return
        self.overlay_area = (right - left) * (bottom - top)
        out = snapshot.append_cairo(_rect(left, top, right - left, bottom - top))
        out.set_source_surface(recording, 0, 0)
        out.paint()
