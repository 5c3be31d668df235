"""ARIA's central server end to end: ``rtmu sim --central`` with three simulated robots switched to it.

Everything is real loopback TCP: the robots connect out to the central server's robot port and
switch, the central server logs in to each over that socket and forwards it on a port of its own,
and the operator side (``rtmu fleet``, ``--robot NAME``, :class:`CentralRoster`) only ever dials
the central server's address.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from patience import cli_timeout
from rtmu import mapfile as maps
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.central import CentralRoster
from rtmu.client.roster import RobotAdded, RobotRemoved, RosterEvent, RosterLost, RosterRestored
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.central_thread import CentralThread

from .uiqueue import eventually

ARENA = project_map("arena.map")
NAMES = ["robot1", "robot2", "robot3"]


@pytest.fixture(scope="module")
def fleet() -> Iterator[CentralThread]:
    with CentralThread(robots=3, template=SimConfig(port=0, map_path=ARENA, camera=False)) as f:
        yield f


def addr(fleet: CentralThread) -> str:
    return f"127.0.0.1:{fleet.port}"


def place(fleet: CentralThread, name: str, x: float, y: float) -> None:
    """Put the robot at (x, y), then wait for its server's next cycle: a status asked before it would be
    the cycle's cached one, from before (a busy machine runs the cycles late)."""
    server = fleet.sims[name]
    world = server.world

    def put() -> int:
        world.body.x, world.body.y = x, y
        return server.cycles

    placed_at = fleet.call(put)
    deadline = time.monotonic() + 10.0
    while fleet.call(lambda: server.cycles) <= placed_at:
        assert time.monotonic() < deadline, f"{name}'s server ran no cycle in 10 s"
        time.sleep(0.005)


def pose(fleet: CentralThread, name: str) -> tuple[float, float]:
    world = fleet.sims[name].world
    return fleet.call(lambda: (world.body.x, world.body.y))


class Heard:
    """What a roster emitted, from its own thread."""

    def __init__(self) -> None:
        self.events: list[RosterEvent] = []
        self._lock = threading.Lock()

    def __call__(self, event: RosterEvent) -> None:
        with self._lock:
            self.events.append(event)

    def of(self, kind: type) -> list[RosterEvent]:
        with self._lock:
            return [e for e in self.events if isinstance(e, kind)]


# -- the simulator role ------------------------------------------------------------------------
def test_each_switched_robot_is_forwarded_on_its_own_port(fleet: CentralThread) -> None:
    robots = fleet.robots()
    assert sorted(robots) == NAMES
    assert len(set(robots.values())) == 3 and fleet.port not in robots.values()


def test_a_robot_switched_to_a_central_server_refuses_direct_logins(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    port = fleet.sims["robot1"].port
    assert main(["status", f"127.0.0.1:{port}", "--once", "--timeout", cli_timeout(5)]) == EXIT_CONNECTION
    assert "central server" in capsys.readouterr().err


# -- rtmu fleet / --robot NAME ---------------------------------------------------------------------
def test_fleet_json_lists_every_robot_with_its_port_and_status(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    place(fleet, "robot2", 1234, -567)
    assert main(["fleet", addr(fleet), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    obj = json.loads(capsys.readouterr().out)
    assert obj["central"] == addr(fleet)
    rows = {r["name"]: r for r in obj["robots"]}
    assert sorted(rows) == NAMES
    forwarded = fleet.robots()
    for name, row in rows.items():
        assert row["host"] == "127.0.0.1" and row["port"] == forwarded[name]
        assert row["status"]["mode"] and "error" not in row["status"]
    assert (rows["robot2"]["status"]["x"], rows["robot2"]["status"]["y"]) == (1234, -567)


def test_fleet_plain_lists_names_ports_and_status_lines(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["fleet", addr(fleet), "--timeout", cli_timeout(5)]) == EXIT_OK
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"{addr(fleet)}: 3 robots"
    for name, line in zip(NAMES, out[1:], strict=True):
        assert line.startswith(f"  {name}  port {fleet.robots()[name]}  x=")


def test_status_with_robot_reads_that_robot(fleet: CentralThread, capsys: pytest.CaptureFixture[str]) -> None:
    for i, name in enumerate(NAMES):
        place(fleet, name, 1000 * (i + 1), 0)
    for i, name in enumerate(NAMES):
        code = main(["status", addr(fleet), "--robot", name, "--once", "--json", "--timeout", cli_timeout(5)])
        assert code == EXIT_OK
        assert json.loads(capsys.readouterr().out)["x"] == 1000 * (i + 1)


def test_robot_names_match_case_insensitively_as_in_aria(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    place(fleet, "robot3", 3210, 0)
    assert (
        main(["status", addr(fleet), "--robot", "ROBOT3", "--once", "--json", "--timeout", cli_timeout(5)])
        == EXIT_OK
    )
    assert json.loads(capsys.readouterr().out)["x"] == 3210


def test_unknown_robot_exits_2_naming_the_robots(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(["status", addr(fleet), "--robot", "nobody", "--once", "--timeout", cli_timeout(5)])
        == EXIT_USAGE
    )
    err = capsys.readouterr().err
    assert err.startswith("rtmu status: no robot 'nobody' behind the central server")
    assert "robots: robot1, robot2, robot3" in err


def test_robot_on_a_plain_robot_server_says_it_is_not_a_central_server(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    forwarded = fleet.robots()["robot1"]  # a robot server, which offers no clientList
    code = main(
        ["status", f"127.0.0.1:{forwarded}", "--robot", "robot1", "--once", "--timeout", cli_timeout(5)]
    )
    assert code not in (EXIT_OK, EXIT_USAGE)
    assert "clientList" in capsys.readouterr().err


def test_drive_with_robot_moves_only_that_robot(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    for i, name in enumerate(NAMES):
        place(fleet, name, 0, 2000 * i)
    before = {name: pose(fleet, name) for name in NAMES}
    argv = ["drive", addr(fleet), "--robot", "robot2", "--trans", "60", "--seconds", "0.6", "--json"]
    assert main([*argv, "--timeout", cli_timeout(5)]) == EXIT_OK
    obj = json.loads(capsys.readouterr().out)
    after = {name: pose(fleet, name) for name in NAMES}
    moved = {
        name: abs(after[name][0] - before[name][0]) + abs(after[name][1] - before[name][1]) for name in NAMES
    }
    assert moved["robot2"] > 50 and moved["robot1"] == 0 and moved["robot3"] == 0
    # The last status the command read, give or take the few mm a stopping robot still rolls.
    assert abs(obj["after"]["x"] - after["robot2"][0]) <= 20
    robot = fleet.sims["robot2"].robot
    assert fleet.call(lambda: (robot.trans_ratio, robot.mode_name)) == (0, "stop")  # stopped by us


def test_map_with_robot_downloads_through_the_forwarder(fleet: CentralThread, tmp_path: Path) -> None:
    expected = maps.read_map(ARENA)  # a map is many packets: the forwarder relays them to the asker
    for extra, name in (([], "bin.map"), (["--text"], "text.map")):
        out = tmp_path / name
        argv = [
            "map",
            addr(fleet),
            "--robot",
            "robot3",
            "--out",
            str(out),
            "--timeout",
            cli_timeout(10),
            *extra,
        ]
        assert main(argv) == EXIT_OK
        got = maps.read_map(out)
        assert (got.num_points, got.num_lines) == (expected.num_points, expected.num_lines)


def test_fleet_neither_offers_nor_takes_robot(
    fleet: CentralThread, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["fleet", "--help"])
    assert exc.value.code == 0 and "[--robot" not in capsys.readouterr().out
    with pytest.raises(SystemExit) as exc:
        main(["fleet", addr(fleet), "--robot", "robot1"])
    assert exc.value.code == EXIT_USAGE
    assert "unrecognized arguments: --robot" in capsys.readouterr().err


# -- CentralRoster ------------------------------------------------------------------------------
def test_roster_hears_the_list_then_robots_leaving_and_coming() -> None:
    with CentralThread(robots=3, template=SimConfig(port=0, camera=False)) as fl:
        heard = Heard()
        roster = CentralRoster("127.0.0.1", fl.port, timeout=5)
        roster.start(heard)
        try:
            eventually(lambda: len(heard.of(RobotAdded)) == 3, timeout=10)
            added = {e.endpoint.name: e.endpoint for e in heard.of(RobotAdded)}  # type: ignore[attr-defined]
            assert sorted(added) == NAMES
            assert all(e.via == f"127.0.0.1:{fl.port}" and e.host == "127.0.0.1" for e in added.values())
            assert {n: e.port for n, e in added.items()} == fl.robots()

            fl.stop_robot("robot3")  # the robot's server goes away: its switched connection ends
            eventually(lambda: heard.of(RobotRemoved) != [], timeout=10)
            assert [e.name for e in heard.of(RobotRemoved)] == ["robot3"]  # type: ignore[attr-defined]

            fl.add_robot("robot4")
            eventually(lambda: any(e.endpoint.name == "robot4" for e in heard.of(RobotAdded)), timeout=10)  # type: ignore[attr-defined]
            assert heard.of(RosterLost) == []
        finally:
            roster.close()


def test_roster_lost_once_when_the_central_server_dies() -> None:
    with CentralThread(robots=2, template=SimConfig(port=0, camera=False)) as fl:
        heard = Heard()
        roster = CentralRoster("127.0.0.1", fl.port, timeout=5)
        roster.start(heard)
        try:
            eventually(lambda: len(heard.of(RobotAdded)) == 2, timeout=10)
            fl.kill_central()
            eventually(lambda: heard.of(RosterLost) != [], timeout=10)
            time.sleep(0.5)  # anything else it might still say
            assert len(heard.of(RosterLost)) == 1
            assert heard.events[-1] == heard.of(RosterLost)[0]
        finally:
            roster.close()


def test_a_restarted_central_server_brings_the_roster_back_once() -> None:
    with CentralThread(robots=2, template=SimConfig(port=0, camera=False)) as fl:
        heard = Heard()
        roster = CentralRoster("127.0.0.1", fl.port, timeout=5)
        roster.start(heard)
        try:
            eventually(lambda: len(heard.of(RobotAdded)) == 2, timeout=10)
            fl.kill_central()
            eventually(lambda: heard.of(RosterLost) != [], timeout=10)
            assert heard.of(RosterLost)[0].retrying  # type: ignore[attr-defined]
            eventually(lambda: roster.attempts >= 2, timeout=10)  # it tries again…
            time.sleep(0.2)
            assert len(heard.of(RosterLost)) == 1 and heard.of(RosterRestored) == []  # …and says nothing more
            fl.restart_central()
            eventually(lambda: len(heard.of(RobotAdded)) == 4, timeout=30)  # the robots switched back
            lost_at = heard.events.index(heard.of(RosterLost)[0])
            after = heard.events[lost_at + 1 :]
            assert isinstance(after[0], RosterRestored) and len(heard.of(RosterRestored)) == 1
            again = {e.endpoint.name: e.endpoint for e in after if isinstance(e, RobotAdded)}
            assert sorted(again) == NAMES[:2] and {n: e.port for n, e in again.items()} == fl.robots()
            assert roster.robots == again
        finally:
            roster.close()


def test_a_roster_refused_its_login_does_not_try_again(tmp_path: Path) -> None:
    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser alice secret1 all\n")
    with CentralThread(robots=0, users_path=users) as fl:
        heard = Heard()
        roster = CentralRoster("127.0.0.1", fl.port, user="alice", password="nope", timeout=5)
        roster.start(heard)
        try:
            # It gives up at once (its thread ends by itself), so no wait past a retry's time can miss one.
            eventually(lambda: roster.given_up, timeout=30)
            assert len(heard.events) == 1 and isinstance(heard.events[0], RosterLost)
            assert not heard.events[0].retrying and roster.attempts == 1
        finally:
            roster.close()


def test_roster_that_cannot_reach_the_central_server_is_lost_once() -> None:
    heard = Heard()
    with CentralThread(robots=0) as fl:
        port = fl.port
    roster = CentralRoster("127.0.0.1", port, timeout=3)  # nobody listens there any more
    roster.start(heard)
    try:
        eventually(lambda: heard.events != [], timeout=10)
        time.sleep(0.2)
        assert len(heard.events) == 1 and isinstance(heard.events[0], RosterLost)
        assert "refused" in heard.events[0].reason  # type: ignore[union-attr]
    finally:
        roster.close()


def test_closed_roster_emits_nothing_more() -> None:
    with CentralThread(robots=1, template=SimConfig(port=0, camera=False)) as fl:
        heard = Heard()
        roster = CentralRoster("127.0.0.1", fl.port, timeout=5)
        roster.start(heard)
        eventually(lambda: len(heard.of(RobotAdded)) == 1, timeout=10)
        roster.close()
        count = len(heard.events)
        fl.add_robot("late")
        fl.wait_for_robots(2)
        fl.kill_central()
        time.sleep(0.5)
        assert len(heard.events) == count


def test_roster_posts_through_the_given_post() -> None:
    posted: list[str] = []
    heard = Heard()

    def post(fn, *args):  # type: ignore[no-untyped-def]
        posted.append(threading.current_thread().name)
        fn(*args)

    with CentralThread(robots=1, template=SimConfig(port=0, camera=False)) as fl:
        roster = CentralRoster("127.0.0.1", fl.port, post=post, timeout=5)
        roster.start(heard)
        try:
            eventually(lambda: len(heard.of(RobotAdded)) == 1, timeout=10)
        finally:
            roster.close()
    assert posted and set(posted) == {"rtmu-central"}


def test_robot_switching_again_under_its_name_replaces_the_old_connection() -> None:
    # The replaced robot would switch back after its retry (as in ARIA): not within this test.
    with CentralThread(robots=1, template=SimConfig(port=0, camera=False), switch_retry=60) as fl:
        old_port = fl.robots()["robot1"]
        twin: SimServer = fl.add_robot("ROBOT1")  # ARIA compares names case-insensitively
        eventually(lambda: fl.robots().get("ROBOT1", old_port) != old_port, timeout=10)
        assert list(fl.robots()) == ["ROBOT1"]
        assert twin.port


def test_every_connecting_subcommand_takes_robot() -> None:
    import argparse

    from rtmu.cli import build_parser

    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    connecting = {name: p for name, p in sub.choices.items() if any(a.dest == "server" for a in p._actions)}
    assert {"status", "drive", "map", "probe", "fleet", "goto", "record"} <= set(connecting)
    for name, p in connecting.items():  # but fleet, which lists every robot of the central server
        assert any("--robot" in a.option_strings for a in p._actions) == (name != "fleet"), name


def test_a_robot_started_with_switch_to_on_the_command_line_joins_the_fleet(
    capsys: pytest.CaptureFixture[str],
) -> None:
    import subprocess
    import sys

    with CentralThread(robots=0) as fl:
        robot_port = fl.central.robot_port  # type: ignore[union-attr]
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "rtmu",
                "sim",
                "--port",
                "0",
                "--no-camera",
                "--switch-to",
                f"127.0.0.1:{robot_port}",
                "--name",
                "cli-bot",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            assert fl.wait_for_robots(1, timeout=30) == {"cli-bot": fl.robots()["cli-bot"]}
            assert (
                main(["status", addr(fl), "--robot", "cli-bot", "--once", "--timeout", cli_timeout(5)])
                == EXIT_OK
            )
            assert "battery=" in capsys.readouterr().out
        finally:
            proc.terminate()
            proc.wait(15)
        fl.wait_for_robots(0, timeout=10)  # its SHUTDOWN on the way out unlists it


def test_a_drive_through_a_central_server_that_dies_ends_and_the_robot_stops() -> None:
    import subprocess
    import sys

    with CentralThread(robots=2, template=SimConfig(port=0, camera=False)) as fl:
        robot = fl.sims["robot1"].robot
        other = fl.sims["robot2"].robot
        argv = [
            "drive",
            addr(fl),
            "--robot",
            "robot1",
            "--trans",
            "60",
            "--seconds",
            "30",
            "--timeout",
            cli_timeout(5),
        ]
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        try:
            eventually(lambda: fl.call(lambda: robot.trans_ratio) == 60, timeout=30)
            fl.kill_central()  # operator and robot links reset at once: nobody can send a stop now
            assert proc.wait(15) != 0
            # The robot's own ratio-drive watchdog (2 s) stops it: no link means no more ratioDrive.
            eventually(lambda: fl.call(lambda: (robot.trans_ratio, robot.vel)) == (0, 0), timeout=10)
            assert fl.call(lambda: other.ratio_drives_received) == 0  # the other robot never drove
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_robot_behind_a_guarded_central_server_logs_in_to_both_with_one_password(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import io

    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser alice secret1 all\n")
    with CentralThread(robots=1, template=SimConfig(port=0, camera=False), users_path=users) as fl:
        # The password comes from stdin once (--password-stdin): the central server and the forwarded
        # robot both get it, and it is never asked for twice.
        monkeypatch.setattr("sys.stdin", io.StringIO("secret1\n"))
        argv = [
            "status",
            addr(fl),
            "--robot",
            "robot1",
            "--user",
            "alice",
            "--password-stdin",
            "--once",
            "--json",
            "--timeout",
            "5",
        ]
        assert main(argv) == EXIT_OK
        assert "battery_v" in json.loads(capsys.readouterr().out)
        monkeypatch.setattr("sys.stdin", io.StringIO("wrong\n"))
        assert main(argv) == EXIT_CONNECTION
        assert "central server" in capsys.readouterr().err


def test_image_with_robot_comes_through_the_forwarder_as_return_video(
    fleet: CentralThread, tmp_path: Path
) -> None:
    fleet.add_robot("cam", camera=True)
    try:
        fleet.wait_for_robots(4)
        out = tmp_path / "cam.jpg"
        assert (
            main(["image", addr(fleet), "--robot", "cam", "--out", str(out), "--timeout", cli_timeout(10)])
            == EXIT_OK
        )
        assert out.read_bytes()[:2] == b"\xff\xd8"
    finally:
        fleet.stop_robot("cam")  # the module's fleet is three robots again for whoever comes next
        fleet.wait_for_robots(3)
