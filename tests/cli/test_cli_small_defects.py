"""The smaller command-line defects a new user met, each against the simulator (issue 22).

Names compare case-insensitively as ARIA compares goal names (goto, patrol, run), sent in the
server's own spelling; a central server is named as such by status and doctor instead of "offers
no robot status".
"""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest

from client.navsim import fast_sim, reset, robot
from client.uiqueue import eventually
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_DOCTOR_STATUS, EXIT_LOST, EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.sim import SimThread
from rtmu.sim.central_thread import CentralThread
from rtmu.sim.ld_data import ld_state


@pytest.fixture(scope="module")
def aram() -> Iterator[SimThread]:
    with fast_sim(profile="aram") as sim:
        yield sim


def test_goal_route_and_command_names_compare_case_insensitively(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    where = f"127.0.0.1:{aram.port}"
    reset(aram)
    assert (
        main(["goto", where, "room 101", "--json", "--timeout", cli_timeout(5), "--limit", "60"]) == EXIT_OK
    )
    last = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert last["outcome"] == "arrived" and last["text"] == "Arrived at Room 101"  # the map's spelling
    assert main(["patrol", where, "NIGHT PATROL", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert ld_state(aram.server).patrols[-1] == "Night patrol"  # type: ignore[arg-type]
    assert main(["run", where, "resettripodometer", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert (
        main(["goto", where, "room 1O1", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    )  # still refused when absent
    assert "no goal 'room 1O1'" in capsys.readouterr().err
    eventually(lambda: robot(aram).status != "", timeout=5)


def test_status_and_doctor_name_a_central_server(capsys: pytest.CaptureFixture[str]) -> None:
    with CentralThread(robots=1) as fleet:
        where = f"127.0.0.1:{fleet.port}"
        assert main(["status", where, "--once", "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
        err = capsys.readouterr().err
        assert "ARIA's central server" in err and f"rtmu fleet {where}" in err and "--robot NAME" in err
        assert "offers no robot status" not in err
        assert main(["doctor", where, "--timeout", cli_timeout(5)]) == EXIT_DOCTOR_STATUS
        out = capsys.readouterr().out
        assert "ARIA's central server" in out and "rtmu --central" in out


def test_dock_after_a_goto_on_an_ld_robot_ends_docked_not_at_the_limit(aram: SimThread) -> None:
    """The status still reads "Arrived at …" while dockInfo says Docked: the dock state answers."""
    where = f"127.0.0.1:{aram.port}"
    reset(aram)
    assert main(["goto", where, "Room 101", "--timeout", cli_timeout(5), "--limit", "60"]) == EXIT_OK
    assert main(["dock", where, "--timeout", cli_timeout(5), "--limit", "60"]) == EXIT_OK
    snap = robot(aram)
    assert aram.call(lambda: aram.server.world.dock_mode.state.name) == "DOCKED"  # type: ignore[union-attr]
    assert abs(snap.x - 800) < 300 and abs(snap.y - 6000) < 300, "it drove to the charger"


def test_an_ld_robots_patrol_and_route_goal_drive_it(aram: SimThread) -> None:
    where = f"127.0.0.1:{aram.port}"
    reset(aram)
    before = robot(aram)
    assert main(["patrol", where, "Loop", "--timeout", cli_timeout(5)]) == EXIT_OK
    eventually(lambda: robot(aram).status.startswith("Touring to"), timeout=10)
    eventually(lambda: abs(robot(aram).x - before.x) + abs(robot(aram).y - before.y) > 500, timeout=30)
    assert main(["goto", where, "Lab A", "--route", "--timeout", cli_timeout(5)]) == EXIT_OK
    eventually(lambda: robot(aram).status == "Arrived at Lab A", timeout=60)


def test_localizing_off_the_map_leaves_the_robot_lost_where_it_was(aram: SimThread) -> None:
    where = f"127.0.0.1:{aram.port}"
    reset(aram)
    before = robot(aram)
    code = main(["localize", where, "999999", "999999", "0", "--timeout", cli_timeout(5), "--limit", "30"])
    assert code == EXIT_LOST
    after = robot(aram)
    assert (after.x, after.y) == (before.x, before.y), "not teleported off the map"
    reset(aram)


def test_the_ld_simulator_says_what_it_is_when_it_starts() -> None:
    import subprocess
    import sys

    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--kind", "aram", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert "Omron LD robot (ARAM) at" in line and "Pioneer" not in line, line
    finally:
        proc.terminate()
        proc.wait(10)


def test_streaming_status_prints_on_change_and_a_heartbeat_at_most_once_a_second() -> None:
    """A parked robot's status was printed ten times a second, the same line every time."""
    import signal
    import subprocess
    import sys
    import time

    from rtmu.sim import SimConfig

    with SimThread(SimConfig(port=0)) as sim:
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "status", f"127.0.0.1:{sim.port}", "--json"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert proc.stdout is not None
        first = proc.stdout.readline()  # connected and streaming: from here on, 2.5 s of a parked robot
        started = time.monotonic()
        time.sleep(2.5)
        proc.send_signal(signal.SIGINT)
        rest, _err = proc.communicate(timeout=30)
        elapsed = time.monotonic() - started
    lines = [first, *rest.splitlines()]
    assert proc.returncode == 128 + signal.SIGINT
    assert len({json.loads(line)["x"] for line in lines}) == 1, "parked: every line the same"
    assert len(lines) <= 2 + elapsed, f"{len(lines)} lines in {elapsed:.1f} s: more than a heartbeat a second"


def test_developer_log_lines_stay_off_the_terminal_unless_asked() -> None:
    import os
    import subprocess
    import sys

    code = (
        "import logging; from rtmu.base import logs; logs.configure(); "
        "logging.getLogger('rtmu.client.connection').warning('the handler for updateNumbers took 12 ms'); "
        "logging.getLogger('rtmu.client.session').error('a real bug')"
    )
    quiet = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert "took 12 ms" not in quiet.stderr and "a real bug" in quiet.stderr
    env = {**os.environ, "RTMU_LOG": "warning"}
    loud = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=env)
    assert "took 12 ms" in loud.stderr
