"""The smaller command-line defects a new user met, each against the simulator (issue 22).

Names compare case-insensitively as ARIA compares goal names (goto, patrol, run), sent in the
server's own spelling; a central server is named as such by status and doctor instead of "offers
no robot status".
"""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest

from rtmu.base.exit_codes import EXIT_DOCTOR_STATUS, EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.sim import SimThread
from rtmu.sim.central_thread import CentralThread
from rtmu.sim.ld_data import ld_state

from .navsim import fast_sim, reset, robot
from .uiqueue import eventually


@pytest.fixture(scope="module")
def aram() -> Iterator[SimThread]:
    with fast_sim(profile="aram") as sim:
        yield sim


def test_goal_route_and_command_names_compare_case_insensitively(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    where = f"127.0.0.1:{aram.port}"
    reset(aram)
    assert main(["goto", where, "room 101", "--json", "--timeout", "5", "--limit", "60"]) == EXIT_OK
    last = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert last["outcome"] == "arrived" and last["text"] == "Arrived at Room 101"  # the map's spelling
    assert main(["patrol", where, "NIGHT PATROL", "--timeout", "5"]) == EXIT_OK
    assert ld_state(aram.server).patrols[-1] == "Night patrol"  # type: ignore[arg-type]
    assert main(["run", where, "resettripodometer", "--timeout", "5"]) == EXIT_OK
    assert main(["goto", where, "room 1O1", "--timeout", "5"]) == EXIT_USAGE  # still refused when absent
    assert "no goal 'room 1O1'" in capsys.readouterr().err
    eventually(lambda: robot(aram).status != "", timeout=5)


def test_status_and_doctor_name_a_central_server(capsys: pytest.CaptureFixture[str]) -> None:
    with CentralThread(robots=1) as fleet:
        where = f"127.0.0.1:{fleet.port}"
        assert main(["status", where, "--once", "--timeout", "5"]) == EXIT_UNSUPPORTED
        err = capsys.readouterr().err
        assert "ARIA's central server" in err and f"rtmu fleet {where}" in err and "--robot NAME" in err
        assert "offers no robot status" not in err
        assert main(["doctor", where, "--timeout", "5"]) == EXIT_DOCTOR_STATUS
        out = capsys.readouterr().out
        assert "ARIA's central server" in out and "rtmu --central" in out
