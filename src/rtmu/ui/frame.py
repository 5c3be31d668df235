"""One frame of the map stage, GTK-free: the window and the benchmark draw with the same functions
(``draw_frame`` here; the window, through ``stage_nodes``, the same static part — the layer's picture
or ``draw_base`` — and ``draw_overlays``, each into render nodes of their own).

Cost per frame does not grow with the map: the static map comes from the tile
cache (a blit per visible tile, or the stretched overview while a tile is still
being rendered), then the overlays — cairns, trail, sonar, robot — are drawn on
top (the fleet's other robots, ``fleet_draw``, under the selected one), with navigation
(``nav_draw``: planned path, goal ring, a picked pose) between the cairns and the robot.
Without a map: a metric grid and its legend. The static part — background, tiles, cairns — comes
from the stage's :class:`~rtmu.ui.map_layer.MapLayer` when it has one for this view.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import cairo

from ..base.i18n import _
from ..values.state import DrawingLayer
from . import drawings_draw, fleet_draw, fov_draw, nav_draw, overlays, stop_draw
from .map_layer import DrawBase, MapLayer
from .overlays import Box
from .tiles import BACKGROUND_RGB, EMPTY, TILE, Overview, TileCache
from .viewport import Viewport


@dataclass
class Scene:
    """What a frame shows. ``tiles`` None (or not ready) = no map: draw the grid."""

    labels: overlays.LabelCache
    tiles: TileCache | None = None
    objects: Sequence[object] = ()
    robot: tuple[float, float, float] | None = None
    """x, y (mm), th (deg); None = no robot known."""
    stale: bool = False
    trail: Iterable[tuple[float, float]] = ()
    sonar: Sequence[tuple[int, int]] = field(default_factory=tuple)
    laser: Sequence[tuple[int, int]] = field(default_factory=tuple)
    """Laser points (LD robots' ``Laser_*Current``), global mm; drawn under the sonar."""
    path: Sequence[tuple[int, int]] = ()
    """The planned path still ahead (``getPath``, mm) while the server navigates."""
    goal: tuple[float, float] | None = None
    """The cairn the robot is heading for, ringed."""
    marker: nav_draw.Marker | None = None
    """A pose the operator is picking (go to a point, set the robot's position)."""
    others: Sequence[fleet_draw.FleetMark] = ()
    """The fleet's other robots on this map, each in its colour with its trail."""
    robot_rgb: tuple[float, float, float] = overlays.ROBOT_RGB
    """The selected robot's colour (its fleet colour; blue for a robot alone)."""
    fov: fov_draw.Wedge | None = None
    """The camera's field of view, drawn as a wedge from the robot (None: not shown)."""
    drawings: Sequence[DrawingLayer] = ()
    """The server's drawings (``drawings_draw``) in their shapes and colours, under or over the robot."""
    stop_reach: stop_draw.StopReach | None = None
    """While the robot moves: the strip it sweeps before it can stand still (``stop_draw``)."""
    layer: MapLayer | None = None
    """The stored picture of the static map (None: draw it every frame)."""


def draw_frame(ctx: cairo.Context, vp: Viewport, scene: Scene) -> bool:
    """Draw one frame; True when a map is shown with every visible tile ready."""
    ctx.new_path()  # every helper starts its own path too; a frame never inherits one
    complete = draw_static(ctx, vp, scene)
    draw_overlays(ctx, vp, scene)
    return complete


def shown_tiles(scene: Scene) -> TileCache | None:
    """The scene's tile cache when it has a map ready to show (None: the grid is drawn)."""
    return scene.tiles if scene.tiles is not None and scene.tiles.ready else None


def draw_static(ctx: cairo.Context, vp: Viewport, scene: Scene) -> bool:
    """The static part — from the stored picture where there is one for this view, else directly."""
    tiles = shown_tiles(scene)
    robot_xy = scene.robot[:2] if scene.robot is not None else None
    layer = scene.layer
    if (
        tiles is not None
        and layer is not None
        and layer.paint(ctx, vp, tiles, scene.objects, robot_xy, base_drawer(scene))
    ):
        return True
    return draw_base(ctx, vp, scene, robot_xy)


def base_drawer(scene: Scene) -> DrawBase:
    """How a :class:`MapLayer` makes its picture of ``scene``'s static part."""
    return lambda ctx, vp, avoided, names: draw_base(ctx, vp, scene, avoided, names)


def draw_overlays(ctx: cairo.Context, vp: Viewport, scene: Scene) -> None:
    """Everything over the static map: navigation, the fleet, the field of view, the stopping strip,
    the trail, sonar, laser, the server's drawings and the robot (what changes as the robot moves)."""
    has_map = shown_tiles(scene) is not None
    if scene.goal is not None:
        nav_draw.draw_goal_highlight(ctx, vp, *scene.goal)
    nav_draw.draw_path(ctx, vp, scene.robot[:2] if scene.robot is not None else None, scene.path)
    if scene.marker is not None:
        nav_draw.draw_marker(ctx, vp, scene.marker)
    if scene.others:
        fleet_draw.draw_fleet(ctx, vp, scene.others, footprint=has_map)
    if scene.fov is not None and scene.robot is not None:
        fov_draw.draw_fov(ctx, vp, scene.fov)
    if scene.stop_reach is not None and scene.robot is not None and not scene.stale:
        stop_draw.draw_stop_reach(ctx, vp, scene.stop_reach)
    if scene.robot is not None:
        x, y, th = scene.robot
        overlays.draw_trail(ctx, vp, scene.trail, (*scene.robot_rgb, fleet_draw.TRAIL_ALPHA))
        if scene.laser and not scene.stale:
            overlays.draw_laser(ctx, vp, scene.laser)
        if scene.sonar and not scene.stale:
            overlays.draw_sonar(ctx, vp, (x, y), scene.sonar)
        if not scene.stale:
            drawings_draw.draw_layers(ctx, vp, scene.drawings, (x, y), above_robot=False)
        overlays.draw_robot(ctx, vp, x, y, th, stale=scene.stale, footprint=has_map, rgb=scene.robot_rgb)
        if not scene.stale:
            drawings_draw.draw_layers(ctx, vp, scene.drawings, (x, y), above_robot=True)


def draw_base(
    ctx: cairo.Context,
    vp: Viewport,
    scene: Scene,
    robot_xy: tuple[float, float] | None,
    names: list[Box] | None = None,
) -> bool:
    """The static part: background, tiles (or the grid) and cairns, names moved from under ``robot_xy``.

    True when a map is shown with every visible tile ready."""
    ctx.set_source_rgb(*BACKGROUND_RGB)
    ctx.paint()
    complete = False
    if scene.tiles is not None and scene.tiles.ready:
        complete = draw_tiles(ctx, vp, scene.tiles)
    else:
        step = overlays.draw_grid(ctx, vp)
        overlays.draw_scale_note(ctx, scene.labels, _("grid {metres}").format(metres=overlays.metres(step)))
    if scene.objects:
        avoid = overlays.robot_box(vp, *robot_xy) if robot_xy is not None else None
        overlays.draw_cairns(ctx, vp, scene.objects, scene.labels, avoid, names)
    return complete


def draw_tiles(ctx: cairo.Context, vp: Viewport, tiles: TileCache) -> bool:
    spots = tiles.visible(vp.scale, vp.origin, vp.width, vp.height)
    overview = tiles.overview
    complete = True
    ctx.new_path()
    for spot in spots:
        surface = spot.surface
        if surface is EMPTY:
            continue
        if surface is None:
            complete = False
            if overview is not None:
                _from_overview(ctx, vp, overview, spot.x, spot.y)
            continue
        ctx.set_source_surface(surface, spot.x, spot.y)  # type: ignore[arg-type]
        ctx.rectangle(spot.x, spot.y, TILE, TILE)
        ctx.fill()
    return complete


def _from_overview(ctx: cairo.Context, vp: Viewport, overview: Overview, x: int, y: int) -> None:
    """A tile that is not ready yet: the same area from the whole-map overview, stretched."""
    ratio = vp.scale / overview.scale
    ox, oy = vp.origin
    ctx.save()
    ctx.new_path()
    ctx.rectangle(x, y, TILE, TILE)
    ctx.clip()
    ctx.translate(ox, oy)
    ctx.scale(ratio, ratio)
    ctx.set_source_surface(overview.surface, overview.gx0, overview.gy0)
    ctx.get_source().set_filter(cairo.FILTER_FAST)
    ctx.paint()
    ctx.restore()
