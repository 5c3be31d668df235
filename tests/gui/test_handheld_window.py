"""The handheld window: a 360×720 portrait phone and an 800×480 landscape screen, alarms, the gamepad pill.

Each layout runs on an X server whose only screen has that size (no window manager:
the window itself must pick the screen's size), so "fits" means fits the screen:
the window, every widget drawn in it, the menu, the Go to list and the connection
dialog (surfaces of their own, measured with xwininfo). The D-pad is driven by a
real pointer press through the X server. Alarms are raised by the simulator itself:
its battery told to fall by its own string command (``SimulatorSetBattery``, sent
by the window's network side) and its Wi-Fi access point moved out of reach.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import gi
import pytest

from rtmu.client.custom_commands import CustomCommand
from rtmu.control.alarms import Alarm
from rtmu.control.gamepad import AXIS_TRANS, DEADMAN, DeadMan
from rtmu.sim import SimThread
from rtmu.sim.wifi import AccessPoint
from rtmu.ui.alarm_view import AlarmView
from rtmu.values.intents import RunServerCommand
from simulators import running, simulator

from .harness import OFFICE_MAP, Gui, idle, on_display, pump

gi.require_version("Gtk", "4.0")
gi.require_version("Graphene", "1.0")
from gi.repository import Graphene, Gtk  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, seed=1)
"""The simulator of the ``gui`` fixture (the session's big screen)."""


def open_on(screen: str, shots: Path, name: str) -> Iterator[tuple[Gui, SimThread]]:
    with (
        running(map_path=OFFICE_MAP, camera=True, seed=1) as sim,
        on_display(screen),
    ):
        gui = Gui.start(shots, name, "127.0.0.1", sim.port)
        try:
            yield gui, sim
        finally:
            gui.close()


@pytest.fixture
def phone(
    screenshots: Path, phone_screen: str, request: pytest.FixtureRequest
) -> Iterator[tuple[Gui, SimThread]]:
    yield from open_on(phone_screen, screenshots, request.node.name)


@pytest.fixture
def landscape(
    screenshots: Path, small_screen: str, request: pytest.FixtureRequest
) -> Iterator[tuple[Gui, SimThread]]:
    yield from open_on(small_screen, screenshots, request.node.name)


def clipped_widgets(window: Gtk.Window) -> list[str]:
    """Every drawn widget (mapped, in this window's surface) whose box leaves the window's X surface."""
    surface = window.get_surface()
    width, height = surface.get_width(), surface.get_height()
    dx, dy = window.get_surface_transform()
    out: list[str] = []

    def walk(widget: Gtk.Widget) -> None:
        child = widget.get_first_child()
        while child is not None:
            if child.get_mapped() and child.get_native() is window:
                ok, bounds = child.compute_bounds(window)
                if ok:
                    x, y = bounds.get_x() + dx, bounds.get_y() + dy
                    w, h = bounds.get_width(), bounds.get_height()
                    if x < -0.5 or y < -0.5 or x + w > width + 0.5 or y + h > height + 0.5:
                        out.append(
                            f"{type(child).__name__}.{'.'.join(child.get_css_classes())} at {x, y, w, h}"
                        )
                if not isinstance(child, Gtk.Viewport):  # a scrolled child may be larger by design
                    walk(child)
            child = child.get_next_sibling()

    walk(window)
    return out


def drawn_rect(gui: Gui, popover: Gtk.Popover) -> tuple[int, int, int, int]:
    """What a popover draws on the screen: its child's box (its X surface also holds a transparent shadow)."""
    sx, sy, _w, _h = gui.screen_rect(popover)
    child = popover.get_child()
    assert child is not None
    ok, bounds = child.compute_bounds(popover)
    assert ok
    dx, dy = popover.get_surface_transform()
    x, y = sx + dx + bounds.get_x(), sy + dy + bounds.get_y()
    return round(x), round(y), round(bounds.get_width()), round(bounds.get_height())


def inside(rect: tuple[int, int, int, int], w: int, h: int) -> bool:
    x, y, rw, rh = rect
    return x >= 0 and y >= 0 and x + rw <= w and y + rh <= h


def centre(widget: Gtk.Widget) -> tuple[int, int]:
    native = widget.get_native()
    ok, point = widget.compute_point(
        native, Graphene.Point().init(widget.get_width() / 2, widget.get_height() / 2)
    )
    assert ok
    dx, dy = native.get_surface_transform()
    return round(point.x + dx), round(point.y + dy)


def test_portrait_phone_layout_fits_and_the_thumb_dpad_drives(phone: tuple[Gui, SimThread]) -> None:
    gui, sim = phone
    window = gui.window
    layout = window.handheld.layout
    pump(lambda: layout.narrow and window.dpad.get_mapped(), 5, "the phone layout")
    idle(0.3)
    assert gui.screen_rect(window) == (0, 0, 360, 720), "the window fills the phone's screen"
    assert layout.strip.get_mapped() and not window.toolbar_revealer.get_visible()
    pump(lambda: "Bat 1" in layout.strip.text, 5, "the strip to show the battery")
    idle(0.3)
    assert clipped_widgets(window) == []
    gui.shot("portrait-360x720")
    # The D-pad sits low and in the middle, under a thumb: its centre in the lower 40 % of the screen.
    cx, cy = centre(window.dpad.pads["stop"])
    assert 130 < cx < 230 and cy > 720 * 0.6, (cx, cy)
    pad = window.dpad.pads["drive_forward"]
    x, y = centre(pad)
    start_x, start_y = sim.snapshot().x, sim.snapshot().y
    gui.xdotool("mousemove", "--window", str(gui.xid()), str(x), str(y), "mousedown", "1")
    try:
        pump(
            lambda: abs(sim.snapshot().x - start_x) + abs(sim.snapshot().y - start_y) > 100,
            8,
            "the D-pad to drive",
        )
        pump(lambda: window.motion.text.startswith("Driving (D-pad held)"), 3, "the pill naming the D-pad")
        gui.shot("portrait-dpad-held")
    finally:
        gui.xdotool("mouseup", "1")
    pump(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", 3, "the robot to stop on release")
    # The menu and the connection dialog open inside the phone's screen.
    gui.click(window.menu_button)
    popover = window.menu_button.get_popover()
    pump(lambda: popover is not None and popover.get_mapped(), 3, "the menu")
    assert inside(drawn_rect(gui, popover), 360, 720), (drawn_rect(gui, popover), gui.screen_rect(popover))
    gui.screen_shot("portrait-menu")
    popover.popdown()
    pump(lambda: not popover.get_mapped(), 3, "the menu to close")
    # The header's Go to list (a popover of its own) too.
    goals = window.goals_panel
    pump(lambda: goals.get_mapped(), 5, "the Go to button (the simulator navigates)")
    gui.click(goals)
    goals_popover = goals.get_popover()
    pump(lambda: goals_popover is not None and goals_popover.get_mapped(), 3, "the Go to list")
    idle(0.3)
    assert inside(drawn_rect(gui, goals_popover), 360, 720), drawn_rect(gui, goals_popover)
    gui.screen_shot("portrait-goto")
    goals_popover.popdown()
    pump(lambda: not goals_popover.get_mapped(), 3, "the Go to list to close")
    window.activate_action("win.settings", None)
    pump(
        lambda: window.dialogs.settings is not None and window.dialogs.settings.get_mapped(),
        5,
        "the connection dialog",
    )
    dialog = window.dialogs.settings
    assert dialog is not None
    idle(0.3)
    assert inside(gui.screen_rect(dialog), 360, 720), gui.screen_rect(dialog)
    assert clipped_widgets(dialog) == []
    gui.screen_shot("portrait-dialog")
    dialog.close()


def test_landscape_800x480_stays_as_it_was(landscape: tuple[Gui, SimThread]) -> None:
    gui, _sim = landscape
    window = gui.window
    idle(0.5)
    layout = window.handheld.layout
    assert not layout.narrow
    assert window.toolbar_revealer.get_mapped() and not layout.strip.get_visible()
    assert not window.dpad.get_visible(), "the D-pad appeared in landscape"
    assert gui.screen_rect(window)[2:] == (800, 480)
    assert clipped_widgets(window) == []
    gui.shot("landscape-800x480")


def test_battery_and_wifi_alarms_from_the_simulator_with_mute(phone: tuple[Gui, SimThread]) -> None:
    gui, sim = phone
    window = gui.window
    alarms = window.handheld.alarms
    banners = window.banners
    pump(lambda: gui.model.robot.value.battery_low is not None, 5, "batteryInfo")
    low = gui.model.robot.value.battery_low
    assert low is not None
    set_battery(gui, low - 0.3)
    pump(lambda: alarm_topic(Alarm.BATTERY) in banners.topics(), 5, "the battery banner")
    assert "Battery low" in (banners.text(alarm_topic(Alarm.BATTERY)) or "")
    assert alarms.sounded.count(Alarm.BATTERY) == 1
    idle(1.0)
    assert alarms.sounded.count(Alarm.BATTERY) == 1, "beeped again without a new crossing"
    gui.shot("alarm-battery-low")
    # Mute through the View menu's action: the banners stay, no more sound.
    window.activate_action("win.alarm-sound", None)
    assert alarms.muted and gui.app.settings.alarms_muted
    shutdown = gui.model.robot.value.battery_shutdown
    assert shutdown is not None
    set_battery(gui, shutdown - 0.2)
    pump(lambda: "critical" in (banners.text(alarm_topic(Alarm.BATTERY)) or ""), 5, "the critical banner")
    beeps = alarms.beeps
    idle(0.3)
    assert alarms.sounded.count(Alarm.BATTERY) == 1 and alarms.beeps == beeps, "a muted alarm beeped"
    window.activate_action("win.alarm-sound", None)
    assert not alarms.muted
    # The Wi-Fi: its access point moved far away, the link quality the server publishes drops.
    world = sim.server.world
    sim.call(lambda: setattr(world, "access_point", AccessPoint(world.obstacles, 1e7, 1e7)))
    pump(lambda: alarm_topic(Alarm.WIFI) in banners.topics(), 8, "the Wi-Fi banner")
    assert alarms.sounded.count(Alarm.WIFI) == 1, alarms.events  # (a loaded machine may add the round trip's)
    pump(lambda: gui.model.robot.value.wifi_quality is not None, 3, "a Wi-Fi value")
    # The banner and the status strip say the same number, in the same unit (issue 21: "10/70" vs "25 %").
    quality = gui.model.robot.value.wifi_quality
    pump(
        lambda: (
            banners.text(alarm_topic(Alarm.WIFI)) == f"Weak Wi-Fi on the robot: link quality {quality} %"
            or quality != gui.model.robot.value.wifi_quality
        ),
        3,
        "the banner to say the Wi-Fi value the strip shows",
    )
    # the same spacing too: the strip writes its units as the banner (and the language) does
    assert f"Wi-Fi {gui.model.robot.value.wifi_quality} %" in window.handheld.layout.strip.text, "strip"
    gui.shot("alarm-wifi")
    assert clipped_widgets(window) == []
    # The simulator's own "Low battery" popup card sits above the thumb's D-pad, not under it.
    cards = window.popup_stack
    pump(lambda: cards.get_mapped() and cards.get_height() > 0, 5, "the server's low-battery popup")
    ok, card = cards.compute_bounds(window)
    ok2, pad = window.dpad.compute_bounds(window)
    assert ok and ok2 and card.get_y() + card.get_height() <= pad.get_y(), (
        card.get_y(),
        card.get_height(),
        pad.get_y(),
    )


def set_battery(gui: Gui, volts: float) -> None:
    """The simulator's own string command, sent by the window's network side: the server took it."""
    command = CustomCommand("SimulatorSetBattery", "", True)
    intent = RunServerCommand(command.name, f"{volts:.2f}", command.takes_argument)
    assert gui.window.session.runner.send(intent).result(10)


def alarm_topic(alarm: Alarm) -> str:
    return AlarmView.topic(alarm)


def test_the_gamepad_pill_and_the_window_focus(phone: tuple[Gui, SimThread]) -> None:
    gui, sim = phone
    window = gui.window
    handheld = window.handheld
    assert handheld.pads.available, "libmanette (gir1.2-manette-0.2) is not installed"
    assert not handheld.pad_status.get_visible(), "a pad shown with none connected"
    pump(lambda: "link" not in window.banners.topics(), 6, "the Connected banner to go")
    gui.focus()
    pump(lambda: window.is_active(), 5, "the window to have the focus")  # a pad drives a focused window only
    device = object()
    handheld.pad.connected(device, "Test <b>pad</b>")
    handheld.pad.axis(device, AXIS_TRANS, -1.0)
    handheld.pad.button(device, DEADMAN, True)
    pump(lambda: handheld.pad_status.get_mapped(), 3, "the pad pill")
    assert handheld.pad.state.deadman is DeadMan.HELD, (window.is_active(), window.controller.analog_blocked)
    assert "<b>" in handheld.pad_status.text, "device text shown as plain text"
    end = time.monotonic() + 10.0
    while sim.call(lambda: sim.server.robot.mode_name) != "ratioDrive" or not window.motion.get_mapped():
        assert time.monotonic() < end, "the pad did not drive"
        if handheld.pad.state.deadman is DeadMan.LATCHED:  # a loaded machine froze the UI: the lease
            handheld.pad.button(device, DEADMAN, False)  # lapsed; as an operator would, press again
            handheld.pad.button(device, DEADMAN, True)
        handheld.pad.axis(device, AXIS_TRANS, -1.0)  # a real stick's noise keeps the pad talking
        idle(0.05)

    def pills_apart() -> bool:
        ok, pill = handheld.pad_status.compute_bounds(window)
        ok2, motion = window.motion.compute_bounds(window)
        assert ok and ok2 and window.motion.get_mapped(), "the held drive's pill is not shown"
        return bool(pill.get_y() >= motion.get_y() + motion.get_height())

    # Just mapped, the motion pill may not be laid out yet (a CI run caught it 6 px tall): wait for the
    # layout, then the two must not overlap.
    pump(pills_apart, 3, "the pad pill below the motion pill (they overlap)")
    gui.shot("gamepad-held")
    other = Gtk.Window(title="elsewhere")
    other.present()
    try:
        pump(lambda: not window.is_active(), 5, "the focus to leave")
        pump(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", 3, "focus loss to stop the pad")
        assert handheld.pad.state.deadman is DeadMan.LATCHED
    finally:
        other.destroy()
    handheld.pad.disconnected(device)
    assert not handheld.pad_status.get_visible()


def test_narrowing_a_desktop_window_switches_and_widening_restores_it_exactly(gui: Gui) -> None:
    """On the session's big screen: 800 wide → 400 (phone layout) → 800 (as it was, D-pad choice kept)."""
    window = gui.window
    layout = window.handheld.layout
    pump(lambda: window.get_width() >= 600 and not layout.narrow, 5, "the landscape window")
    assert not window.dpad.get_visible() and window.toolbar_revealer.get_visible()
    window.set_default_size(400, 700)
    pump(
        lambda: layout.narrow and window.dpad.get_mapped() and layout.strip.get_mapped(),
        5,
        "the phone layout",
    )
    assert not window.toolbar_revealer.get_visible()
    gui.shot("narrowed-400")
    window.set_default_size(800, 480)
    pump(lambda: not layout.narrow, 5, "the landscape layout again")
    idle(0.3)
    assert not window.dpad.get_visible(), "the D-pad the phone layout showed stayed"
    assert window.toolbar_revealer.get_mapped() and not layout.strip.get_visible()
    assert window.dpad.get_halign() is Gtk.Align.START and window.dpad.get_margin_bottom() == 12
    gui.shot("widened-800")
