"""The map stage's render nodes (``rtmu.ui.stage_nodes``) show what the frame function draws, and
keep the static map's node while only the robot moves — so GTK, which repaints only where a frame's
nodes differ from the last one's, repaints the robot's neighbourhood, not the map (issue 28's follow
target). Nodes are made into a real ``Gtk.Snapshot`` and drawn by GSK itself, then compared with
``frame.draw_frame`` pixel by pixel."""

from __future__ import annotations

from pathlib import Path

import cairo
import gi
import numpy as np

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from rtmu.ui.frame import Scene  # noqa: E402
from rtmu.ui.map_layer import MapLayer  # noqa: E402
from rtmu.ui.stage_nodes import StageNodes  # noqa: E402
from rtmu.ui.tiles import TileCache  # noqa: E402
from rtmu.ui.viewport import Viewport, fit_view  # noqa: E402

from .office_frames import TOLERANCE, H, W, frame, ready, scene_of, views  # noqa: E402


def shown(nodes: StageNodes, scene: Scene, vp: Viewport, path: Path | None = None) -> tuple[np.ndarray, bool]:
    """One frame made into a snapshot by ``nodes`` and drawn by GSK: its pixels and its completeness."""
    snapshot = Gtk.Snapshot()
    complete = nodes.snapshot(snapshot, vp, scene)
    node = snapshot.to_node()
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, vp.width, vp.height)
    ctx = cairo.Context(surface)
    ctx.set_source_rgb(1, 0, 1)  # a colour no frame has: a hole in the nodes would show it
    ctx.paint()
    assert node is not None
    node.draw(ctx)
    surface.flush()
    if path is not None:
        surface.write_to_png(str(path))
    data = np.ndarray(
        (vp.height, vp.width, 4), np.uint8, surface.get_data(), strides=(surface.get_stride(), 4, 1)
    )
    return data[..., :3].astype(int).copy(), complete


def test_the_nodes_show_the_frame_the_frame_function_draws(
    screenshots: Path, office: object, tiles: TileCache
) -> None:
    for view, (vp, robot) in views(tiles, office).items():
        ready(tiles, vp)
        drawn = frame(scene_of(office, tiles, robot, None), vp)
        nodes = StageNodes()
        pixels, complete = shown(
            nodes, scene_of(office, tiles, robot, MapLayer()), vp, screenshots / f"stage-nodes-{view}.png"
        )
        assert complete and nodes.static_nodes == 1
        assert (drawn != pixels).any(axis=-1).sum() <= W * H // 1000, (
            f"{view}: over 0.1 % of the pixels differ"
        )
        assert np.abs(drawn - pixels).max() <= TOLERANCE, view


def test_a_moving_robot_keeps_the_static_node_and_its_overlays_stay_small(
    office: object, tiles: TileCache
) -> None:
    vp, (x, y, th) = views(tiles, office)["zoomed"]
    ready(tiles, vp)
    nodes, layer = StageNodes(), MapLayer()
    areas = []
    for step in range(8):  # a drive along the view: only the robot, its trail and heading change
        robot = (x + 40.0 * step, y, th + 5.0 * step)
        pixels, _complete = shown(nodes, scene_of(office, tiles, robot, layer), vp)
        areas.append(nodes.overlay_area)
        drawn = frame(scene_of(office, tiles, robot, None), vp)
        assert np.abs(drawn - pixels).max() <= TOLERANCE, f"step {step}"
    assert nodes.static_nodes == 1, "the static map's node was made again while only the robot moved"
    assert 0 < max(areas) < W * H // 10, f"the overlay nodes cover {max(areas)} px² of {W * H}"
    moved = vp.panned(300, 0)  # follow re-centres: a new view, a new node
    ready(tiles, moved)
    shown(nodes, scene_of(office, tiles, (x, y, th), layer), moved)
    assert nodes.static_nodes == 2


def test_without_a_stored_picture_one_node_covers_the_stage(office: object, tiles: TileCache) -> None:
    """A fresh cache has its index, no tile yet (``tiles`` renders them only when asked)."""
    vp = fit_view(tiles.bounds, W, H)  # type: ignore[arg-type]
    nodes = StageNodes()
    pixels, complete = shown(nodes, scene_of(office, tiles, (0.0, 0.0, 0.0), MapLayer()), vp)
    assert not complete and nodes.static_nodes == 0 and nodes.overlay_area == W * H
    assert not ((pixels == (255, 0, 255)).all(axis=-1)).any(), "a hole in the frame"
    ready(tiles, vp)
    _pixels, complete = shown(nodes, scene_of(office, tiles, (0.0, 0.0, 0.0), MapLayer()), vp)
    assert complete and nodes.static_nodes == 1


def test_a_stage_not_laid_out_yet_appends_nothing(office: object, tiles: TileCache) -> None:
    snapshot = Gtk.Snapshot()
    complete = StageNodes().snapshot(
        snapshot, Viewport(0, 0, 1.0, 0.0, 0.0), scene_of(office, tiles, (0.0, 0.0, 0.0), MapLayer())
    )
    assert not complete and snapshot.to_node() is None
