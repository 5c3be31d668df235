"""The stored map picture (``rtmu.ui.map_layer``) draws what the direct path draws, pixel by pixel.

Frames of the office map, drawn without a window by the window's own frame function: once with the
static map drawn directly and once painted from the stored picture, at the fitted view and zoomed in
while the robot moves. The picture is made once per view, not once per frame (the gain of issue 28's
follow target), and steps aside — the direct path draws — while a tile is missing or the robot
stands where a name sits (the name then moves from under it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rtmu.ui.map_layer import MapLayer
from rtmu.ui.tiles import TileCache
from rtmu.ui.viewport import Viewport, fit_view

from .office_frames import TOLERANCE, H, W, frame, named, ready, scene_of, views


@pytest.mark.parametrize("view", ["fitted", "zoomed"])
def test_the_stored_picture_draws_the_same_map_as_drawing_it_directly(
    screenshots: Path, office: object, tiles: TileCache, view: str
) -> None:
    vp, robot = views(tiles, office)[view]
    ready(tiles, vp)
    direct = frame(scene_of(office, tiles, robot, None), vp, screenshots / f"map-layer-{view}-direct.png")
    layer = MapLayer()
    frame(scene_of(office, tiles, robot, layer), vp)  # makes the picture
    stored = frame(scene_of(office, tiles, robot, layer), vp, screenshots / f"map-layer-{view}-stored.png")
    assert layer.builds == 1 and layer.uses == 2, "both frames painted the one stored picture"
    assert (direct != stored).any(axis=-1).sum() <= W * H // 1000, "more than 0.1 % of the pixels differ"
    assert np.abs(direct - stored).max() <= TOLERANCE
    assert (direct != 245).any(axis=-1).sum() > W * H // 200, "control: the frame shows a map, not background"


def test_the_picture_is_made_once_per_view_while_the_robot_moves(office: object, tiles: TileCache) -> None:
    vp, (x, y, th) = views(tiles, office)["zoomed"]
    ready(tiles, vp)
    layer = MapLayer()
    for step in range(10):  # a drive along the view: only the robot, its trail and heading change
        frame(scene_of(office, tiles, (x + 40.0 * step, y, th + step), layer), vp)
    assert (layer.builds, layer.uses) == (1, 10)
    moved = vp.panned(300, 0)  # follow re-centres: a new view, a new picture
    ready(tiles, moved)
    frame(scene_of(office, tiles, (x, y, th), layer), moved)
    assert (layer.builds, layer.uses) == (2, 11)


def test_the_robot_on_a_name_moves_it_in_a_picture_made_for_that_pose(
    screenshots: Path, office: object, tiles: TileCache
) -> None:
    """At Home or a dock the robot stands on a name: the name moves from under it in the picture too,
    and turning there (the same pose's place) makes no new picture."""
    goal = named(office)[0]
    vp = Viewport(W, H, 1.0, float(goal.x), float(goal.y))  # type: ignore[attr-defined]
    ready(tiles, vp)
    x, y = float(goal.x), float(goal.y) - 200.0  # type: ignore[attr-defined]  # on its name
    layer = MapLayer()
    on_name = frame(
        scene_of(office, tiles, (x, y, 0.0), layer), vp, screenshots / "map-layer-robot-on-a-name.png"
    )
    direct = frame(scene_of(office, tiles, (x, y, 0.0), None), vp)
    assert np.abs(on_name - direct).max() <= TOLERANCE
    clear = frame(scene_of(office, tiles, (x + 3000.0, y + 2000.0, 0.0), None), vp)
    assert (on_name != clear).any(axis=-1).sum() > 400, "control: the name did move (and the robot)"
    builds = layer.builds
    for th in (30.0, 60.0, 90.0):  # turning in place
        frame(scene_of(office, tiles, (x, y, th), layer), vp)
    assert layer.builds == builds and layer.uses == 4
    frame(scene_of(office, tiles, (x + 3000.0, y + 2000.0, 0.0), layer), vp)  # off the name again
    assert layer.builds == builds + 1


def test_missing_tiles_make_no_picture(office: object, tiles: TileCache) -> None:
    """A fresh cache has its index, no tile yet (``tiles`` renders them only when asked)."""
    vp = fit_view(tiles.bounds, W, H)  # type: ignore[arg-type]
    layer = MapLayer()
    frame(scene_of(office, tiles, (0.0, 0.0, 0.0), layer), vp)  # asks for the tiles: none ready yet
    assert (layer.builds, layer.uses) == (0, 0), "a picture with the overview's blur would stay"
    ready(tiles, vp)
    frame(scene_of(office, tiles, (0.0, 0.0, 0.0), layer), vp)
    assert layer.builds == 1
