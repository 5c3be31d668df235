"""``rtmu config`` against the simulator: list, JSON, set, refusals (exit 6), no configuration (exit 4)."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

import pytest

from client.servers import SPECS, ServerThread, TestServer
from client.uiqueue import UiQueue, eventually
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_REFUSED, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.config_feed import MAX_TEXT, ConfigFeed, ServerConfig, check_value, fetch_config
from rtmu.client.connection import AriaClient
from rtmu.client.errors import MalformedReply
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import RobotModel
from rtmu.protocol.payloads.config import ConfigParam, ConfigSectionPacket, ParamType
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target
from simulators import simulator

sim = simulator()


def addr(port: int) -> str:
    return f"127.0.0.1:{port}"


def test_config_lists_sections_and_parameters(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["config", addr(sim.port), "--timeout", cli_timeout(5)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "[Teleop]" in out and "Timeout = 2    [double 0…60, intermediate]" in out
    assert "FrameSize = 320x240    [string one of 320x240, 640x480, intermediate]" in out
    assert "SerialNumber = SIM-P3DX-0001    [string, factory, read-only]" in out


def test_config_json_has_types_limits_and_editability(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["config", addr(sim.port), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["source"] == "getConfigBySectionsV4" and doc["last_editable"] == "expert"
    params = {f"{s['name']}/{p['name']}": p for s in doc["sections"] for p in s["params"]}
    assert params["Teleop/Timeout"] | {"description": ""} == {
        "name": "Timeout",
        "type": "double",
        "value": 2.0,
        "description": "",
        "priority": "intermediate",
        "editable": True,
        "min": 0.0,
        "max": 60.0,
    }
    assert params["Camera/FrameSize"]["choices"] == ["320x240", "640x480"]
    assert params["Robot config/SerialNumber"]["editable"] is False
    assert params["Battery/Drain"]["value"] is True


def test_config_set_changes_the_simulation(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        [
            "config",
            addr(sim.port),
            "--timeout",
            "5",
            "--set",
            "Teleop/Timeout=0.75",
            "Robot config/TransVelMax=400",
        ]
    )
    assert code == EXIT_OK
    assert capsys.readouterr().out.strip() == "accepted: 2 values"
    assert sim.call(
        lambda: (sim.server.world.ratio_mode.timeout, sim.server.world.ratio_mode.trans_vel_max)
    ) == (
        0.75,
        400,
    )
    assert main(["config", addr(sim.port), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["sections"][0]["params"][0]["value"] == 0.75


def test_a_refused_value_exits_6_with_the_servers_words(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "config",
            addr(sim.port),
            "--timeout",
            cli_timeout(5),
            "--set",
            "Teleop/Timeout=1",
            "Camera/FrameSize=1x1",
        ]
    )
    assert code == EXIT_REFUSED
    err = capsys.readouterr().err
    assert (
        err.strip()
        == "rtmu config: the server refused: Camera/FrameSize: '1x1' is not one of 320x240, 640x480"
    )
    assert sim.call(lambda: sim.server.world.ratio_mode.timeout) == 2.0  # all or nothing
    code = main(
        ["config", addr(sim.port), "--json", "--timeout", cli_timeout(5), "--set", "Teleop/Timeout=-1"]
    )
    assert code == EXIT_REFUSED
    assert json.loads(capsys.readouterr().out) == {
        "accepted": False,
        "error": "Teleop/Timeout: -1 is below the minimum of 0",
    }


def test_markup_and_control_characters_from_the_server_are_printed_harmlessly(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with SimThread(SimConfig(port=0, config_filler=40)) as s:
        assert main(["config", addr(s.port), "--timeout", cli_timeout(5)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "[<b>Extra</b> & 0]" in out and "P1<i>&amp; = 0.1" in out  # literal, as the server sent it


def test_bad_assignments_fail_before_connecting(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["config", "127.0.0.1:9", "--set", "NoSlash=1"])
    assert exit_info.value.code == EXIT_USAGE
    assert "SECTION/PARAM=VALUE" in capsys.readouterr().err


def test_a_server_without_configuration_exits_4(capsys: pytest.CaptureFixture[str]) -> None:
    with ServerThread(TestServer()) as server:
        assert main(["config", addr(server.port), "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
        assert "offers no configuration" in capsys.readouterr().err
        assert (
            main(["config", addr(server.port), "--timeout", cli_timeout(5), "--set", "A/b=1"])
            == EXIT_UNSUPPORTED
        )


# -- the client module on its own: big, hostile and malformed configurations -----------------------
CONFIG_SPECS = [
    ("getConfigBySectionsV4", "config", "none", "sections", "ConfigEditing", "RETURN_UNTIL_EMPTY"),
    ("setConfig", "set", "pairs", "string", "ConfigEditing", "RETURN_SINGLE|IDLE_PACKET"),
]


def _fetch(port: int) -> ServerConfig:
    async def go() -> ServerConfig:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", port), timeout=5)
        try:
            return await fetch_config(client, 10)
        finally:
            await client.disconnect()

    return asyncio.run(go())


def test_ten_thousand_parameters_arrive_whole_and_bounded() -> None:
    with SimThread(SimConfig(port=0, camera=False, config_filler=10_000)) as s:
        config = _fetch(s.port)
        served = s.call(  # every parameter but the separators, which only draw a line
            lambda: sum(p.template.kind is not ParamType.SEPARATOR for p in s.server.arconfig.params)  # type: ignore[union-attr]
        )
    assert served > 10_000  # the filler, its control-character one and the simulator's own
    assert config.param_count == served and config.cut == 0
    extra = [sec for sec in config.sections if sec.name.startswith("<b>Extra")]
    assert len(extra) == 10 and all(len(sec.params) == 1000 for sec in extra)  # parts joined per section
    assert config.find("<b>extra</b> & 3", "P3500<I>&AMP;") is not None  # ARIA compares names case-blind


def test_a_malformed_section_is_a_clear_error_and_a_huge_text_is_cut() -> None:
    server = TestServer(SPECS + CONFIG_SPECS)
    big = ConfigSectionPacket("S", "", (ConfigParam("Long", ParamType.STRING, "x" * 30_000),))
    replies = {"ok": [big.encode(), b""], "bad": [b"Sname\x00comment\x00\x00\x01\x00Pbroken", b""]}
    mode = ["ok"]
    server.handlers["getConfigBySectionsV4"] = lambda side, args: replies[mode[0]]
    with ServerThread(server) as running:
        config = _fetch(running.port)
        value = config.sections[0].params[0].value
        assert isinstance(value, str) and len(value) == MAX_TEXT and value.endswith("…")
        mode[0] = "bad"
        with pytest.raises(MalformedReply, match="getConfigBySectionsV4 did not decode"):
            _fetch(running.port)


def test_check_value_knows_types_limits_and_choices() -> None:
    timeout = ConfigParam("Timeout", ParamType.DOUBLE, 2.0, minimum=0.0, maximum=60.0)
    assert check_value(timeout, "0.5") == "" and check_value(timeout, "61") == "above the maximum of 60"
    assert (
        check_value(timeout, "-1") == "below the minimum of 0"
        and check_value(timeout, "soon") == "not a number"
    )
    assert check_value(timeout, "nan") == "not a number"
    count = ConfigParam("N", ParamType.INT, 1, minimum=0, maximum=9)
    assert check_value(count, "1.5") == "not a whole number"
    size = ConfigParam("Size", ParamType.STRING, "a", display_hint="Choices:a;;b")
    assert check_value(size, "c") == "not one of a, b" and check_value(size, "b") == ""
    assert check_value(ConfigParam("On", ParamType.BOOL, True), "maybe") == "not true or false"
    assert check_value(ConfigParam("L", ParamType.LIST), "x") == "cannot be changed here"


def test_a_flood_of_config_updated_reaches_the_ui_as_a_few_posts() -> None:
    specs = [
        *SPECS,
        *CONFIG_SPECS,
        ("configUpdated", "changed", "none", "none", "ConfigEditing", "RETURN_SINGLE"),
    ]
    server = TestServer(specs)
    thread = ServerThread(server)
    model, ui = RobotModel(), UiQueue()
    calls: list[int] = []
    with thread, ClientRunner(model, post=ui.post) as runner:
        runner.on_config_updated = lambda: calls.append(1)
        runner.connect(Target("127.0.0.1", server.port)).result(10)
        number = server.datalist.number("configUpdated")
        eventually(
            lambda: bool(thread.call(lambda: all(number in s.conn.subscriptions for s in server.sides)))
        )
        thread.call(lambda: [server.broadcast("configUpdated") for _ in range(5000)])
        runner.call(lambda: runner.session.client.request_once("getSafeDrive"))  # type: ignore[union-attr]
        eventually(lambda: runner.session.feed(ConfigFeed).updates == 5000)  # type: ignore[union-attr]
        posted = ui.drain()
    assert 1 <= len(calls) <= 50 and posted < 5000  # not one UI callback per broadcast


def test_a_user_without_config_editing_is_offered_no_configuration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """ARIA lists data only to users of its command group: without ConfigEditing there is nothing to edit."""
    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser alice secret1 all\nuser bob pw2 RobotInfo Movement Stop\n")
    pw_bob, pw_alice = tmp_path / "bob.pw", tmp_path / "alice.pw"
    pw_bob.write_text("pw2\n")
    pw_alice.write_text("secret1\n")
    with SimThread(SimConfig(port=0, camera=False, users_path=users)) as s:
        bob = [
            "config",
            addr(s.port),
            "--user",
            "bob",
            "--password-file",
            str(pw_bob),
            "--timeout",
            cli_timeout(5),
        ]
        assert main(bob) == EXIT_UNSUPPORTED
        assert main([*bob, "--set", "Teleop/Timeout=1"]) == EXIT_UNSUPPORTED
        assert s.call(lambda: s.server.world.ratio_mode.timeout) == 2.0  # type: ignore[union-attr]
        alice = [
            "config",
            addr(s.port),
            "--user",
            "alice",
            "--password-file",
            str(pw_alice),
            "--timeout",
            "5",
        ]
        assert main([*alice, "--set", "Teleop/Timeout=1"]) == EXIT_OK
        assert s.call(lambda: s.server.world.ratio_mode.timeout) == 1.0  # type: ignore[union-attr]
    assert "offers no configuration" in capsys.readouterr().err
