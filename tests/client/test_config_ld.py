"""An LD robot's configuration, told truthfully: which API it has, that RTMU cannot edit it yet, and
that the console can still ask for it — against ``rtmu sim --profile aram`` (protocol 6MTX), which
lists LD's ``getConfigValues`` family instead of ArConfig's and, as their layouts are not public,
never answers them.
"""

from __future__ import annotations

import json

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_FOREIGN_CONFIG, EXIT_OK, EXIT_TIMEOUT
from rtmu.cli import main
from rtmu.client.config_feed import ConfigApi, ForeignConfig, config_api
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.profiles import ARAM, DEFAULT
from rtmu.values.intents import FetchConfig, SetConfig
from rtmu.values.target import Target
from simulators import simulator

from .uiqueue import UiQueue

OFFICE = project_map("office.map")


aram = simulator(scope="module", profile="aram", map_path=OFFICE)


def addr(port: int) -> str:
    return f"127.0.0.1:{port}"


def test_the_api_is_named_from_the_data_list() -> None:
    assert config_api(ARAM.catalogue(camera=True)) is ConfigApi.OMRON_LD
    assert config_api(DEFAULT.catalogue(camera=True)) is ConfigApi.ARCONFIG
    assert config_api({"getConfigValues", "getConfigBySectionsV4"}) is ConfigApi.ARCONFIG
    assert config_api({"updateNumbers"}) is ConfigApi.NONE


def test_rtmu_config_says_which_api_and_exits_with_its_own_code(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["config", addr(aram.port), "--timeout", cli_timeout(5)]) == EXIT_FOREIGN_CONFIG
    out, err = capsys.readouterr()
    assert out == ""
    assert "configuration is Omron LD's (getConfigValues, setConfigValues, updateConfigValues" in err
    assert "cannot show or edit it yet" in err and "rtmu call HOST getConfigValues" in err
    assert "none offered" not in err and "offers no configuration" not in err
    assert main(["config", addr(aram.port), "--json", "--timeout", cli_timeout(5)]) == EXIT_FOREIGN_CONFIG
    said = json.loads(capsys.readouterr().out)
    assert said == {
        "api": "omron-ld",
        "data": ["getConfigValues", "setConfigValues", "updateConfigValues", "configExpandedSectionList"],
        "editable": False,
    }
    assert (
        main(["config", addr(aram.port), "--set", "Teleop/Timeout=3", "--timeout", cli_timeout(5)])
        == EXIT_FOREIGN_CONFIG
    )
    assert "cannot show or edit it yet" in capsys.readouterr().err


def test_an_arconfig_robot_says_its_api_in_json(capsys: pytest.CaptureFixture[str]) -> None:
    with SimThread(SimConfig(port=0)) as sim:
        assert main(["config", addr(sim.port), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["api"] == "arconfig"


def test_the_windows_configuration_feed_gets_the_same_plain_words(aram: SimThread) -> None:
    ui = UiQueue()
    runner = ClientRunner(RobotModel(), post=ui.post)
    runner.start()
    try:
        runner.connect(Target("127.0.0.1", aram.port)).result(10)
        with pytest.raises(ForeignConfig) as info:
            runner.send(FetchConfig()).result(10)
        assert info.value.api is ConfigApi.OMRON_LD and "cannot show or edit it yet" in str(info.value)
        with pytest.raises(ForeignConfig):
            runner.send(SetConfig({"Teleop": {"Timeout": "3"}})).result(10)
    finally:
        runner.close()


def test_the_console_reads_it_and_says_when_the_robot_is_silent(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(["call", addr(aram.port), "--list", "config", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    )
    listed = {e["name"]: e for e in json.loads(capsys.readouterr().out)}
    assert listed["getConfigValues"]["effect"] == "read"
    assert listed["setConfigValues"]["effect"] == "changes something"
    assert listed["updateConfigValues"]["effect"] == "changes something"
    # The simulator cannot know what an LD robot answers, so it does not: the console says so.
    assert main(["call", addr(aram.port), "getConfigValues", "--timeout", "0.5"]) == EXIT_TIMEOUT
    assert "getConfigValues: silent: no reply within 0.5 s" in capsys.readouterr().err
