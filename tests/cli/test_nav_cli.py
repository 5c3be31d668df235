"""``rtmu goals / goto / home / dock / localize`` against the navigating simulator, over loopback.

Exit codes and progress lines, an unknown goal, a server without navigation, LD robots' gotoRouteGoal
where gotoGoal is not listed, and Ctrl-C: the stop goes out before the command ends.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import pytest

from client.navsim import OFFICE, fast_sim, reset, robot
from client.servers import SPECS, ServerThread, TestServer
from client.uiqueue import eventually
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_TIMEOUT, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.protocol.payloads.robot import ModeInfo
from rtmu.sim import SimThread
from rtmu.sim.ld_data import ld_state
from rtmu.sim.profiles import PROFILES, SimProfile
from rtmu.subcommands._nav_args import EXIT_NAV_CANCELLED, EXIT_NAV_FAILED, EXIT_NAV_LOST
from simulators import running


@pytest.fixture(scope="module")
def sim() -> Iterator[SimThread]:
    with fast_sim() as s:
        yield s


@pytest.fixture
def home(sim: SimThread) -> SimThread:
    reset(sim)
    eventually(lambda: robot(sim).status == "Stopped", timeout=5)
    return sim


def addr(sim: SimThread | TestServer) -> str:
    return f"127.0.0.1:{sim.port}"


def run(sim: SimThread, *argv: str) -> int:
    return main([argv[0], addr(sim), *argv[1:], "--timeout", cli_timeout(5), "--limit", "60"])


def test_goals_lists_the_maps_goals(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["goals", addr(sim), "--timeout", cli_timeout(5)]) == EXIT_OK
    names = capsys.readouterr().out.splitlines()
    assert {"Room 101", "Lab B", "Kitchen", "Corridor End"} <= set(names)
    assert main(["goals", addr(sim), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == names


def test_goto_a_goal_arrives_and_exits_0(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(home, "goto", "Room 101") == EXIT_OK
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "Going to Room 101" and out[-1] == "Arrived at Room 101"
    snap = robot(home)
    assert abs(snap.x - 2000) <= 250 and abs(snap.y - 3200) <= 250


def test_goto_a_pose_with_json(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(home, "goto", "--x", "4000", "--y", "6000", "--th", "90", "--json") == EXIT_OK
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0] == {"status": "Going to point", "phase": "going"}
    last = lines[-1]
    assert last["outcome"] == "arrived" and last["text"] == "Arrived at point"
    assert abs(last["x"] - 4000) <= 250 and abs(last["y"] - 6000) <= 250
    assert abs(robot(home).th - 90) <= 3


def test_an_unknown_goal_is_a_usage_error(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(home, "goto", "Nowhere") == EXIT_USAGE
    err = capsys.readouterr().err
    assert "no goal 'Nowhere'" in err and "Room 101" in err
    assert robot(home).mode_name == "stop"  # nothing was sent


def test_an_unreachable_point_fails_with_the_servers_words(
    home: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert run(home, "goto", "--x", "17000", "--y", "9500") == EXIT_NAV_FAILED  # the forbidden server room
    assert "Failed to plan to point" in capsys.readouterr().err
    # The same again: the server repeats its words; they are still the answer, not a hang.
    assert run(home, "goto", "--x", "17000", "--y", "9500") == EXIT_NAV_FAILED


def test_a_lost_robot_exits_8_until_localized(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert home.server is not None
    home.call(home.server.lose_localization)
    assert run(home, "goto", "Room 101") == EXIT_NAV_LOST
    assert "Failed to get to Room 101 because the robot is lost" in capsys.readouterr().err
    assert run(home, "localize", "2500", "6000", "0") == EXIT_OK
    assert capsys.readouterr().out.splitlines()[-1].startswith("localized (score 0.9")
    snap = robot(home)
    assert (round(snap.x), round(snap.y)) == (2500, 6000)
    assert run(home, "home") == EXIT_OK
    assert capsys.readouterr().out.splitlines()[-1] == "Returned home"


def test_dock_exits_0_when_docked(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(home, "dock", "--json") == EXIT_OK
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0]["status"] == "Going to dock at Charger"
    assert lines[-1]["outcome"] == "docked"
    assert robot(home).status == "Docked"
    assert run(home, "dock") == EXIT_OK  # already docked: the server's "Docked" answers at once


def test_another_client_stopping_the_robot_exits_7(home: SimThread) -> None:
    assert home.server is not None
    server = home.server

    missed: list[BaseException] = []

    def stop_later() -> None:
        try:  # generous: on a busy machine the fast-clock simulator plans late
            eventually(lambda: robot(home).status == "Going to Corridor End", timeout=30)
        except AssertionError as exc:
            missed.append(exc)  # said below, not lost in the thread
        home.call(server.world.stop)

    stopper = threading.Thread(target=stop_later)
    stopper.start()
    try:
        code = run(home, "goto", "Corridor End")
    finally:
        stopper.join(35)
    assert not missed, "the robot never said it was going to Corridor End"
    assert code == EXIT_NAV_CANCELLED


def test_limit_stops_the_robot_and_exits_5(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["goto", addr(home), "Corridor End", "--timeout", cli_timeout(5), "--limit", "0.5"])
    assert code == EXIT_TIMEOUT
    assert "stop sent" in capsys.readouterr().err
    eventually(lambda: robot(home).mode_name == "stop", timeout=5)


def test_no_wait_sends_and_leaves_it_driving(home: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(home, "goto", "Lab B", "--no-wait") == EXIT_OK
    assert capsys.readouterr().out == "sent gotoGoal\n"
    # Under load the fast clock runs slower and the long plan takes longer: generous waits.
    eventually(lambda: robot(home).status == "Going to Lab B", timeout=15)
    eventually(lambda: robot(home).vel > 100 or robot(home).status != "Going to Lab B", timeout=20)
    assert robot(home).status == "Going to Lab B", robot(home).status


def test_ctrl_c_sends_stop_before_exiting(home: SimThread) -> None:
    args = [sys.executable, "-m", "rtmu", "goto", addr(home), "Corridor End", "--timeout", cli_timeout(5)]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, process_group=0)
    try:
        assert proc.stdout is not None and proc.stdout.readline() == "Going to Corridor End\n"
        eventually(lambda: robot(home).vel > 100, timeout=10)
        proc.send_signal(signal.SIGINT)
        assert proc.wait(10) == 128 + signal.SIGINT
        err = proc.stderr.read()  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert err == "rtmu goto: interrupted by SIGINT; the robot was stopped\n"
    snap = robot(home)
    assert snap.mode_name == "stop" and snap.status in ("Stopping", "Stopped")
    eventually(lambda: robot(home).vel == 0, timeout=10)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_stop_the_robot_too(home: SimThread, sig: signal.Signals) -> None:
    args = [sys.executable, "-m", "rtmu", "home", addr(home), "--timeout", cli_timeout(5)]
    assert home.server is not None
    home.call(lambda: home.server.world.goto_mode.goto_point(8000, 6000, None))  # type: ignore[union-attr]
    eventually(lambda: robot(home).status == "Arrived at point", timeout=20)
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, process_group=0)
    try:
        assert proc.stdout is not None and proc.stdout.readline() == "Returning home\n"
        proc.send_signal(sig)
        assert proc.wait(10) == 128 + sig
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert robot(home).mode_name == "stop"


def test_a_server_without_navigation_exits_4(capsys: pytest.CaptureFixture[str]) -> None:
    with ServerThread(TestServer()) as server:
        for argv in (
            ["goals"],
            ["goto", "Lab A"],
            ["goto", "--x", "1", "--y", "2"],
            ["home"],
            ["dock"],
            ["localize", "1", "2", "3"],
        ):
            assert (
                main([argv[0], addr(server), *argv[1:], "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
            ), argv
        err = capsys.readouterr().err
        assert "this server does not drive to goals (it does not offer gotoGoal)" in err
        assert "rtmu home: this server does not drive home (it does not offer home)" in err
        assert not {"gotoGoal", "gotoPose", "home", "dock", "localizeToPose"} & set(server.names())


def test_usage_errors() -> None:
    assert main(["goto", "127.0.0.1:1", "--x", "1"]) == EXIT_USAGE
    assert main(["goto", "127.0.0.1:1", "Lab A", "--x", "1", "--y", "2"]) == EXIT_USAGE
    assert main(["goto", "127.0.0.1:1"]) == EXIT_USAGE


@pytest.fixture(scope="module")
def ld_only() -> Iterator[SimThread]:
    """An LD robot that lists gotoRouteGoal but not ARNL's gotoGoal."""
    PROFILES["ld-only"] = SimProfile("ld-only", "LD data without ARNL's", modules=("rtmu.sim.ld_data",))
    try:
        with running(profile="ld-only", map_path=OFFICE) as s:
            yield s
    finally:
        del PROFILES["ld-only"]


def test_ld_robots_without_goto_goal_get_goto_route_goal(
    ld_only: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert ld_only.server is not None
    server = ld_only.server
    assert main(["goto", addr(ld_only), "Lab A", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert capsys.readouterr().err == "going to Lab A\n"
    eventually(lambda: ld_only.call(lambda: ld_state(server).route_goals) == ["Lab A"])  # type: ignore[arg-type]
    assert (
        main(["goto", addr(ld_only), "--x", "1", "--y", "2", "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
    )


def test_hostile_status_text_is_escaped_and_bounded(capsys: pytest.CaptureFixture[str]) -> None:
    specs = [*SPECS, ("gotoPose", "point", "byte4 byte4 byte4", "none", "Navigation", "RETURN_NONE")]
    server_obj = TestServer(specs)

    def on_once(side: object, name: str, args: bytes) -> None:
        if name == "gotoPose":
            server_obj.strings = ("Going to point\x1b[2J", "Goto point", "")

    server_obj.on_once = on_once  # type: ignore[assignment]
    with ServerThread(server_obj) as server:
        server.handlers["getModeInfo"] = lambda side, args: [ModeInfo("Goto").encode()]

        def fail_later() -> None:
            eventually(lambda: server.strings[0].startswith("Going"), timeout=5)
            time.sleep(0.5)
            failed = "Failed to get to point because \x1b]0;pwned\x07" + "x" * 5000
            server.strings = (failed, "Goto point", "")

        thread = threading.Thread(target=fail_later)
        thread.start()
        try:
            code = main(
                ["goto", addr(server), "--x", "1", "--y", "2", "--timeout", cli_timeout(5), "--limit", "20"]
            )
        finally:
            thread.join(10)
    assert code == EXIT_NAV_FAILED
    out, err = capsys.readouterr()
    assert "\x1b" not in out + err and "\x07" not in out + err
    assert out.splitlines()[0] == "Going to point\\x1b[2J"
    assert err.startswith("rtmu goto: Failed to get to point because \\x1b]0;pwned\\x07xxx")
    assert len(err) < 400  # the server's words are cut, not copied whole


def test_an_ld_robots_dock_is_followed_through_dock_info(capsys: pytest.CaptureFixture[str]) -> None:
    with fast_sim(profile="aram") as aram:
        assert main(["dock", addr(aram), "--timeout", cli_timeout(5), "--limit", "60"]) == EXIT_OK
        lines = capsys.readouterr().out.splitlines()  # it drives there, as the server says, to Docked
        assert lines[0] == "Going to dock at Charger" and lines[-1] == "Docked", lines
