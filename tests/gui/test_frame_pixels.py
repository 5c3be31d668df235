"""One frame drawn without a window (``rtmu.ui.frame.draw_frame``), checked pixel by pixel.

Each drawing helper must start its own path: a current point left behind by an
earlier helper (the legend's text, a label) turns the next ``arc`` into a line
from there — a stray black line across the map.
"""

from __future__ import annotations

from pathlib import Path

import cairo
import numpy as np
import pytest

from rtmu.ui import overlays
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.viewport import Viewport

W, H = 800, 400


def render(scene: Scene, vp: Viewport, path: Path) -> np.ndarray:
    """The frame as an (H, W, 3) uint8 array; also saved as a PNG for the operator's eye."""
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, vp.width, vp.height)
    ctx = cairo.Context(surface)
    draw_frame(ctx, vp, scene)
    surface.flush()
    surface.write_to_png(str(path))
    data = np.ndarray((vp.height, surface.get_stride() // 4), np.uint32, surface.get_data())[:, : vp.width]
    rgb = np.stack([(data >> 16) & 0xFF, (data >> 8) & 0xFF, data & 0xFF], axis=-1)
    return rgb.astype(np.uint8)


def darkest_along(pixels: np.ndarray, a: tuple[float, float], b: tuple[float, float]) -> int:
    """The darkest pixel (sum of R, G, B) on the segment a → b, ends left out (legend box, robot)."""
    darkest = 3 * 255
    for t in np.linspace(0.15, 0.85, 200):
        x = round(a[0] + t * (b[0] - a[0]))
        y = round(a[1] + t * (b[1] - a[1]))
        darkest = min(darkest, int(pixels[y, x].astype(int).sum()))
    return darkest


@pytest.mark.parametrize("sonar", [False, True], ids=["robot", "robot-and-sonar"])
def test_no_map_frame_has_no_stray_line_from_the_legend_to_the_robot(screenshots: Path, sonar: bool) -> None:
    vp = Viewport(W, H, 0.36, 0.0, 0.0)
    readings = [(2000, 0), (1500, 1500), (0, 2000), (-1500, 1500)] if sonar else []
    scene = Scene(labels=overlays.LabelCache(), robot=(0.0, 0.0, 0.0), sonar=readings)
    pixels = render(scene, vp, screenshots / f"frame-no-map-{'sonar' if sonar else 'plain'}.png")
    robot = vp.to_screen(0.0, 0.0)
    # Grid lines are faint (≥ ~200 per channel); the stray line was the robot's dark outline colour.
    assert darkest_along(pixels, (11, 8), robot) > 3 * 170, "a dark line runs from the legend to the robot"
    assert darkest_along(pixels, (W - 1, 0), robot) > 3 * 170, "control: the other diagonal is clean"
    # The robot itself is drawn (blue) where it is.
    r, g, b = (int(c) for c in pixels[round(robot[1]) + 2, round(robot[0]) - 3])
    assert b > 150 and b - r > 60, (r, g, b)


def _helpers() -> dict[str, object]:
    from types import SimpleNamespace

    labels = overlays.LabelCache()
    spot = (3000.0, -2000.0)
    dot = SimpleNamespace(type="Area", x=spot[0], y=spot[1], name="")
    return {
        "robot-circle": lambda ctx, vp: overlays.draw_robot(ctx, vp, *spot, 0, stale=False, footprint=False),
        "robot-footprint": lambda ctx, vp: overlays.draw_robot(ctx, vp, *spot, 0.0, stale=True),
        "cairn-dot": lambda ctx, vp: overlays.draw_cairns(ctx, vp, [dot], labels),
        "sonar": lambda ctx, vp: overlays.draw_sonar(ctx, vp, spot, [(3500, -2000)]),
        "trail": lambda ctx, vp: overlays.draw_trail(ctx, vp, [spot, (spot[0] + 300, spot[1])]),
    }


@pytest.mark.parametrize("name", list(_helpers()))
def test_every_helper_starts_its_own_path(screenshots: Path, name: str) -> None:
    """A current point left at the top left corner must not become a line to what the helper draws."""
    vp = Viewport(W, H, 0.1, 0.0, 0.0)
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, W, H)
    ctx = cairo.Context(surface)
    ctx.set_source_rgb(1, 1, 1)
    ctx.paint()
    ctx.move_to(0, 0)  # what PangoCairo.show_layout or a label leaves behind
    _helpers()[name](ctx, vp)  # type: ignore[operator]
    surface.flush()
    surface.write_to_png(str(screenshots / f"frame-helper-{name}.png"))
    data = np.ndarray((H, surface.get_stride() // 4), np.uint32, surface.get_data())[:, :W]
    pixels = np.stack([(data >> 16) & 0xFF, (data >> 8) & 0xFF, data & 0xFF], axis=-1).astype(np.uint8)
    target = vp.to_screen(3000.0, -2000.0)
    assert darkest_along(pixels, (0, 0), target) > 3 * 240, f"{name} joined the previous current point"


def test_a_stale_robot_on_home_at_fit_zoom_stays_distinct_and_home_keeps_its_label(screenshots: Path) -> None:
    """At Fit zoom the robot often stands on Home: it must not melt into the marker or hide its name."""
    from types import SimpleNamespace

    vp = Viewport(W, H, 0.25, 0.0, 0.0)  # "Fit 25 %"
    home = SimpleNamespace(type="RobotHome", x=0.0, y=0.0, name="Home")
    labels = overlays.LabelCache()
    scene = Scene(labels=labels, objects=[home], robot=(0.0, 0.0, 0.0), stale=True)
    pixels = render(scene, vp, screenshots / "frame-stale-robot-on-home.png")
    sx, sy = (round(v) for v in vp.to_screen(0.0, 0.0))
    r, g, b = (int(c) for c in pixels[sy + 3, sx - 5])  # on the body, behind the heading mark
    assert abs(r - g) < 12 and abs(g - b) < 12 and 120 < g < 190, f"not the stale grey: {(r, g, b)}"
    # Big enough to find: the body spans at least ROBOT_MIN_PX along its heading.
    row = pixels[sy, sx - 20 : sx + 20].astype(int).sum(axis=1)
    assert (row < 3 * 200).sum() >= overlays.ROBOT_MIN_PX - 2
    # The name "Home" is drawn, and not under the robot.
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, W, H)
    robot = overlays.robot_box(vp, 0.0, 0.0)
    drawn = dict(overlays.draw_cairns(cairo.Context(surface), vp, [home], labels, robot))
    assert "Home" in drawn
    box = drawn["Home"]
    assert box[1] >= robot[3] or box[3] <= robot[1] or box[0] >= robot[2] or box[2] <= robot[0]
