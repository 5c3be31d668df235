"""The real window against ``rtmu sim --kind aram``: state of charge in %, and first-contact words."""

from __future__ import annotations

import socket
from pathlib import Path

import pytest

from rtmu.client.diagnosis import ADVICE
from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP, Gui, pump


@pytest.mark.parametrize(
    ("volts", "text", "state"),
    [(12.37, "76 %", "ok"), (11.3, "17 %", "low"), (11.05, "3 %", "critical")],
)
def test_toolbar_shows_state_of_charge_in_percent(
    screenshots: Path, request: pytest.FixtureRequest, volts: float, text: str, state: str
) -> None:
    # 11.0…12.8 V map onto 0…100 % in the aram profile; it reports low at 20 % and shutdown at 5 %.
    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE_MAP, battery_v=volts)) as sim:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)  # logs in: 6MTX answered
        try:
            robot = gui.model.robot
            pump(lambda: robot.value.battery_is_soc, 5, "batteryInfo's state-of-charge flag")
            cell = gui.window.toolbar.cells["battery"]
            pump(lambda: cell.value.get_text() == text, 5, f"the battery cell to read {text!r}")
            assert "%" in (cell.get_tooltip_text() or "")
            assert gui.window.toolbar.battery_gauge.state == state
            for cls in ("low", "critical"):
                assert cell.has_css_class(cls) == (cls == state)
            gui.shot(f"aram-battery-{state}")
        finally:
            gui.close()


def test_connection_error_uses_the_doctors_words(screenshots: Path, request: pytest.FixtureRequest) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # bound, not listening: connecting is refused
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", port, connect=False)
        try:
            gui.window.controller.connect()
            banners = gui.window.banners
            pump(lambda: ADVICE["refused"] in (banners.text("link") or ""), 10, "the refusal banner")
            assert (banners.text("link") or "").startswith(f"Could not connect to 127.0.0.1:{port}")
            gui.shot("refused-banner")
        finally:
            gui.close()


def test_window_protocol_option_overrides_and_a_refusal_names_the_wanted_string(
    screenshots: Path, request: pytest.FixtureRequest
) -> None:
    from rtmu.ui.options import GuiOptions

    from .harness import scratch_dir

    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE_MAP)) as sim:
        options = GuiOptions(
            host="127.0.0.1",
            port=sim.port,
            settings_path=scratch_dir("settings-") / "settings.toml",
            persist=False,
            connect=False,
            protocol="5MTX",
        )
        gui = Gui.open(options, screenshots, request.node.name, connect=False)
        try:
            assert gui.window.controller.profile.protocol == "5MTX"
            gui.window.controller.connect()
            banners = gui.window.banners
            pump(lambda: "--protocol 6MTX" in (banners.text("link") or ""), 10, "the protocol banner")
            assert "we sent '5MTX'" in (banners.text("link") or "")
            gui.shot("protocol-refused")
        finally:
            gui.close()


def test_settings_dialog_keeps_a_protocol_string(screenshots: Path, request: pytest.FixtureRequest) -> None:
    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE_MAP)) as sim:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            window = gui.window
            gui.key("ctrl+comma")
            pump(
                lambda: window.dialogs.settings is not None and window.dialogs.settings.get_mapped(),
                3,
                "the settings dialog",
            )
            dialog = window.dialogs.settings
            assert dialog.protocol.get_text() == ""  # empty: answer as the server asks
            dialog.protocol.set_text(" 6MTX ")
            gui.render(dialog, gui.shots / f"{gui.name}-01-protocol.png")
            dialog.save.emit("clicked")
            pump(lambda: not dialog.get_visible(), 3, "the dialog to close")
            assert window.controller.profile.protocol == "6MTX"
            name = window.controller.profile.name
            assert gui.app.settings.profiles[name].protocol == "6MTX"
        finally:
            gui.close()
