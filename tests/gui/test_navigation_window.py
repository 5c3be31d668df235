"""Sending the robot somewhere from the real window: goals, a clicked point, the dock, a lost robot.

Real window, real simulator (it navigates as an ARNL server), real X input (xdotool clicks, drags
and keys). What is checked is the simulator's own pose and status, and the pixels the window drew;
every navigation wait is generous because the simulated robot drives in real time (750 mm/s).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import gi
import numpy as np
import pytest

from rtmu.model.observables import Phase
from rtmu.sim import SimConfig, SimThread
from rtmu.ui.nav_draw import PATH_RGB, MarkerKind
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump

gi.require_version("Gtk", "4.0")
gi.require_version("GdkX11", "4.0")
gi.require_version("Graphene", "1.0")
from gi.repository import GdkX11, Graphene, Gtk  # noqa: E402

GOALS = {"Meeting Room": (3000, 8300), "Lab B": (22500, 9000), "Room 101": (2000, 3200)}
"""Cairns of rtmu/data/maps/office.map used here (mm)."""
ARRIVE_MM = 250.0
TRIP_S = 60.0


sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


# -- helpers --------------------------------------------------------------------------------------


def distance(sim: SimThread, x: float, y: float) -> float:
    snap = sim.snapshot()
    return math.hypot(snap.x - x, snap.y - y)


def status(sim: SimThread) -> str:
    return sim.snapshot().status


def sim_mode(sim: SimThread) -> str:
    return sim.call(lambda: sim.server.robot.mode_name)


def stopped(sim: SimThread) -> bool:
    snap = sim.snapshot()
    return abs(snap.vel) < 1.0 and abs(snap.rot_vel) < 1.0


def teal(pixels: np.ndarray, x: float, y: float, radius: int = 3) -> bool:
    """A pixel of the path's colour near (x, y) on the stage."""
    xi, yi = round(x), round(y)
    patch = pixels[max(0, yi - radius) : yi + radius + 1, max(0, xi - radius) : xi + radius + 1].astype(int)
    want = np.array([round(c * 255) for c in PATH_RGB])
    return bool((np.abs(patch - want).sum(axis=2) < 60).any())


def teal_count(pixels: np.ndarray) -> int:
    want = np.array([round(c * 255) for c in PATH_RGB])
    return int(np.count_nonzero(np.abs(pixels.astype(int) - want).sum(axis=2) < 60))


def typing(gui: Gui) -> bool:
    """A text field (the goals' search) has the keyboard focus."""
    return isinstance(gui.window.get_focus(), Gtk.Editable)


def open_goals(gui: Gui) -> Gtk.Popover:
    panel = gui.window.goals_panel
    pump(panel.get_visible, 5, "the Go to button (the server navigates)")
    pump(lambda: len(panel.rows) >= 5, 5, "the map's goals in the popover")
    gui.click(panel)
    popover = panel.get_popover()
    assert popover is not None
    pump(popover.get_mapped, 3, "the goals popover")
    return popover


def on_surface(gui: Gui, wx: float, wy: float) -> tuple[int, int]:
    """Where the world point (mm) is on the window's X surface, for pointer events."""
    stage = gui.stage
    sx, sy = stage.viewport.to_screen(wx, wy)
    native = stage.get_native()
    ok, point = stage.compute_point(native, Graphene.Point().init(sx, sy))
    assert ok
    dx, dy = native.get_surface_transform()
    return round(point.x + dx), round(point.y + dy)


def drag_on_map(gui: Gui, wx: float, wy: float, heading_deg: float, length_px: float = 60.0) -> None:
    """A real press at the world point, a drag towards ``heading_deg`` (map degrees), a release."""
    x, y = on_surface(gui, wx, wy)
    th = math.radians(heading_deg)
    xid = str(GdkX11.X11Surface.get_xid(gui.window.get_surface()))
    steps = [(x + f * length_px * math.cos(th), y - f * length_px * math.sin(th)) for f in (0.3, 0.7, 1.0)]
    args = ["mousemove", "--window", xid, str(x), str(y), "mousedown", "1"]
    for px, py in steps:
        args += ["sleep", "0.05", "mousemove", "--window", xid, str(round(px)), str(round(py))]
    gui.xdotool(*args, "sleep", "0.05", "mouseup", "1")


def choose_goal(gui: Gui, query: str) -> None:
    """Open the popover, type in its search field, press Return: the first goal that matches."""
    popover = open_goals(gui)
    panel = gui.window.goals_panel
    pump(lambda: typing(gui), 3, "the search field to have the keys")
    gui.xdotool("type", "--delay", "40", query)
    pump(lambda: panel.search.get_text() == query, 3, "the query in the search field")
    gui.screen_shot("goals-search")
    gui.key("Return")
    pump(lambda: not popover.get_mapped(), 3, "the popover to close")


# -- tests ----------------------------------------------------------------------------------------


def test_choosing_a_goal_drives_there_rings_its_cairn_and_says_arrived(gui: Gui, sim: SimThread) -> None:
    window, nav = gui.window, gui.model.navigation
    start = sim.snapshot()
    choose_goal(gui, "meet")
    assert gui.model.robot.value.x == pytest.approx(start.x, abs=50), "typing in the search did not drive"
    pump(lambda: nav.value.navigating and nav.value.target == "Meeting Room", 5, "navigation to start")
    pump(lambda: window.motion.kind == "autonomous", 3, "the autonomous motion indicator")
    assert window.motion.text.startswith("Navigating (autonomous) · To Meeting Room · ")
    # The distance comes with the planned path, a reply of its own after the navigation's start (the
    # fresh-machine run CI52 read the pill between the two): waited for, bounded.
    pump(lambda: "m left · Space or STOP cancels" in window.motion.text, 5, "the distance left in the pill")
    assert window.goals_panel.rows["Meeting Room"].has_css_class("current-goal")
    # The goal's cairn is ringed while the robot heads there.
    pixels = gui.stage_pixels()
    cx, cy = gui.stage.viewport.to_screen(*GOALS["Meeting Room"])
    ring = [teal(pixels, cx + 15 * math.cos(a), cy + 15 * math.sin(a), 2) for a in np.linspace(0, 6, 12)]
    assert sum(ring) >= 8, f"the cairn is not ringed: {ring}"
    gui.shot("heading-for-the-meeting-room")

    pump(lambda: status(sim) == "Arrived at Meeting Room", TRIP_S, "the robot to arrive")
    assert distance(sim, *GOALS["Meeting Room"]) <= ARRIVE_MM
    pump(lambda: window.banners.text("navigation") == "Arrived at Meeting Room", 3, "the arrival banner")
    pump(lambda: not window.motion.get_visible(), 3, "the indicator to go")
    mode = window.toolbar.cells["mode"].value.get_text()
    assert "Arrived at Meeting Room" in mode, mode
    gui.shot("arrived")


def test_the_path_is_drawn_and_stop_ends_the_navigation_mid_route(gui: Gui, sim: SimThread) -> None:
    window, nav = gui.window, gui.model.navigation
    assert teal_count(gui.stage_pixels()) == 0, "no path before navigating"
    window.goals_panel.choose("Lab B")
    pump(lambda: len(nav.value.path) >= 2 and sim.snapshot().vel > 200, 10, "a path and a moving robot")
    pump(lambda: nav.value.remaining_mm is not None, 3, "the distance left")
    pixels = gui.stage_pixels()
    vp = gui.stage.viewport
    path = [(gui.model.robot.value.x, gui.model.robot.value.y), *nav.value.path]
    hits = tried = 0
    for (ax, ay), (bx, by) in itertools.pairwise(path):
        for t in (0.25, 0.5, 0.75):
            sx, sy = vp.to_screen(ax + t * (bx - ax), ay + t * (by - ay))
            if 4 <= sx < vp.width - 4 and 4 <= sy < vp.height - 4:
                tried += 1
                hits += teal(pixels, sx, sy)
    assert tried >= 3 and hits >= 0.8 * tried, f"{hits}/{tried} path samples are teal"
    mode = window.toolbar.cells["mode"].value.get_text()
    assert "m left" in mode, mode
    gui.shot("path-to-lab-b")

    gui.click(window.stop_button)
    pump(lambda: sim_mode(sim) == "stop", 3, "the simulator to get the stop")
    pump(lambda: stopped(sim), 5, "the robot to stop")
    pump(lambda: not nav.value.navigating, 3, "the navigation to end in the window")
    pump(lambda: not window.motion.get_visible(), 3, "the indicator to go")
    pump(lambda: teal_count(gui.stage_pixels()) == 0, 3, "the path to go from the map")
    where = sim.snapshot()
    idle(1.0)
    assert distance(sim, where.x, where.y) < 20, "the robot stays stopped"
    gui.shot("stopped-mid-route")


def test_focus_loss_leaves_navigation_alone_and_a_drive_key_cancels_it(gui: Gui, sim: SimThread) -> None:
    window, nav = gui.window, gui.model.navigation
    window.goals_panel.choose("Lab B")
    pump(lambda: nav.value.navigating and sim.snapshot().vel > 200, 10, "the robot to navigate")
    other = Gtk.Window(title="elsewhere")
    other.present()
    try:
        pump(other.get_mapped, 3, "the other window")
        gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(other.get_surface())))
        pump(lambda: not window.is_active(), 3, "the window to lose focus")
        idle(1.0)
        assert sim_mode(sim) == "Goto" and sim.snapshot().vel > 200, "focus loss must not stop navigation"
    finally:
        other.destroy()
    gui.focus()
    gui.keydown("Up")
    try:
        pump(lambda: sim_mode(sim) == "stop", 3, "a drive key to cancel the navigation")
        pump(lambda: stopped(sim), 5, "the robot to stop")
        idle(0.5)
        assert sim_mode(sim) == "stop", "the press that cancelled does not drive"
        pump(lambda: "cancelled" in (window.banners.text("navigation") or ""), 3, "the banner")
        gui.shot("cancelled-by-a-drive-key")
    finally:
        gui.keyup("Up")
    gui.keydown("Up")
    try:
        pump(lambda: window.motion.kind == "held", 3, "held driving in the indicator")
        assert window.motion.text.startswith("Driving (held keys)")
        gui.shot("held-drive")
    finally:
        gui.keyup("Up")


def test_click_to_go_with_a_dragged_heading(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    popover = open_goals(gui)
    gui.click(window.goals_panel.buttons["goto"])
    pump(lambda: not popover.get_mapped(), 3, "the popover to close")
    assert window.picker.kind is MarkerKind.GOTO and window.pose_bar.get_visible()
    assert not window.pose_bar.go_button.get_sensitive(), "nothing to send before a click"
    gui.key("Escape")  # Esc leaves the mode (it does not open the camera page)
    pump(lambda: not window.picker.active and not window.pose_bar.get_visible(), 3, "Esc to end the mode")
    assert window.stack.get_visible_child_name() == "map"
    window.start_pick(MarkerKind.GOTO)
    target, heading = (6000.0, 6000.0), 90.0
    before = gui.stage.viewport
    drag_on_map(gui, *target, heading)
    pump(lambda: window.picker.marker is not None and window.picker.marker.th is not None, 3, "the pick")
    marker = window.picker.marker
    assert marker is not None and marker.th is not None
    assert math.hypot(marker.x - target[0], marker.y - target[1]) < 3 / before.scale
    assert abs(marker.th - heading) < 3, marker.th
    assert gui.stage.viewport == before, "the drag picked a heading; it did not pan the map"
    assert "facing 90°" in window.pose_bar.label.get_text()
    assert sim_mode(sim) != "Goto", "nothing is sent before Go"
    pixels = gui.stage_pixels()
    assert teal(pixels, *before.to_screen(*target), radius=12), "the target marker"
    gui.shot("point-picked")

    gui.click(window.pose_bar.go_button)
    pump(lambda: not window.pose_bar.get_visible(), 3, "the mode to end")
    pump(lambda: status(sim) == "Arrived at point", TRIP_S, "the robot to arrive at the point")
    assert distance(sim, *target) <= ARRIVE_MM
    th = sim.snapshot().th
    assert abs((th - heading + 180) % 360 - 180) < 10, th
    gui.shot("arrived-at-the-point")


def test_dock_and_charge(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    sim.call(lambda: sim.server.world.set_battery(11.4))  # under ARIA's 11.5 V low level
    pump(lambda: (window.banners.text("alarm:battery") or "").startswith("Battery low"), 5, "the low alarm")
    assert "bring the robot to its charger" in (window.banners.text("alarm:battery") or "")
    popover = open_goals(gui)
    dock = window.goals_panel.buttons["dock"]
    assert dock.get_sensitive() and "dock" in gui.model.connection.value.offers
    gui.click(dock)
    pump(lambda: not popover.get_mapped(), 3, "the popover to close")
    pump(lambda: window.motion.kind == "autonomous", 5, "navigating to the dock")
    pump(lambda: status(sim) == "Docked", TRIP_S, "the robot to dock")
    pump(lambda: window.banners.text("navigation") == "Docked", 3, "the Docked banner")
    # On its charger, "bring the robot to its charger" would be a lie: a charging note takes its place.
    pump(
        lambda: "charging on its dock" in (window.banners.text("alarm:battery") or ""), 3, "the charging note"
    )
    gui.shot("docked-low-battery-charging")
    # Just under a tenth: a second or two of charging shows as a rise in the window too.
    sim.call(lambda: sim.server.world.set_battery(11.8497))
    pump(lambda: gui.model.robot.value.battery_v == pytest.approx(11.8), 3, "the lower battery")
    before = sim.snapshot().battery_v
    pump(lambda: gui.model.robot.value.battery_v == pytest.approx(11.9), 10, "the battery to rise")
    assert sim.snapshot().battery_v > before
    assert window.toolbar.cells["battery"].value.get_text() == "11.9 V"
    gui.shot("docked-and-charging")


def test_a_lost_robot_is_localized_with_the_map_mode_and_navigates_again(gui: Gui, sim: SimThread) -> None:
    window, nav = gui.window, gui.model.navigation
    window.set_default_size(1200, 720)  # a normal size: a Good localization column gives way at 800 px
    pump(lambda: window.get_width() > 1100, 5, "the window to grow")
    loc = window.toolbar.cells["loc"]
    pump(lambda: loc.get_visible() and loc.has_css_class("loc-good"), 5, "localization shown as good")
    sim.call(sim.server.lose_localization)
    pump(lambda: loc.has_css_class("loc-lost") and loc.value.get_text().startswith("Lost"), 5, "lost")
    window.goals_panel.choose("Room 101")
    pump(lambda: "because" in (window.banners.text("navigation") or ""), 5, "the failure banner")
    assert "lost" in (window.banners.text("navigation") or "")
    gui.shot("lost")

    popover = open_goals(gui)
    gui.click(window.goals_panel.buttons["localize"])
    pump(lambda: not popover.get_mapped(), 3, "the popover to close")
    assert window.picker.kind is MarkerKind.LOCALIZE
    place = (2500.0, 6000.0)
    drag_on_map(gui, *place, 0.0)
    pump(lambda: window.picker.marker is not None, 3, "the placed robot")
    assert window.pose_bar.go_button.get_label() == "Set here"
    gui.shot("placing-the-robot")
    gui.click(window.pose_bar.go_button)
    pump(
        lambda: (window.banners.text("navigation") or "").startswith("Position set: robot at 2."),
        3,
        "the confirmation of Set position",
    )
    pump(lambda: distance(sim, *place) < 60, 3, "the simulator to take the pose")
    pump(lambda: loc.has_css_class("loc-good"), 5, "localization good again")
    assert abs(sim.snapshot().th) < 5

    window.goals_panel.choose("Room 101")
    pump(lambda: nav.value.navigating, 5, "navigation to start")
    pump(lambda: status(sim) == "Arrived at Room 101", TRIP_S, "the robot to arrive")
    assert distance(sim, *GOALS["Room 101"]) <= ARRIVE_MM
    assert gui.phase is Phase.CONNECTED
    gui.shot("arrived-after-localizing")


def test_a_lost_link_while_navigating_says_the_robot_is_on_its_own_and_stop_stays(
    request: pytest.FixtureRequest, screenshots: Path
) -> None:
    from linkfaults import TO_CLIENT, TO_SERVER, FaultProxy

    with (
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, camera=False, seed=1)) as sim,
        FaultProxy("127.0.0.1", sim.port) as proxy,
    ):
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", proxy.port)
        try:
            window, nav = gui.window, gui.model.navigation
            window.goals_panel.choose("Lab B")
            pump(lambda: nav.value.navigating and sim.snapshot().vel > 200, 10, "the robot to navigate")
            proxy.mute(TO_CLIENT, TO_SERVER)  # new connections hang too: the window keeps trying
            proxy.reset()
            pump(lambda: gui.phase is Phase.RECONNECTING, 5, "the window to see the link go")
            link = window.banners.text("link") or ""
            assert "navigating on its own (going to Lab B)" in link, link
            others = [t for topic, _l, t in window.banners.history if topic != "link" and "on its own" in t]
            assert not others, f"said in one place only: {others}"
            assert not window.motion.get_visible(), "the pill gives way to the link banner"
            assert window.stop_button.get_sensitive() and window.stop_button.get_mapped()
            assert sim_mode(sim) == "Goto" and sim.snapshot().vel > 100, "the server drives on"
            gui.shot("link-lost-while-navigating")
            proxy.restore()
            pump(lambda: gui.phase is Phase.CONNECTED, 15, "the link to come back")
            pump(lambda: nav.value.navigating, 5, "the window to see the navigation again")
            gui.click(window.stop_button)
            pump(lambda: sim_mode(sim) == "stop" and stopped(sim), 5, "STOP to stop it")
        finally:
            gui.close()


def test_goals_popover_pick_bar_and_indicator_fit_an_800x480_screen(
    request: pytest.FixtureRequest, screenshots: Path, small_screen: str
) -> None:
    from .harness import on_display

    with (
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, camera=True, seed=1)) as sim,
        on_display(small_screen),
    ):
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            window = gui.window
            popover = open_goals(gui)
            x, y, w, h = gui.screen_rect(popover)
            gui.screen_shot("goals-800x480")
            assert x >= 0 and y >= 0 and x + w <= 800 and y + h <= 480, (x, y, w, h)
            gui.click(window.goals_panel.buttons["goto"])
            pump(lambda: not popover.get_mapped(), 3, "the popover to close")
            drag_on_map(gui, 6000.0, 6000.0, 0.0)
            pump(lambda: window.picker.marker is not None, 3, "the pick")
            bar = window.pose_bar
            assert bar.go_button.get_mapped() and bar.cancel_button.get_mapped()
            assert bar.label.get_layout().is_ellipsized() is False, bar.label.get_text()
            gui.shot("pick-800x480")
            gui.click(bar.go_button)
            pump(lambda: window.motion.kind == "autonomous", 5, "the indicator")
            pump(lambda: len(gui.model.navigation.value.path) > 0, 5, "the path")
            ok, bounds = window.motion.compute_bounds(window)
            assert ok and bounds.get_x() + bounds.get_width() <= window.get_width()
            assert not window.toolbar.hidden_columns(), window.toolbar.hidden_columns()
            gui.shot("navigating-800x480")
            window.stop_now()
            pump(lambda: stopped(sim) and not window.motion.get_visible(), 5, "the stop")
        finally:
            gui.close()


def test_what_the_server_does_not_list_stays_visible_greyed_with_its_reason() -> None:
    """The panel alone, on a model whose server lists goals and points but neither dock nor localize."""
    from rtmu.control.commands import CommandState
    from rtmu.model.observables import ConnectionState, NavState, RobotModel
    from rtmu.ui.goals_panel import GoalsPanel

    model = RobotModel()
    chosen: list[str] = []
    panel = GoalsPanel(
        model,
        goto=chosen.append,
        run=chosen.append,
        pick=lambda kind: chosen.append(kind.value),
    )
    try:
        assert not panel.get_visible(), "hidden while not connected"
        offers = frozenset({"gotoGoal", "gotoPose", "home", "tourGoals", "getGoals"})
        model.connection.set(ConnectionState(phase=Phase.CONNECTED, offers=offers))
        model.navigation.set(NavState(offered=offers, goals=("Lab A", "Lab B", "Room <b>1</b>")))
        panel.commands_changed(
            {
                "home": CommandState(True, ""),
                "tour_goals": CommandState(True, ""),
                "dock": CommandState(False, "this server does not offer dock"),
            }
        )
        assert panel.get_visible()
        assert panel.buttons["home"].get_sensitive() and panel.buttons["goto"].get_sensitive()
        assert not panel.buttons["dock"].get_sensitive() and not panel.buttons["localize"].get_sensitive()
        assert panel.buttons["dock"].get_visible() and panel.buttons["localize"].get_visible()
        reasons = panel.reasons.get_text()
        assert "Dock: not offered by the server" in reasons and "Set position: not offered" in reasons
        label = panel.rows["Room <b>1</b>"].get_child()
        assert isinstance(label, Gtk.Label) and label.get_text() == "Room <b>1</b>", "plain text, not markup"
        panel.search.set_text("lab b")
        panel._filter()
        assert [n for n, row in panel.rows.items() if row.get_child_visible()] == ["Lab B"], "spaces ignored"
        panel.choose_first()
        assert chosen == ["Lab B"]
    finally:
        panel.close()


def test_space_cancels_navigation_even_while_typing_in_the_goal_search(gui: Gui, sim: SimThread) -> None:
    window, nav = gui.window, gui.model.navigation
    window.goals_panel.choose("Lab B")
    pump(lambda: nav.value.navigating and sim.snapshot().vel > 200, 10, "the robot to navigate")
    popover = open_goals(gui)
    pump(lambda: typing(gui), 3, "the search field to have the keys")
    gui.xdotool("type", "--delay", "40", "lab")
    pump(lambda: window.goals_panel.search.get_text() == "lab", 3, "letters typed, not driven")
    assert sim_mode(sim) == "Goto", "typing letters (a, s, d …) in the search does not touch the robot"
    gui.key("space")
    pump(lambda: sim_mode(sim) == "stop", 3, "Space to stop the robot")
    pump(lambda: stopped(sim), 5, "the robot to stop")
    assert window.goals_panel.search.get_text() == "lab", "Space stopped; it typed nothing"
    assert popover.get_mapped()
    gui.screen_shot("space-stopped-while-typing")
    popover.popdown()  # an open popover holds the keyboard: leave none for the next test
    pump(lambda: not popover.get_mapped(), 3, "the popover to close")
