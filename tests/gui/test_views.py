"""The window's other states: no map, no camera, zoom and pan, the D-pad, focus loss, dialogs, plain text."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from pathlib import Path

import gi
import numpy as np
import pytest

from rtmu.base.notices import Kind, Notice
from rtmu.mapfile import MapObject, new_map, write_map
from rtmu.model.observables import Phase
from rtmu.sim import SimConfig, SimThread
from rtmu.ui.stop_keys import is_guarded

from .harness import OFFICE_MAP, Gui, idle, pump
from .test_window import moving, robot_blue, stopped

gi.require_version("Gtk", "4.0")
gi.require_version("Graphene", "1.0")
from gi.repository import Graphene, Gtk  # noqa: E402

Start = Callable[..., tuple[Gui, SimThread]]


@pytest.fixture
def start(request: pytest.FixtureRequest, screenshots: Path) -> Iterator[Start]:
    """``start(**sim_config)`` → (gui, sim), both torn down after the test."""
    opened: list[tuple[Gui, SimThread]] = []

    def make(**config: object) -> tuple[Gui, SimThread]:
        config.setdefault("map_path", OFFICE_MAP)
        sim = SimThread(SimConfig(port=0, seed=1, **config)).start()  # type: ignore[arg-type]
        try:
            gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        except BaseException:
            sim.stop()
            raise
        opened.append((gui, sim))
        return gui, sim

    yield make
    for gui, sim in opened:
        try:
            gui.close()
        finally:
            sim.stop()


def widget_centre_on_surface(widget: Gtk.Widget) -> tuple[int, int]:
    """Where the middle of ``widget`` is on its X window (surface) — for pointer events."""
    pump(lambda: widget.get_mapped() and widget.get_width() > 0, 3, "the widget to be laid out")
    idle(0.1)
    native = widget.get_native()
    ok, point = widget.compute_point(
        native, Graphene.Point().init(widget.get_width() / 2, widget.get_height() / 2)
    )
    assert ok
    dx, dy = native.get_surface_transform()
    return round(point.x + dx), round(point.y + dy)


def wait_for_window(title: str) -> Gtk.Window:
    def find() -> Gtk.Window | None:
        return next(
            (w for w in Gtk.Window.list_toplevels() if w.get_title() == title and w.get_mapped()), None
        )

    pump(lambda: find() is not None, 3, f"the window {title!r}")
    window = find()
    assert window is not None
    return window


def test_without_a_map_the_stage_shows_a_grid_the_robot_as_a_circle_and_says_so(start: Start) -> None:
    gui, sim = start(map_path=None)
    assert gui.model.map.value.state in ("none", "unsupported")
    note = gui.window.map_note
    assert note.get_visible() and "no map" in note.get_text()
    gui.shot("no-map")
    pixels = gui.stage_pixels()
    vp = gui.stage.viewport
    snap = sim.snapshot()
    th = math.radians(snap.th)
    sx, sy = vp.to_screen(snap.x - 150 * math.cos(th), snap.y - 150 * math.sin(th))
    assert robot_blue(pixels, sx, sy)
    # Grid lines: columns of slightly darker pixels recur across an empty row.
    row = pixels[20, :, :].astype(int).sum(axis=1)
    background = np.median(row)
    assert (row < background - 6).sum() >= 5, "no grid lines"


def test_the_map_note_says_connecting_connected_and_not_connected(start: Start, screenshots: Path) -> None:
    """One note, from the connection phase: never "not connected" beside a Disconnect button."""
    import socket

    from rtmu.model.observables import MapModel

    with socket.socket() as deaf:  # accepts the TCP connection (backlog) and never says a word
        deaf.bind(("127.0.0.1", 0))
        deaf.listen(1)
        port = deaf.getsockname()[1]
        gui = Gui.start(screenshots, "test_map_note_phases", "127.0.0.1", port, connect=False)
        try:
            note = gui.window.map_note
            assert note.get_visible() and note.get_text().startswith("Not connected: press Connect")
            gui.shot("not-connected")
            gui.window.connect_now()
            pump(lambda: gui.phase is Phase.CONNECTING, 3, "connecting")
            pump(lambda: note.get_text() == f"Connecting to 127.0.0.1:{port}…", 3, "the connecting note")
            assert note.get_visible() and gui.window.connect_button.get_label() == "Disconnect"
            gui.shot("connecting")
            gui.key("ctrl+d")
            pump(lambda: gui.phase is Phase.DISCONNECTED, 3, "the disconnect")
            assert note.get_visible() and note.get_text().startswith("Not connected: press Connect")
        finally:
            gui.close()
    gui, _sim = start()
    note = gui.window.map_note
    assert gui.model.map.value.state == "ready" and not note.get_visible(), "a shown map needs no note"
    gui.model.map.set(MapModel(state="loading", received=7))
    assert note.get_visible() and note.get_text() == "Loading the map… (7 packets)"
    gui.shot("loading")
    gui.model.map.set(MapModel(state="failed", error="line 3: not a number"))
    assert note.get_text() == "The map could not be loaded: line 3: not a number"
    gui.shot("map-error")
    gui.key("ctrl+d")
    pump(lambda: gui.phase is Phase.DISCONNECTED, 3, "the disconnect")
    assert note.get_visible() and note.get_text().startswith("Not connected: press Connect")
    gui.shot("after-ctrl-d")


def test_without_a_camera_the_command_is_disabled_and_says_why(start: Start) -> None:
    gui, _sim = start(camera=False)
    window = gui.window
    assert not window.camera_button.get_sensitive()
    assert "no camera" in (window.camera_button.get_tooltip_text() or "")
    gui.key("Escape")
    pump(lambda: window.banners.text("camera") is not None, 3, "the camera banner")
    assert "no camera" in window.banners.text("camera")  # type: ignore[operator]
    assert window.stack.get_visible_child_name() == "map"
    gui.shot("no-camera")


def test_zoom_keys_fit_and_a_drag_that_turns_follow_off(start: Start) -> None:
    gui, _sim = start()
    stage = gui.stage
    assert stage.fitted and stage.follow
    fitted_zoom = stage.viewport.zoom
    gui.key("ctrl+plus", "ctrl+plus", "ctrl+plus", "ctrl+plus", "ctrl+plus")
    pump(lambda: stage.viewport.zoom > fitted_zoom * 2, 3, "zooming in")
    assert not stage.fitted
    pump(lambda: stage.last_frame_complete, 5, "the zoomed tiles")
    r = gui.model.robot.value
    sx, sy = stage.viewport.to_screen(r.x, r.y)
    assert 0 <= sx < stage.viewport.width and 0 <= sy < stage.viewport.height, (
        "follow keeps the robot in view"
    )
    gui.shot("zoomed-in")
    x, y = widget_centre_on_surface(stage)
    before = (stage.viewport.cx, stage.viewport.cy)
    gui.xdotool("mousemove", "--window", str(gui.xid()), str(x), str(y), "mousedown", "1")
    gui.xdotool("mousemove", "--window", str(gui.xid()), str(x - 120), str(y - 60))
    gui.xdotool("mousemove", "--window", str(gui.xid()), str(x - 200), str(y - 90), "mouseup", "1")
    pump(lambda: (stage.viewport.cx, stage.viewport.cy) != before, 3, "the drag to pan")
    assert not stage.follow and not gui.window.follow_button.get_active()
    gui.shot("panned")
    gui.key("ctrl+0")
    pump(lambda: stage.fitted and abs(stage.viewport.zoom - fitted_zoom) < 1e-9, 3, "fit")
    gui.key("f")
    pump(lambda: stage.follow, 3, "follow back on")


def test_the_touch_dpad_drives_while_held_and_shows_the_release(start: Start) -> None:
    gui, sim = start()
    window = gui.window
    window.activate_action("win.dpad", None)
    pump(lambda: window.dpad.get_visible() and window.dpad.get_mapped(), 3, "the D-pad")
    pad = window.dpad.pads["drive_forward"]
    x, y = widget_centre_on_surface(pad)
    start_x = sim.snapshot().x
    gui.xdotool("mousemove", "--window", str(gui.xid()), str(x), str(y), "mousedown", "1")
    try:
        pump(lambda: sim.snapshot().x > start_x + 100, 8, "the D-pad to drive forward")
        assert pad.has_css_class("held")
        gui.shot("dpad-held")
    finally:
        gui.xdotool("mouseup", "1")
    pump(lambda: not pad.has_css_class("held"), 3, "the pad to show the release")
    pump(lambda: stopped(sim), 8, "the robot to stop on release")
    gui.shot("dpad-released")


def test_focus_loss_while_driving_stops_the_robot(start: Start) -> None:
    gui, sim = start()
    other = Gtk.Window(title="elsewhere")
    other.present()
    try:
        pump(other.get_mapped, 3, "the other window")
        gui.focus()
        gui.keydown("Up")
        try:
            pump(lambda: moving(sim), 8, "the robot to move")
            from gi.repository import GdkX11

            gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(other.get_surface())))
            pump(lambda: not gui.window.is_active(), 3, "the RTMU window to lose focus")
            pump(lambda: stopped(sim), 8, "the robot to stop on focus loss")
            gui.shot("stopped-after-focus-loss")
        finally:
            gui.keyup("Up")
    finally:
        other.destroy()


def test_settings_dialog_validates_inline_and_saves_a_profile(start: Start) -> None:
    gui, _sim = start()
    window = gui.window
    gui.key("ctrl+comma")
    pump(
        lambda: window.dialogs.settings is not None and window.dialogs.settings.get_mapped(),
        3,
        "the settings dialog",
    )
    dialog = window.dialogs.settings
    dialog.port.set_text("99999")
    dialog.host.set_text("bad host!")
    assert not dialog.save.get_sensitive()
    assert dialog.errors["port"].get_visible() and "65535" in dialog.errors["port"].get_text()
    assert dialog.errors["host"].get_visible()
    gui.render(dialog, gui.shots / f"{gui.name}-01-invalid.png")
    dialog.port.set_text("7373")
    dialog.host.set_text("robot.local")
    dialog.profile_entry.set_text("lab robot")
    assert dialog.save.get_sensitive() and not dialog.errors["port"].get_visible()
    dialog.save.emit("clicked")
    pump(lambda: not dialog.get_visible(), 3, "the dialog to close")
    profile = window.controller.profile
    assert (profile.name, profile.host, profile.port) == ("lab robot", "robot.local", 7373)
    assert gui.app.settings.profiles["lab robot"].port == 7373
    assert gui.phase is Phase.CONNECTED, "saving does not drop the current connection"


def test_f1_opens_the_keys_window(start: Start) -> None:
    gui, _sim = start()
    gui.key("F1")
    pump(lambda: gui.window.keys_help.shown is not None and gui.window.keys_help.shown.get_mapped(), 3, "F1")
    keys = gui.window.keys_help.shown
    assert keys is not None
    gui.render(keys, gui.shots / f"{gui.name}-01-keys.png")
    keys.close()


def test_server_strings_are_plain_text_never_markup(start: Start, tmp_path: Path) -> None:
    odd = "<b>Lab</b> & <i>co"
    path = tmp_path / "<b>odd & map.map"
    write_map(
        new_map(
            [[0, 0], [5000, 0]],
            [[0, 0, 5000, 0], [0, 0, 0, 4000], [5000, 0, 5000, 4000], [0, 4000, 5000, 4000]],
            objects=[
                MapObject("RobotHome", 1000, 2000, 0, name="Home"),
                MapObject("Goal", 3000, 2000, name=odd),
            ],
        ),
        path,
    )
    gui, _sim = start(map_path=path)
    assert "<b>odd & map.map" in gui.window.subtitle_label.get_text()
    assert not gui.window.subtitle_label.get_use_markup()
    layout = gui.stage.labels.layout(odd)
    assert layout.get_text() == odd
    gui.window.show_notice(Notice.error(Kind.GENERAL, odd))
    assert gui.window.banners.text(f"notice:{odd}") == odd
    idle(0.2)
    gui.shot("odd-strings")


def test_banners_tell_connecting_connected_and_a_failure_with_its_reason(screenshots: Path) -> None:
    with SimThread(SimConfig(port=0, map_path=None, seed=1)) as sim:
        gui = Gui.start(screenshots, "test_banners_connect", "127.0.0.1", sim.port)
        try:
            told = [(topic, text) for topic, _level, text in gui.window.banners.history]
            assert ("link", f"Connecting to 127.0.0.1:{sim.port}…") in told
            assert ("link", f"Connected to 127.0.0.1:{sim.port}") in told
        finally:
            gui.close()
    import socket

    with socket.socket() as s:  # a port with nobody listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    gui = Gui.start(screenshots, "test_banners_refused", "127.0.0.1", port, connect=False)
    try:
        gui.window.connect_now()
        pump(lambda: gui.phase is Phase.FAILED, 10, "the connection to fail")
        text = gui.window.banners.text("link") or ""
        assert text.startswith(f"Could not connect to 127.0.0.1:{port}: ") and len(text) > 40, text
        gui.shot("refused")
    finally:
        gui.close()


def test_speed_at_its_limit_says_so(start: Start) -> None:
    gui, _sim = start()
    gui.key(*["plus"] * 6)
    pump(lambda: gui.operator.speed.value.percent == 100, 3, "full speed")
    gui.key("plus")
    pump(lambda: gui.window.banners.text("speed") == "Speed at its maximum: 100 %", 3, "the limit banner")
    gui.shot("speed-limit")


def test_t_opens_turn_by_angle_and_the_robot_turns(start: Start) -> None:
    from gi.repository import GdkX11

    gui, sim = start()
    window = gui.window
    gui.key("t")
    dialog = wait_for_window("Turn by an angle")
    gui.render(dialog, gui.shots / f"{gui.name}-01-turn-dialog.png")
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(dialog.get_surface())))
    gui.key("ctrl+a", "4", "5", "Return")  # type 45, Enter = Go
    pump(lambda: abs(sim.snapshot().th - 45) < 3, 15, "the robot to turn 45° left")
    assert window.get_mapped()
    gui.focus()
    gui.key("g")
    wait_for_window("Go a distance").close()


def test_the_window_grows_gracefully(start: Start) -> None:
    gui, _sim = start()
    window = gui.window
    small = (gui.stage.get_width(), gui.stage.get_height())
    window.set_default_size(1280, 800)
    pump(lambda: window.get_width() >= 1200, 5, "the window to grow")
    pump(
        lambda: gui.stage.get_width() > small[0] + 300 and gui.stage.last_frame_complete, 5, "a bigger stage"
    )
    assert gui.stage.fitted, "a fitted map is fitted again to the new size"
    gui.shot("1280x800")


def test_a_user_is_asked_for_the_password_and_a_wrong_one_is_reported(
    screenshots: Path, tmp_path: Path
) -> None:
    from gi.repository import GdkX11

    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser alice secret1 all\n")
    with SimThread(SimConfig(port=0, map_path=None, users_path=users, seed=1)) as sim:
        gui = Gui.start(screenshots, "test_password", "127.0.0.1", sim.port, connect=False, user="alice")
        try:
            for password, ok in (("nope", False), ("secret1", True)):
                gui.focus()
                gui.key("ctrl+o")
                prompt = wait_for_window("Password")
                gui.render(prompt, gui.shots / f"{gui.name}-prompt.png")
                gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(prompt.get_surface())))
                gui.xdotool("type", "--delay", "20", password)
                gui.key("Return")
                if ok:
                    gui.wait_connected()
                else:
                    pump(lambda: gui.phase is Phase.FAILED, 10, "the login to be rejected")
                    assert (gui.window.banners.text("link") or "").startswith("Could not connect")
                    gui.shot("wrong-password")
        finally:
            gui.close()


def test_plain_rtmu_opens_the_last_profile_and_connects(screenshots: Path, tmp_path: Path) -> None:
    from rtmu.settings.store import Profile, Settings, save_settings
    from rtmu.ui.options import GuiOptions

    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        settings = Settings()
        settings.put(Profile(name="elsewhere", host="127.0.0.1", port=1))
        settings.put(Profile(name="lab", host="127.0.0.1", port=sim.port, zoom=1.0, speed=70))
        path = save_settings(settings, tmp_path / "settings.toml")
        gui = Gui.open(GuiOptions(settings_path=path), screenshots, "test_last_profile")
        try:
            assert gui.window.controller.profile.name == "lab"
            assert gui.operator.speed.value.percent == 70
            assert abs(gui.stage.viewport.zoom - 1.0) < 1e-9 and not gui.stage.fitted
            gui.key("minus")
            pump(lambda: gui.operator.speed.value.percent == 60, 3, "the speed to drop")
            gui.shot("last-profile-at-100pct-speed-60")
        finally:
            gui.close()
        from rtmu.settings.store import load_settings

        saved = load_settings(path).settings
        assert saved.last_profile == "lab" and saved.profiles["lab"].speed == 60, (
            "view choices are remembered"
        )


@pytest.mark.parametrize(("volts", "state"), [(11.3, "low"), (10.8, "critical")])
def test_battery_turns_amber_at_the_low_level_and_red_at_shutdown(
    start: Start, volts: float, state: str
) -> None:
    gui, _sim = start(map_path=None, battery_v=volts)
    cell = gui.window.toolbar.cells["battery"]
    pump(lambda: cell.has_css_class(state), 5, f"the battery cell to show {state}")
    assert gui.window.toolbar.battery_gauge.state == state
    assert ("LOW" if state == "low" else "SHUTDOWN") in (cell.get_tooltip_text() or "")
    gui.shot(f"battery-{state}")


def test_unsupported_commands_are_disabled_with_the_reason(start: Start) -> None:
    from rtmu.control.commands import CommandState

    gui, _sim = start(map_path=None)
    window = gui.window
    window.activate_action("win.dpad", None)
    reason = "this server does not offer ratioDrive"
    window.commands_changed({"drive_forward": CommandState(False, reason)})
    pad = window.dpad.pads["drive_forward"]
    assert not pad.get_sensitive() and reason in (pad.get_tooltip_text() or "")
    window.commands_changed({"turn": CommandState(False, "this server does not offer turnByAngle")})
    assert not window.lookup_action("turn").get_enabled()
    gui.key("t")
    pump(lambda: "turnByAngle" in (window.banners.text("notice:turn") or ""), 3, "the reason banner")
    gui.shot("turn-unsupported")


def test_wifi_not_published_is_greyed_with_a_reason(screenshots: Path) -> None:
    import time as _time

    from rtmu.model.observables import RobotState

    gui = Gui.start(screenshots, "test_wifi", "127.0.0.1", 1, connect=False)
    try:
        gui.model.robot.set(RobotState(x=1.0, battery_v=12.5, numbers_at=_time.monotonic()))
        cell = gui.window.toolbar.cells["wifi"]
        assert cell.stale and "does not publish" in (cell.get_tooltip_text() or "")
        assert gui.window.toolbar.cells["x"].stale, "values while not connected are never shown as fresh"
        gui.shot("wifi-not-published")
    finally:
        gui.close()


def test_f11_full_screen_and_ctrl_q_quits_after_stopping_the_robot(start: Start) -> None:
    gui, sim = start()
    window = gui.window
    gui.key("F11")
    pump(lambda: window.lookup_action("fullscreen").get_state().get_boolean(), 3, "the full-screen request")
    gui.shot("f11-requested")
    # Xvfb has no window manager to honour the request: what is checked is that F11 reached the window.
    gui.key("F11")
    pump(lambda: not window.lookup_action("fullscreen").get_state().get_boolean(), 3, "leaving full screen")
    gui.keydown("Up")
    try:
        pump(lambda: moving(sim), 8, "the robot to move")
        gui.shot("driving-before-ctrl-q")
        gui.key("ctrl+q")
        pump(lambda: not window.get_visible(), 3, "the window to close")
        pump(lambda: stopped(sim), 8, "the robot to stop on quit")
    finally:
        gui.keyup("Up")


def test_full_screen_keeps_stop_connect_the_menu_and_a_way_out(screenshots: Path, tmp_path: Path) -> None:
    """``rtmu --fullscreen``: GTK hides the header bar, so a slim bar must offer the essentials."""
    from rtmu.ui.options import GuiOptions

    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        options = GuiOptions(
            host="127.0.0.1", port=sim.port, fullscreen=True, connect=False,
            settings_path=tmp_path / "settings.toml", persist=False,
        )  # fmt: skip
        gui = Gui.open(options, screenshots, "test_fullscreen", connect=False)
        try:
            window = gui.window
            bar = window.fullscreen_bar
            pump(window.is_fullscreen, 3, "full screen")
            pump(lambda: bar.get_child_revealed(), 3, "the full-screen bar")
            assert not window.get_titlebar().get_mapped(), "GTK hides the header bar in full screen"
            for button in (bar.stop_button, bar.connect_button, bar.menu_button, bar.leave_button):
                assert button.get_mapped() and button.get_sensitive()
            assert bar.stop_button.has_css_class("destructive-action")
            assert bar.connect_button.get_label() == "Connect"
            gui.shot("fullscreen-not-connected")
            gui.click(bar.connect_button)
            gui.wait_connected()
            assert bar.connect_button.get_label() == "Disconnect"
            assert "connected" in bar.status_label.get_text()
            gui.keydown("Up")
            try:
                pump(lambda: moving(sim), 8, "the robot to move")
                gui.click(bar.stop_button)
                pump(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", 3, "stop from the bar")
                pump(lambda: stopped(sim), 8, "the robot to stop")
            finally:
                gui.keyup("Up")
            gui.shot("fullscreen-connected")
            gui.click(bar.menu_button)
            popover = bar.menu_button.get_popover()
            pump(lambda: popover is not None and popover.get_mapped(), 3, "the menu")
            gui.screen_shot("fullscreen-menu")
            # The bar's menu is made on this first open: it carries the stop keys all the same.
            assert popover is not None and is_guarded(popover)
            stops = window.stop_keys.stops
            gui.key("space")
            pump(lambda: window.stop_keys.stops == stops + 1, 3, "Space to stop from the bar's menu")
            popover.popdown()
            pump(lambda: not popover.get_mapped(), 3, "the menu to close")
            # Xvfb has no window manager: once mapped, the window's full-screen state cannot change,
            # so what is checked is that the click (and F11) reached the window as a request.
            action = window.lookup_action("fullscreen")
            assert action.get_state().get_boolean()
            gui.click(bar.leave_button)
            pump(lambda: not action.get_state().get_boolean(), 3, "the request to leave full screen")
            gui.key("F11")
            pump(lambda: action.get_state().get_boolean(), 3, "F11: full screen again")
            assert bar.get_child_revealed(), "the bar stays while the window is full screen"
        finally:
            gui.close()


def test_first_run_hint_in_full_screen_points_at_the_menu_on_screen(
    screenshots: Path, tmp_path: Path
) -> None:
    from rtmu.ui.application import FIRST_RUN_HINT
    from rtmu.ui.options import GuiOptions

    options = GuiOptions(fullscreen=True, settings_path=tmp_path / "settings.toml", persist=False)
    gui = Gui.open(options, screenshots, "test_first_run_fullscreen", connect=False)
    try:
        window = gui.window
        pump(lambda: window.fullscreen_bar.get_child_revealed(), 3, "the full-screen bar")
        assert window.banners.text("notice:hint") == FIRST_RUN_HINT
        assert "menu" in FIRST_RUN_HINT and window.fullscreen_bar.menu_button.get_mapped()
        assert "rtmu --demo" in FIRST_RUN_HINT.replace("\u2060", "").replace("\u00a0", " ")
        gui.shot("first-run-hint")
    finally:
        gui.close()


def test_greyed_menu_items_say_why(start: Start) -> None:
    """GTK menus have no tooltips: a disabled robot command carries its reason in its label."""
    gui, _sim = start(camera=False)
    window = gui.window

    def labels() -> dict[str, str]:
        menu = window.robot_menu
        out = {}
        for i in range(menu.get_n_items()):
            action = menu.get_item_attribute_value(i, "action", None).get_string()
            out[action] = menu.get_item_attribute_value(i, "label", None).get_string()
        return out

    def open_menu(label: str) -> None:
        gui.click(window.menu_button)
        popover = window.menu_button.get_popover()
        pump(lambda: popover.get_mapped(), 3, "the menu")
        gui.screen_shot(label)
        popover.popdown()
        pump(lambda: not popover.get_mapped(), 3, "the menu to close")

    assert labels()["win.camera"] == "Camera picture — not offered by the server"
    assert not window.lookup_action("camera").get_enabled()
    assert labels()["win.turn"] == "Turn by an angle…" and window.lookup_action("turn").get_enabled()
    open_menu("menu-no-camera")
    gui.focus()
    gui.key("ctrl+d")
    pump(lambda: gui.phase is Phase.DISCONNECTED, 3, "the disconnect")
    for action, label in labels().items():
        assert label.endswith(" — not connected"), (action, label)
        assert not window.lookup_action(action.removeprefix("win.")).get_enabled()
    open_menu("menu-not-connected")


def test_toolbar_columns_stay_put_between_connected_and_disconnected(start: Start) -> None:
    """Fixed column widths: "—" and "12.8 V" take the same room, so nothing shifts sideways."""
    gui, _sim = start()
    toolbar = gui.window.toolbar

    def lefts() -> dict[str, float]:
        out = {}
        for name, cell in toolbar.cells.items():
            ok, bounds = cell.compute_bounds(toolbar)
            assert ok
            out[name] = round(bounds.get_x())
        return out

    pump(lambda: not toolbar.cells["battery"].stale, 3, "fresh values")
    connected = lefts()
    gui.shot("connected")
    gui.key("ctrl+d")
    pump(lambda: gui.phase is Phase.DISCONNECTED, 3, "the disconnect")
    idle(0.2)
    assert lefts() == connected
    assert gui.window.get_focus() is None, "no widget holds the focus (no ring on the menu button)"
    gui.shot("disconnected")
