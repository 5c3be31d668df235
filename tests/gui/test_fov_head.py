"""The map's field-of-view wedge follows the real camera head: panned with Ctrl+arrows and zoomed with
Page Up on the camera page (real keys through the X server), the simulated VC-C4 turns and narrows, the
window reads the head back (``getCameraData``) and the wedge on the map — its pixels — turns right and
narrows to a beam."""

from __future__ import annotations

import math

import numpy as np

from rtmu.sim import SimThread
from rtmu.ui.fov_draw import MIN_RANGE_PX, RANGE_MM
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump

PANS = 6
"""Ctrl+Right presses: 10° each (``ptz_controls.PAN_STEP``), so the head looks 60° right."""
ZOOMS = 10
"""Page Up presses: 10 % each, so the head is at full zoom (a 4° view)."""


sim = simulator(map_path=OFFICE_MAP, camera=True, seed=1)


def head(sim: SimThread) -> tuple[float, float, float]:
    assert sim.server is not None
    p = sim.server.world.camera.ptz
    return sim.call(lambda: (p.pan, p.tilt, p.zoom))


def amber(pixels: np.ndarray) -> np.ndarray:
    """The wedge's translucent fill over the floor (245, 224, 191) and its edge; not the kitchen's beige
    (242, 234, 214) nor the server room's pink."""
    r, g, b = (pixels[..., i].astype(int) for i in range(3))
    return (r - b > 40) & (g - b > 20) & (g < r)


def amber_toward(gui: Gui, pixels: np.ndarray, turn_deg: float) -> int:
    """Amber pixels in a 7x7 patch at 60 % of the wedge's reach, ``turn_deg`` counter-clockwise from the
    robot's heading (as the map turns)."""
    r = gui.model.robot.value
    vp = gui.stage.viewport
    reach_mm = max(RANGE_MM, MIN_RANGE_PX / vp.scale)
    a = math.radians(r.th + turn_deg)
    sx, sy = vp.to_screen(r.x + 0.6 * reach_mm * math.cos(a), r.y + 0.6 * reach_mm * math.sin(a))
    x, y = round(sx), round(sy)
    assert 3 <= x < pixels.shape[1] - 3 and 3 <= y < pixels.shape[0] - 3, "the point is on the map"
    return int(amber(pixels[y - 3 : y + 4, x - 3 : x + 4]).sum())


def test_the_wedge_turns_and_narrows_with_the_camera_head(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    pump(lambda: (p := gui.model.robot.value.ptz) is not None and p.position is not None, 8, "the head read")
    pump(lambda: gui.model.map.value.state == "ready", 10, "the map")
    idle(0.5)
    wide = gui.stage_pixels()
    gui.shot("wedge-wide")
    assert amber_toward(gui, wide, 0.0) > 10, "the wide wedge looks straight ahead"
    assert amber_toward(gui, wide, -60.0) == 0

    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
    for _ in range(PANS):
        gui.key("ctrl+Right")
    pump(lambda: abs(head(sim)[0] - 10.0 * PANS) < 0.5, 5, "the simulated head to pan right")
    for _ in range(ZOOMS):
        gui.key("Page_Up")
    pump(lambda: head(sim)[2] >= 99.5, 5, "the simulated head to zoom in fully")
    position = lambda: gui.model.robot.value.ptz.position  # noqa: E731
    pump(lambda: position() is not None and position()[2] >= 99.5, 5, "the window to read the head back")
    assert abs(position()[0] - 10.0 * PANS) < 0.5
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "map", 3, "the map again")
    idle(0.5)
    beam = gui.stage_pixels()
    gui.shot("wedge-panned-zoomed")

    # ARIA's pan is to the right: on the map (counter-clockwise angles) the beam is at -60°, not +60°.
    assert amber_toward(gui, beam, -60.0) > 3, "the beam looks where the head looks"
    assert amber_toward(gui, beam, 0.0) == 0, "no longer straight ahead"
    assert amber_toward(gui, beam, 60.0) == 0, "turned right, not left"
    assert amber_toward(gui, beam, -60.0 + 12.0) == 0, "a 4° beam, not a 48° wedge"
    window.activate_action("win.fov", None)  # the same map without the wedge: the labels' own amber
    pump(lambda: not gui.stage.show_fov, 3, "the wedge off")
    idle(0.3)
    base = int(amber(gui.stage_pixels()).sum())
    assert (int(amber(beam).sum()) - base) * 4 < int(amber(wide).sum()) - base, "a beam covers far less"
