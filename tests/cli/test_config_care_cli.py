"""``rtmu config`` care against the simulator and scripted servers: factory values, reset, export, import."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from client.servers import SPECS, ServerThread, TestServer
from client.uiqueue import UiQueue, eventually
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.config_file import ConfigFileError, read_file
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import RobotModel
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.config import ConfigParam, ConfigSectionPacket, ParamType, SetConfigReply
from rtmu.protocol.payloads.configcare import ConfigDefaults
from rtmu.sim import SimThread
from rtmu.subcommands.config import EXIT_REFUSED
from rtmu.values.target import Target
from simulators import simulator

sim = simulator()


def config(port: int, *argv: str) -> int:
    return main(["config", f"127.0.0.1:{port}", "--timeout", cli_timeout(5), *argv])


def test_defaults_list_only_what_differs_from_the_factory_values(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert config(sim.port, "--defaults") == EXIT_OK
    assert capsys.readouterr().out.strip() == "every parameter has its factory value"
    assert config(sim.port, "--set", "Teleop/Timeout=0.75", "Battery/Drain=false") == EXIT_OK
    capsys.readouterr()
    assert config(sim.port, "--defaults") == EXIT_OK
    assert capsys.readouterr().out.splitlines() == [
        "Teleop/Timeout = 0.75    factory: 2",
        "Battery/Drain = false    factory: true",
        "Battery/DrainScale = 0    factory: 1",
    ]
    assert config(sim.port, "--defaults", "--json") == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["differences"][0] == {
        "section": "Teleop",
        "name": "Timeout",
        "value": "0.75",
        "default": "2",
        "editable": True,
    }
    served = sim.call(lambda: len(sim.server.arconfig.values()))  # type: ignore[union-attr]
    assert doc["factory_values"] == served and doc["cut"] == 0  # every parameter that has a value


def test_reset_one_parameter_then_a_whole_section(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert config(sim.port, "--set", "Teleop/Timeout=0.75", "Robot config/TransVelMax=400") == EXIT_OK
    assert config(sim.port, "--set", "Robot config/RotVelMax=100") == EXIT_OK
    capsys.readouterr()
    assert config(sim.port, "--reset", "teleop/timeout") == EXIT_OK  # names as ARIA compares them
    assert capsys.readouterr().out.strip() == "reset to factory values: Teleop/Timeout"
    ratio = sim.server.world.ratio_mode  # type: ignore[union-attr]
    assert ratio.timeout == 2.0 and ratio.trans_vel_max == 400
    assert config(sim.port, "--reset", "Robot config", "--json") == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc == {
        "reset": ["Robot config/TransVelMax", "Robot config/RotVelMax"],
        "accepted": True,
        "error": "",
    }
    assert ratio.trans_vel_max == 1500 and ratio.rot_vel_max == 500
    assert config(sim.port, "--reset", "Teleop") == EXIT_OK
    assert "already at its factory value" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("target", "why"),
    [("Teleop/Nope", "no parameter 'Teleop/Nope'"), ("Nowhere", "no section 'Nowhere'")],
)
def test_reset_of_something_the_server_lacks_is_a_usage_error(
    sim: SimThread, capsys: pytest.CaptureFixture[str], target: str, why: str
) -> None:
    assert config(sim.port, "--reset", target) == EXIT_USAGE
    assert why in capsys.readouterr().err


def test_export_then_import_restores_every_value_in_one_set(
    sim: SimThread, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    file = tmp_path / "robot.toml"
    assert config(sim.port, "--export", str(file)) == EXIT_OK
    served = sim.call(lambda: len(sim.server.arconfig.values()))  # type: ignore[union-attr]
    assert capsys.readouterr().out.strip() == f"wrote {served} parameters to {file}"
    values = read_file(file)
    assert values["Teleop"]["Timeout"] == "2" and values["Robot config"]["SerialNumber"] == "SIM-P3DX-0001"
    assert '"SerialNumber" = "SIM-P3DX-0001"  # factory, read-only' in file.read_text()
    assert config(sim.port, "--set", "Teleop/Timeout=0.5", "Camera/FrameSize=640x480") == EXIT_OK
    sets = sim.server.arconfig.sets  # type: ignore[union-attr]
    capsys.readouterr()
    assert config(sim.port, "--import", str(file)) == EXIT_OK
    assert capsys.readouterr().out.strip() == f"imported 2 values ({served - 2} already as the file says)"
    assert sim.server.arconfig.sets == sets + 1  # type: ignore[union-attr]
    assert sim.server.world.ratio_mode.timeout == 2.0 and sim.server.video_size == (320, 240)  # type: ignore[union-attr]


def test_an_existing_file_is_kept_unless_forced(sim: SimThread, tmp_path: Path, capsys) -> None:
    file = tmp_path / "robot.toml"
    file.write_text("precious")
    assert config(sim.port, "--export", str(file)) == EXIT_USAGE
    assert "already exists (give --force to replace it)" in capsys.readouterr().err
    assert file.read_text() == "precious"
    assert config(sim.port, "--export", str(file), "--force") == EXIT_OK
    assert read_file(file)["Teleop"]["Timeout"] == "2"
    assert sorted(os.listdir(tmp_path)) == ["robot.toml"]  # no temporary file left beside it
    assert main(["config", "127.0.0.1:1", "--force"]) == EXIT_USAGE


def test_an_import_that_does_not_fit_sends_nothing_and_names_every_problem(
    sim: SimThread, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    file = tmp_path / "bad.toml"
    file.write_text(
        'format = "rtmu-config-1"\n'
        '["Teleop"]\n"Timeout" = "99"\n'
        '["Robot config"]\n"SerialNumber" = "STOLEN"\n"TransVelMax" = "300"\n'
        '["Camera"]\n"FrameSize" = "1x1"\n"Zoom" = "2"\n'
        '["Nowhere"]\n"X" = "1"\n'
    )
    sets = sim.server.arconfig.sets  # type: ignore[union-attr]
    assert config(sim.port, "--import", str(file)) == EXIT_REFUSED
    err = capsys.readouterr().err
    for words in (
        "Teleop/Timeout: '99' is above the maximum of 60",
        "Robot config/SerialNumber is read-only here ('STOLEN' differs from 'SIM-P3DX-0001')",
        "Camera/FrameSize: '1x1' is not one of 320x240, 640x480",
        "no parameter Camera/Zoom on this server",
        "no section 'Nowhere' on this server",
        "nothing was imported",
    ):
        assert words in err
    assert sim.server.arconfig.sets == sets  # type: ignore[union-attr]
    assert sim.server.world.ratio_mode.trans_vel_max == 1500  # type: ignore[union-attr]  # the good value too


@pytest.mark.parametrize(
    ("content", "why"),
    [
        ("not = [toml", "not a configuration export"),
        ('["Teleop"]\n"Timeout" = "2"\n', 'no format = "rtmu-config-1"'),
        ('format = "rtmu-config-1"\n["Teleop"]\n"Timeout" = 2\n', "must be a string"),
        ('format = "rtmu-config-1"\nTeleop = "x"\n', "is not a section"),
        (b"\xff\xfe", "not a configuration export"),
    ],
)
def test_a_file_that_is_not_an_export_is_refused(tmp_path: Path, content: str | bytes, why: str) -> None:
    file = tmp_path / "f.toml"
    if isinstance(content, bytes):
        file.write_bytes(content)
    else:
        file.write_text(content)
    with pytest.raises(ConfigFileError, match=why):
        read_file(file)


def test_a_missing_or_huge_import_file_is_a_usage_error(
    sim: SimThread, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert config(sim.port, "--import", str(tmp_path / "none.toml")) == EXIT_USAGE
    assert "cannot read" in capsys.readouterr().err
    huge = tmp_path / "huge.toml"
    with open(huge, "wb") as f:
        f.truncate(17 << 20)
    assert config(sim.port, "--import", str(huge)) == EXIT_USAGE
    assert "larger than 16 MB" in capsys.readouterr().err


def test_reload_is_heard_by_every_client_and_set_config_param_resets_one(sim: SimThread) -> None:
    model, ui = RobotModel(), UiQueue()
    calls: list[int] = []
    with ClientRunner(model, post=ui.post) as runner:
        runner.on_config_updated = lambda: calls.append(1)
        runner.connect(Target("127.0.0.1", sim.port)).result(10)
        eventually(lambda: runner.session is not None and runner.session.client is not None, 10)
        assert config(sim.port, "--reload") == EXIT_OK
        ui.wait_for(lambda: bool(calls), 10)
        assert config(sim.port, "--set", "Teleop/Timeout=1") == EXIT_OK
        ui.wait_for(lambda: len(calls) >= 2, 10)
        assert config(sim.port, "--reset", "Teleop/Timeout") == EXIT_OK  # through setConfigParam
        ui.wait_for(lambda: len(calls) >= 3, 10)
    assert sim.server.world.ratio_mode.timeout == 2.0  # type: ignore[union-attr]


# -- scripted servers ---------------------------------------------------------------------------------

CARE_SPECS = [
    *SPECS,
    ("getConfigBySectionsV4", "config", "none", "sections", "ConfigEditing", "RETURN_UNTIL_EMPTY"),
    ("setConfig", "set", "pairs", "string", "ConfigEditing", "RETURN_SINGLE|IDLE_PACKET"),
    ("setConfigParam", "set one", "TODO", "string", "ConfigEditing", "RETURN_SINGLE|IDLE_PACKET"),
    ("getConfigDefaults", "defaults", "string", "pairs", "ConfigEditing", "RETURN_SINGLE"),
    ("configUpdated", "updated", "none", "none", "ConfigEditing", "RETURN_SINGLE"),
]
TIMEOUT = ConfigParam("Timeout", ParamType.DOUBLE, 0.75, "s", 1, 0.0, 60.0, 2)


def care_server(defaults: list[bytes] | None, *, listed: bool = True) -> TestServer:
    server = TestServer(CARE_SPECS if listed else [s for s in CARE_SPECS if s[0] != "getConfigDefaults"])
    section = ConfigSectionPacket("Teleop", "", (TIMEOUT,))
    server.handlers["getConfigBySectionsV4"] = lambda s, a: [section.encode(), b""]
    server.handlers["getConfigDefaults"] = lambda s, a: defaults
    server.handlers["setConfig"] = lambda s, a: [SetConfigReply("").encode()]
    server.handlers["setConfigParam"] = lambda s, a: [
        FieldWriter().string("Changes prevented: serviced").bytes()
    ]
    return server


def run_config(server: TestServer, *argv: str) -> int:
    with ServerThread(server) as running:
        return main(["config", f"127.0.0.1:{running.port}", "--timeout", "2", *argv])


def test_a_server_without_factory_values_says_so(capsys: pytest.CaptureFixture[str]) -> None:
    assert run_config(care_server(None, listed=False), "--defaults") == EXIT_UNSUPPORTED
    assert "offers no factory values (getConfigDefaults" in capsys.readouterr().err


def test_a_server_that_prevents_changes_is_a_refusal_in_its_own_words(
    capsys: pytest.CaptureFixture[str],
) -> None:
    defaults = [ConfigDefaults((("Section", "Teleop"), ("Timeout", "2"))).encode()]
    assert run_config(care_server(defaults), "--reset", "Teleop/Timeout") == EXIT_REFUSED
    assert "the server refused: Changes prevented: serviced" in capsys.readouterr().err


def test_hostile_defaults_are_bounded_or_refused(capsys: pytest.CaptureFixture[str]) -> None:
    odd = [FieldWriter().string("Section").string("Teleop").string("Timeout").bytes()]  # a name, no value
    assert run_config(care_server(odd), "--defaults") == EXIT_CONNECTION
    assert "getConfigDefaults" in capsys.readouterr().err
    long_name = "x" * 5000
    noisy = [ConfigDefaults((("Section", "Teleop"), ("Timeout", "2"), (long_name, "1"))).encode()]
    assert run_config(care_server(noisy), "--defaults", "--json") == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["cut"] == 1 and doc["differences"][0]["name"] == "Timeout"
    assert run_config(care_server([b""]), "--defaults", "--json") == EXIT_OK  # no defaults: nothing differs
    assert json.loads(capsys.readouterr().out)["differences"] == []
