"""``rtmu why`` / ``rtmu drive`` / ``rtmu doctor`` against the simulator put in each state, over loopback.

Each test starts a simulator of its own (they start in milliseconds), puts it in one state through
the simulator's own simple commands (``rtmu run``) or a ``--users`` file, and checks that the cause
and its fix are named, that the fix works where there is one, that nothing is acknowledged,
enabled or made unsafe without a yes, and that a drive that did not move never exits 0.
"""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

import jsonschema
import pytest

from client.navsim import fast_sim, reset, robot
from client.servers import SPECS, ServerThread, TestServer
from client.uiqueue import eventually
from patience import cli_timeout
from rtmu.base import exit_codes as codes
from rtmu.cli import main
from rtmu.client.connection import AriaClient
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.ld_safety import safety_state
from rtmu.subcommands.json_schemas import SCHEMAS
from rtmu.values.target import Target
from simulators import simulator

USERS = """UserInfoVersion1
user alice secret1 all
user bob pw RobotInfo SensorInfo Stop
user carol pw RobotInfo SensorInfo Movement
user viewer pw RobotInfo SensorInfo
"""


sim = simulator()


@pytest.fixture
def users(tmp_path: Path) -> Path:
    path = tmp_path / "users"
    path.write_text(USERS)
    return path


def addr(server: SimThread | TestServer) -> str:
    return f"127.0.0.1:{server.port}"


def why(server: SimThread | TestServer, *extra: str) -> int:
    return main(["why", addr(server), "--timeout", cli_timeout(5), *extra])


def why_json(server: SimThread, capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[int, dict]:
    code = why(server, "--json", *extra)
    return code, json.loads(capsys.readouterr().out)


def command(server: SimThread, name: str, *arg: str) -> None:
    assert main(["run", addr(server), name, *arg, "--timeout", cli_timeout(5)]) == codes.EXIT_OK


def drive(server: SimThread | TestServer, *extra: str) -> int:
    return main(["drive", addr(server), "--timeout", cli_timeout(5), "--seconds", "0.6", *extra])


def x_of(sim: SimThread) -> float:
    return robot(sim).x


def login(user: str, tmp_path: Path) -> list[str]:
    pw = tmp_path / f"{user}.pw"
    pw.write_text("secret1\n" if user == "alice" else "pw\n")
    return ["--user", user, "--password-file", str(pw)]


def zero_drive(sim: SimThread) -> None:
    """A zero ratioDrive over the wire: the drive mode takes over, the robot stays still."""

    async def go() -> None:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", sim.port), timeout=5)
        try:
            client.send(RatioDrive(0.0, 0.0, 0.0))
            await client.flush()
        finally:
            await client.disconnect()

    asyncio.run(go())
    eventually(lambda: robot(sim).mode_name == "ratioDrive", timeout=5)


# -- nothing wrong --------------------------------------------------------------------------------
def test_a_free_robot_can_move_and_a_drive_says_it_moved(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    code, answer = why_json(sim, capsys)
    assert code == codes.EXIT_OK and answer["can_move"] is True and answer["reasons"] == []
    # 1.5 s rather than 0.6: on a busy machine the robot's first metres may come late (x stayed 0 in 0.6 s).
    assert drive(sim, "--trans", "50", "--json", "--seconds", "1.5") == codes.EXIT_OK
    assert json.loads(capsys.readouterr().out)["moved"] is True


# -- the mode lock ------------------------------------------------------------------------------------
def test_a_mode_locked_for_good_is_named_and_a_drive_against_it_exits_27(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    command(sim, "SimulatorLockStopMode")
    capsys.readouterr()
    code, answer = why_json(sim, capsys)
    assert code == codes.EXIT_WHY_LOCKED == 27
    (reason,) = answer["reasons"]
    assert "'stop' mode" in reason["problem"] and "will not unlock" in reason["problem"]
    assert "RTMU cannot release it" in reason["advice"] and "fix" not in reason
    assert why(sim, "--fix") == codes.EXIT_WHY_LOCKED  # no fix to try: still locked
    x0 = x_of(sim)
    assert drive(sim, "--trans", "50", "--json") == codes.EXIT_WHY_LOCKED
    out, err = capsys.readouterr()
    assert "the robot did not move" in err and "will not unlock" in err
    assert abs(x_of(sim) - x0) < 1.0
    line = json.loads(out.splitlines()[-1])  # after what why --fix printed
    jsonschema.validate(line, SCHEMAS["drive"])  # the published shape, "moved" and "why" included
    assert line["moved"] is False and line["why"]["exit_code"] == codes.EXIT_WHY_LOCKED


def test_a_lock_that_gives_way_is_unlocked_by_the_fix_without_moving(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    command(sim, "SimulatorLockStopModeUnlockable")
    capsys.readouterr()
    code, answer = why_json(sim, capsys)
    assert code == codes.EXIT_WHY_LOCKED and answer["reasons"][0]["fix"]["key"] == "unlock"
    x0 = x_of(sim)
    code, answer = why_json(sim, capsys, "--fix")
    assert code == codes.EXIT_OK and answer["fixes"] == [
        {"key": "unlock", "sent": True, "worked": True, "message": "sent ratioDrive: done"}
    ]
    assert sim.call(lambda: sim.server.world.mode_info())[1] is False  # type: ignore[union-attr]
    assert abs(x_of(sim) - x0) < 1.0  # asking to unlock never moves the robot
    assert drive(sim, "--trans", "50") == codes.EXIT_OK


# -- who may drive and stop -------------------------------------------------------------------------
def test_a_user_without_movement_may_not_drive(users: Path, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    with SimThread(SimConfig(port=0, users_path=users)) as s:
        assert why(s, *login("bob", tmp_path)) == codes.EXIT_WHY_NO_DRIVE == 21
        out = capsys.readouterr().out
        assert "user 'bob' may not drive" in out and "Movement" in out and "WARNING" not in out
        assert drive(s, "--trans", "50", *login("bob", tmp_path)) == codes.EXIT_WHY_NO_DRIVE
        assert "no ratioDrive" in capsys.readouterr().err


def test_a_user_without_stop_is_warned_loudly(users: Path, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    with SimThread(SimConfig(port=0, users_path=users)) as s:
        assert why(s, *login("carol", tmp_path)) == codes.EXIT_WHY_NO_STOP == 20
        assert "SAFETY" in capsys.readouterr().out
        assert drive(s, "--trans", "50", *login("carol", tmp_path)) == codes.EXIT_OK  # it can drive…
        assert "WARNING: SAFETY" in capsys.readouterr().err  # …but is told it cannot stop


def test_a_viewer_may_neither_drive_nor_stop(users: Path, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    with SimThread(SimConfig(port=0, users_path=users)) as s:
        code, answer = why_json(s, capsys, *login("viewer", tmp_path))
        assert code == codes.EXIT_WHY_NO_DRIVE
        assert [r["cause"] for r in answer["reasons"]] == ["no_drive", "no_stop"]
        assert "may neither drive nor stop" in answer["sentence"] and answer["reasons"][1]["loud"]
        assert drive(s, "--trans", "50", *login("viewer", tmp_path)) == codes.EXIT_WHY_NO_DRIVE
        err = capsys.readouterr().err
        assert "neither drive nor stop" in err and "WARNING: SAFETY" in err


# -- the robot's own state ------------------------------------------------------------------------------
def test_stalled_motors_are_named_and_the_drive_exits_26(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    command(sim, "SimulatorStallMotors")
    x0 = x_of(sim)
    assert drive(sim, "--trans", "50") == codes.EXIT_WHY_STALLED == 26
    assert '"Stalled"' in capsys.readouterr().err and abs(x_of(sim) - x0) < 1.0
    zero_drive(sim)  # in the drive mode the status says Stalled, as ARIA's does
    assert why(sim) == codes.EXIT_WHY_STALLED
    command(sim, "SimulatorClearStall")
    # The server says so on its next cycle (as ARIA's does on its next robot task cycle): ask then.
    eventually(lambda: sim.call(lambda: sim.server.world.mode.status) != "Stalled", timeout=10)  # type: ignore[union-attr]
    assert why(sim) == codes.EXIT_OK


def test_estop_then_motors_off_then_free(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    command(sim, "SimulatorEStop")
    x0 = x_of(sim)
    assert why(sim) == codes.EXIT_WHY_ESTOP == 23
    assert "e-stop is pressed" in capsys.readouterr().out
    assert drive(sim, "--trans", "50") == codes.EXIT_WHY_ESTOP and abs(x_of(sim) - x0) < 1.0
    command(sim, "SimulatorEStopRelease")
    assert why(sim) == codes.EXIT_WHY_MOTORS == 25
    command(sim, "SimulatorMotorsOn")
    assert why(sim) == codes.EXIT_OK


def test_a_battery_below_shutdown(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    command(sim, "SimulatorSetBattery", "10.5")
    assert why(sim) == codes.EXIT_WHY_BATTERY == 30
    assert "shutdown level (11 V)" in capsys.readouterr().out


def test_a_drive_watchdog_shorter_than_our_resend(capsys) -> None:  # type: ignore[no-untyped-def]
    with SimThread(SimConfig(port=0, drive_timeout=0.05)) as s:
        code, answer = why_json(s, capsys)
    assert code == codes.EXIT_WHY_WATCHDOG == 32
    assert "0.05 s" in answer["sentence"] and "Timeout" in answer["reasons"][0]["advice"]


# -- every state the simple commands make: the text, --json and a drive agree ---------------------------
STATES = [
    (("SimulatorEStop",), codes.EXIT_WHY_ESTOP, "estop", "e-stop is pressed", "release the e-stop"),
    (("SimulatorMotorsOff",), codes.EXIT_WHY_MOTORS, "motors", "motors are disabled", "enable them"),
    (("SimulatorSetBattery", "10.5"), codes.EXIT_WHY_BATTERY, "battery", "shutdown level (11 V)", "charge"),
    (("SimulatorLockStopMode",), codes.EXIT_WHY_LOCKED, "locked", "will not unlock", "cannot release it"),
    (("SimulatorObstacleAhead",), codes.EXIT_WHY_SAFE_DRIVE, "safe_drive", "safe drive holds", "drive away"),
]


@pytest.mark.parametrize(("args", "code", "key", "problem", "advice"), STATES, ids=[s[2] for s in STATES])
def test_each_state_has_its_code_words_and_json_and_a_drive_against_it_never_exits_0(
    sim: SimThread, capsys, args: tuple[str, ...], code: int, key: str, problem: str, advice: str
) -> None:  # type: ignore[no-untyped-def]
    command(sim, *args)
    capsys.readouterr()
    assert why(sim) == code
    out = capsys.readouterr().out
    assert problem in out and advice in out, out
    got, answer = why_json(sim, capsys)
    jsonschema.validate(answer, SCHEMAS["why"])
    assert got == code and answer["exit_code"] == code and answer["cause"] == key
    assert answer["can_move"] is False and problem in answer["sentence"]
    x0 = x_of(sim)
    assert drive(sim, "--trans", "50", "--json") == code
    out, err = capsys.readouterr()
    line = json.loads(out.splitlines()[-1])
    assert line["moved"] is False and line["why"]["cause"] == key and problem in err
    assert abs(x_of(sim) - x0) < 10.0


# -- safe drive ---------------------------------------------------------------------------------------
def test_an_obstacle_inside_safe_drive_and_switching_it_off_needs_a_yes(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    command(sim, "SimulatorObstacleAhead")
    capsys.readouterr()
    code, answer = why_json(sim, capsys)
    assert code == codes.EXIT_WHY_SAFE_DRIVE == 31
    reason = answer["reasons"][0]
    assert "290 mm ahead of its centre (straight on)" in reason["problem"]
    assert "half the robot's length + 94 mm" in reason["problem"]
    assert "backwards: that way is clear" in reason["advice"] and reason["fix"]["confirm"] is True
    x0 = x_of(sim)
    assert drive(sim, "--trans", "50") == codes.EXIT_WHY_SAFE_DRIVE and abs(x_of(sim) - x0) < 1.0
    capsys.readouterr()
    assert drive(sim, "--trans", "-50") == codes.EXIT_OK and x_of(sim) < x0 - 10  # away from it: free
    command(sim, "SimulatorObstacleAhead")
    capsys.readouterr()
    code, answer = why_json(sim, capsys, "--fix")  # no terminal, no --yes: nothing sent
    assert code == codes.EXIT_WHY_SAFE_DRIVE and answer["fixes"][0]["sent"] is False
    assert robot(sim).safe_drive is True
    code, answer = why_json(sim, capsys, "--fix", "--yes")
    assert answer["fixes"][0] == {"key": "safe_drive_off", "sent": True, "worked": True,
                                  "message": "sent setSafeDrive: done"}  # fmt: skip
    assert robot(sim).safe_drive is False and code == codes.EXIT_OK


# -- the server's own driving -------------------------------------------------------------------------
def test_navigating_docked_and_lost_with_their_fixes(capsys) -> None:  # type: ignore[no-untyped-def]
    with fast_sim() as s:
        reset(s)
        eventually(lambda: robot(s).status == "Stopped", timeout=5)
        assert (
            main(["goto", addr(s), "Corridor End", "--no-wait", "--timeout", cli_timeout(5)]) == codes.EXIT_OK
        )
        eventually(lambda: robot(s).status.startswith("Going to"), timeout=10)
        capsys.readouterr()
        code, answer = why_json(s, capsys)
        assert code == codes.EXIT_WHY_NAVIGATING == 28 and "Corridor End" in answer["sentence"]
        code, answer = why_json(s, capsys, "--fix")
        assert answer["fixes"][0]["worked"] is True and code == codes.EXIT_OK
        assert robot(s).mode_name == "stop"

        assert main(["dock", addr(s), "--timeout", cli_timeout(5), "--limit", "60"]) == codes.EXIT_OK
        capsys.readouterr()
        code, answer = why_json(s, capsys)
        assert code == codes.EXIT_WHY_DOCKED == 29 and answer["reasons"][0]["fix"]["key"] == "undock"
        assert [r["cause"] for r in answer["reasons"]] == ["docked"]  # the dock's lock is the dock
        code, answer = why_json(s, capsys, "--fix")
        assert answer["fixes"][0]["worked"] is True and code == codes.EXIT_OK
        assert robot(s).status != "Docked"

        command(s, "SimulatorLoseLocalization")
        assert why(s) == codes.EXIT_OK  # driving by hand does not need localization…
        assert why(s, "--navigate") == codes.EXIT_WHY_LOST == 33  # …navigating does


# -- an Omron LD robot -------------------------------------------------------------------------------
def test_ld_faults_are_read_raw_and_acknowledged_only_with_a_yes(capsys) -> None:  # type: ignore[no-untyped-def]
    with SimThread(SimConfig(port=0, profile="aram", test_hooks=True)) as s:
        assert s.server is not None
        state = safety_state(s.server)
        command(s, "SimulatorFault")
        capsys.readouterr()
        code, answer = why_json(s, capsys)
        assert code == codes.EXIT_WHY_FAULTS == 24
        assert "Drive fault 1" in answer["sentence"] and answer["reasons"][0]["fix"]["confirm"] is True
        raw = {v["name"]: v for v in answer["raw"]}
        assert {"getFaults", "safetyStatusEStop", "queryMotors", "getBlockDriving"} <= set(raw)
        assert raw["getBlockDriving"]["fields"] == ["1"] and raw["getBlockDriving"]["hex"] == "01"
        x0 = x_of(s)
        assert drive(s, "--trans", "50") == codes.EXIT_WHY_FAULTS and abs(x_of(s) - x0) < 1.0
        capsys.readouterr()
        code, answer = why_json(s, capsys, "--fix")
        assert code == codes.EXIT_WHY_FAULTS and answer["fixes"][0]["sent"] is False
        assert state.acknowledged == []  # nothing acknowledged without a yes
        code, answer = why_json(s, capsys, "--fix", "--yes")
        assert state.acknowledged == ["Drive fault 1: simulated motor controller fault"]
        assert code == codes.EXIT_OK


def test_ld_motors_are_enabled_only_with_a_yes(capsys) -> None:  # type: ignore[no-untyped-def]
    with SimThread(SimConfig(port=0, profile="aram", test_hooks=True)) as s:
        assert s.server is not None
        state = safety_state(s.server)
        command(s, "SimulatorMotorsOff")
        capsys.readouterr()
        code, answer = why_json(s, capsys, "--fix")
        assert code == codes.EXIT_WHY_MOTORS and answer["reasons"][0]["fix"]["key"] == "enable_motors"
        assert state.enables == 0
        code, answer = why_json(s, capsys, "--fix", "--yes")
        assert state.enables == 1 and code == codes.EXIT_OK


# -- a drive nothing explains, and the doctor -----------------------------------------------------------
def test_a_drive_that_moves_nothing_and_nothing_explains_exits_39(capsys) -> None:  # type: ignore[no-untyped-def]
    with ServerThread(TestServer(SPECS)) as server:
        assert drive(server, "--trans", "50", "--json") == codes.EXIT_WHY_UNEXPLAINED == 39
    obj = json.loads(capsys.readouterr().out)
    assert obj["moved"] is False and obj["why"]["cause"] == "unexplained"


def test_the_doctor_asks_why_it_wont_move(sim: SimThread, capsys) -> None:  # type: ignore[no-untyped-def]
    assert main(["doctor", addr(sim), "--json", "--timeout", cli_timeout(5)]) == codes.EXIT_OK
    report = json.loads(capsys.readouterr().out)
    assert report["steps"][-1]["step"] == "motion" and report["steps"][-1]["result"] == "ok"
    command(sim, "SimulatorLockStopMode")
    capsys.readouterr()
    assert main(["doctor", addr(sim), "--json", "--timeout", cli_timeout(5)]) == codes.EXIT_WHY_LOCKED
    report = json.loads(capsys.readouterr().out)
    assert report["failed_step"] == "motion" and report["steps"][-1]["cause"] == "locked"


# -- a hostile server ------------------------------------------------------------------------------------
def test_a_hostile_servers_replies_are_bounded_and_never_crash_the_answer(capsys) -> None:  # type: ignore[no-untyped-def]
    rows = [
        *SPECS,
        ("getFaults", "faults", "none", "?", "Safety", "RETURN_SINGLE"),
        ("queryMotors", "motors", "none", "?", "Safety", "RETURN_SINGLE"),
        ("enableMotors", "enable", "byte4: secret", "none", "Safety", "RETURN_NONE"),
    ]
    server = TestServer(rows)
    server.strings = ("EStop pressed\x1b[2J", "Stop", "Motors disabled")
    server.handlers["getModeInfo"] = lambda side, args: [b"\x01"]  # no terminator: does not decode
    server.handlers["getFaults"] = lambda side, args: [b"F\x00" * 15_000]  # 15 000 "faults"
    server.handlers["queryMotors"] = lambda side, args: [b"\xff" * 30_000]
    with ServerThread(server) as s:
        assert why(s) == codes.EXIT_WHY_ESTOP
        out = capsys.readouterr().out
        assert "\x1b" not in out and "\\x1b[2J" in out  # the server's words, escaped
        assert "getModeInfo did not decode" in out
        code = why(s, "--json", "--fix", "--yes")
        answer = json.loads(capsys.readouterr().out)
        sent = [r.name for r in server.received]
    raw = {v["name"]: v for v in answer["raw"]}
    assert len(raw["getFaults"]["fields"]) == 64 and raw["queryMotors"]["fields"] == []
    assert raw["queryMotors"]["hex"].endswith("… (30000 bytes)") and len(raw["queryMotors"]["hex"]) < 1000
    assert code == codes.EXIT_WHY_ESTOP and "enableMotors" not in sent and "acknowledgeFault" not in sent
    assert "a layout RTMU cannot build" in answer["fixes"][0]["message"]  # byte4: secret — never guessed
