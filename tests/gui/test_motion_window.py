"""Motion the operator can predict, in the real window against the simulator (issue 21): the stopping
distance drawn ahead of the moving robot, the near-people cap on what the simulator receives, and a
jog into a wall that ends with its outcome on screen."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from rtmu.control.motion_limits import capped_throttle
from rtmu.sim import SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump
from .stop_paths import owned_windows

sim = simulator(map_path=OFFICE_MAP, seed=1)


def red_pixels(pixels: np.ndarray) -> np.ndarray:
    r, g, b = (pixels[..., i].astype(int) for i in range(3))
    return (r - g > 40) & (r - b > 40) & (r > 120)


def strip_mask(gui: Gui, mm: float) -> tuple[np.ndarray, tuple[float, float], tuple[float, float]]:
    """The stage's red pixels, and where ``mm`` ahead of the robot and as far behind it are on screen."""
    pixels = gui.stage_pixels()
    r = gui.model.robot.value
    vp = gui.stage.viewport
    c, s = math.cos(math.radians(r.th)), math.sin(math.radians(r.th))
    return (
        red_pixels(pixels),
        vp.to_screen(r.x + mm * c, r.y + mm * s),
        vp.to_screen(r.x - mm * c, r.y - mm * s),
    )


def near(mask: np.ndarray, x: float, y: float, radius: int = 4) -> bool:
    xi, yi = round(x), round(y)
    return bool(mask[max(0, yi - radius) : yi + radius + 1, max(0, xi - radius) : xi + radius + 1].any())


def test_the_stopping_distance_is_drawn_ahead_while_the_robot_moves_and_goes_when_it_stands(
    gui: Gui, sim: SimThread
) -> None:
    window = gui.window
    gui.stage.set_zoom(1.0)  # 0.1 px/mm: a metre is 100 px
    for _ in range(3):
        gui.key("plus")
    gui.keydown("Up")
    try:
        pump(lambda: gui.model.robot.value.vel > 900, 15, "the robot to go faster than 0.9 m/s")
        vel = gui.model.robot.value.vel
        distance = window.controller.limits.stopping_distance(vel)
        mask, ahead, behind = strip_mask(gui, 210 + distance / 2)  # the middle of the strip
        gui.shot("stopping-distance-while-driving")
    finally:
        gui.keyup("Up")
    assert distance > 1500, f"at {vel:.0f} mm/s a P3-DX needs more than 1.5 m: {distance:.0f} mm"
    assert near(mask, *ahead), "the strip ahead of the robot"
    assert not near(mask, *behind), "nothing behind it"
    pump(lambda: abs(sim.snapshot().vel) < 1 and abs(gui.model.robot.value.vel) < 1, 15, "the robot to stand")
    idle(0.3)
    mask, ahead, _behind = strip_mask(gui, 210 + distance / 2)
    assert not near(mask, *ahead), "no strip once it stands"
    gui.shot("standing-no-strip")


def test_near_people_caps_what_the_simulator_receives_and_says_so(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    pump(lambda: window.controller.limits.source.startswith("its server's"), 10, "the robot's own limits")
    assert window.controller.limits.max_speed == 1500.0, "the simulator's Robot config/TransVelMax"
    for _ in range(5):
        gui.key("plus")  # 100 %: without the cap, 1.5 m/s
    window.activate_action("win.near-people", None)
    banner = window.banners.text("speed") or ""
    assert banner.startswith("Near people: at most 250 mm/s") and "17 %" in banner, banner
    fastest = [0.0]

    def cruising() -> bool:
        snap = sim.snapshot()
        fastest[0] = max(fastest[0], snap.vel)
        return snap.vel > 200

    gui.keydown("Up")
    try:
        pump(lambda: sim.snapshot().throttle_ratio > 0, 5, "the drive")
        want = capped_throttle(100.0, 250, window.controller.limits)
        assert sim.snapshot().throttle_ratio == pytest.approx(want, abs=0.1)
        pump(cruising, 10, "the robot to reach the cap")  # 300 mm/s² reaches 250 mm/s in under a second
        end = time.monotonic() + 1.0

        def watched_a_second() -> bool:
            cruising()  # keeps the fastest speed seen
            return time.monotonic() > end

        pump(watched_a_second, 5, "a second at the cap")
        assert fastest[0] <= 255, f"the cap let the robot reach {fastest[0]:.0f} mm/s"
        gui.shot("near-people-capped")
    finally:
        gui.keyup("Up")
    window.activate_action("win.near-people", None)
    assert "cap off" in (window.banners.text("speed") or "")


def test_a_jog_into_a_wall_ends_with_its_outcome_on_screen(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    banner = lambda: window.banners.text("navigation") or ""  # noqa: E731

    def dialog(key: str, amount: str) -> None:
        gui.key(key)
        pump(lambda: owned_windows(window), 3, f"the {key} dialog")
        gui.key("ctrl+a")
        gui.xdotool("type", "--delay", "30", amount)
        gui.key("Return")
        pump(lambda: not owned_windows(window), 3, "the dialog to close")
        gui.focus()

    dialog("t", "90")  # face the corridor's north wall
    pump(lambda: banner() == "Turned 90°", 15, "the turn's outcome")
    dialog("g", "2")
    pump(lambda: "Stopped by an obstacle" in banner(), 20, "the jog's outcome")
    words = banner()
    travelled = float(words.split(" after ")[1].split(" m")[0])
    assert 0.2 < travelled < 1.5 and words.endswith("of 2.00 m"), words
    assert sim.snapshot().status.startswith("Moving 2000"), "the server itself never says it stopped"
    gui.shot("jog-outcome")
