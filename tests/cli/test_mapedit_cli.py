"""``rtmu mapedit`` against the simulator and against servers that refuse, lie, stall or hold 10⁵ objects.

Exit codes as documented: 0 the server's map holds the change (read again to be sure), 2 an edit that
does not fit the map, 4 not offered, 5 no verdict in time, 6 refused, 7 "applied" but not in the map.
"""

from __future__ import annotations

import asyncio
import json

import pytest

from client.servers import MAP_LINES, SPECS, ServerSide, ServerThread, TestServer
from client.uiqueue import UiQueue
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_TIMEOUT, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.runner import ClientRunner
from rtmu.mapfile import MapObject
from rtmu.model.observables import RobotModel
from rtmu.package_data import project_map
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.map import MapId
from rtmu.protocol.payloads.mapchange import (
    ChangeCommand,
    ChangeData,
    LineChange,
    MapChangePacket,
    MapChangeReply,
)
from rtmu.protocol.payloads.server import IdleProcessingPending
from rtmu.sim import SimThread
from rtmu.subcommands.mapedit import EXIT_NOT_HELD, EXIT_REFUSED
from rtmu.values.target import Target
from simulators import simulator

sim = simulator(map_path=project_map("arena.map"))


def addr(port: int) -> str:
    return f"127.0.0.1:{port}"


def mapedit(port: int, *edits: str, timeout: float = 10.0) -> int:
    return main(["mapedit", addr(port), "--timeout", str(timeout), *edits])


def test_one_change_set_of_every_kind_is_applied_and_read_back(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    code = mapedit(
        sim.port,
        "--add-goal", "Lab", "--x", "1000", "--y", "2000", "--th", "45",
        "--add-dock", "Second dock", "--x", "-500", "--th", "180", "--y", "1500",
        "--add-forbidden-line", "0", "-1000", "3000", "-1000",
        "--add-forbidden-area", "3000", "1000", "3500", "1800",
        "--remove", "Goal",
    )  # fmt: skip
    out = capsys.readouterr()
    assert code == EXIT_OK, out.err
    assert out.out.splitlines() == [
        'removed goal "Goal"',
        'added goal "Lab"',
        'added dock "Second dock"',
        "added forbidden line (0, -1000)–(3000, -1000)",
        "added forbidden area (3000, 1000)–(3500, 1800)",
    ]
    served = sim.server.map  # type: ignore[union-attr]
    assert MapObject("GoalWithHeading", 1000, 2000, 45, name="Lab") in served.objects
    assert MapObject("Dock", -500, 1500, 180, name="Second dock") in served.objects
    assert "Goal" not in served.goals


def test_json_says_what_was_sent_and_that_the_map_holds_it(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert mapedit(sim.port, "--json", "--add-goal", "Porch", "--x", "1", "--y", "2") == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc == {
        "removed": [],
        "added": ['goal "Porch"'],
        "applied": True,
        "status": 10,
        "words": "the server applied the change",
        "map_updated": True,
        "holds": True,
        "missing": [],
    }


def test_a_change_by_one_client_is_seen_by_another_clients_session(sim: SimThread) -> None:
    model, ui = RobotModel(), UiQueue()
    with ClientRunner(model, post=ui.post) as runner:
        runner.connect(Target("127.0.0.1", sim.port)).result(10)
        ui.wait_for(lambda: model.map.value.data is not None, 15)
        first = model.map.value.generation
        assert mapedit(sim.port, "--add-goal", "Seen", "--x", "1200", "--y", "-800") == EXIT_OK

        def seen() -> bool:
            m = model.map.value
            return (
                m.generation > first and m.data is not None and any(o.name == "Seen" for o in m.data.objects)
            )

        ui.wait_for(seen, 15)


@pytest.mark.parametrize(
    ("edits", "why"),
    [
        (("--remove", "Nope"), 'no goal or dock named "Nope"'),
        (("--add-goal", "Goal", "--x", "0", "--y", "0"), 'already has goal "Goal"'),
        (("--add-goal", "Lab", "--x", "0"), "needs --y"),
        (("--add-dock", "D", "--x", "0", "--y", "0"), "needs --th"),
    ],
)
def test_edits_that_do_not_fit_the_map_send_nothing(
    sim: SimThread, capsys: pytest.CaptureFixture[str], edits: tuple[str, ...], why: str
) -> None:
    before = sim.server.map.md5  # type: ignore[union-attr]
    assert mapedit(sim.port, *edits) == EXIT_USAGE
    assert why in capsys.readouterr().err
    assert sim.server.map.md5 == before  # type: ignore[union-attr]


@pytest.mark.parametrize(
    "argv",
    [
        ["--x", "1"],
        ["--add-goal", "A", "--x", "1", "--x", "2"],
        ["--add-forbidden-line", "0", "0", "nan", "1"],
        ["--add-forbidden-area", "0", "0", "1"],
        ["--check-map", "--remove", "A"],
        [],
    ],
)
def test_bad_arguments_are_usage_errors(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    try:
        code = main(["mapedit", "127.0.0.1:1", *argv])
    except SystemExit as exc:
        code = int(exc.code or 0)
    assert code == EXIT_USAGE
    assert capsys.readouterr().err


def test_check_map_says_whether_the_file_had_changed(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["mapedit", addr(sim.port), "--check-map", "--timeout", "1", "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == {"map_updated": False}


# -- servers that are not the simulator ------------------------------------------------------------------

CHANGE_SPECS = [
    *SPECS,
    ("getMapId", "map id", "none", "id", "Map", "RETURN_SINGLE"),
    ("goalsUpdated", "goals changed", "none", "none", "Map", "RETURN_SINGLE"),
    ("processMapChanges", "changes", "TODO", "TODO", "Map", "RETURN_SINGLE|IDLE_PACKET"),
    ("mapChangesInProgress", "in progress", "TODO", "TODO", "Map", "RETURN_NONE"),
    ("idleProcessingPending", "idle", "none", "byte", "RobotInfo", "RETURN_SINGLE"),
]
OBJECT_LINES = ['Cairn: Goal 1000 500 0.000000 "" ICON "Kitchen"']


def change_server(objects: list[str], on_finish, *, listed: bool = True) -> TestServer:
    """A server whose map holds ``objects``; ``on_finish(server, side)`` answers a change set's finish."""
    head = MAP_LINES[: MAP_LINES.index("LINES")]
    server = TestServer(
        CHANGE_SPECS if listed else SPECS, map_lines=[*head, *objects, *MAP_LINES[len(head) :]]
    )
    server.handlers["getMapId"] = lambda s, a: [MapId("", "test.map", b"\x01" * 16, 99, 5).encode()]
    server.handlers["idleProcessingPending"] = lambda s, a: [IdleProcessingPending(False).encode()]

    def process(side: ServerSide, args: bytes) -> list[bytes] | None:
        packet = MapChangePacket.decode(args)
        if packet.command is ChangeCommand.FINISH:
            return on_finish(server, side)
        if packet.command is ChangeCommand.CONTINUE and packet.data is ChangeData.OBJECTS:
            server.pending.append((packet.change, packet.groups))  # type: ignore[attr-defined]
        return None

    server.handlers["processMapChanges"] = process
    server.pending = []  # type: ignore[attr-defined]
    return server


def honest(server: TestServer, side: ServerSide) -> list[bytes]:
    lines = server.map_lines
    for change, groups in server.pending:  # type: ignore[attr-defined]
        for g in groups:
            text = g.parent.text
            if change is LineChange.DELETIONS:
                name = text.rsplit('"', 2)[-2]
                lines[:] = [x for x in lines if not (x.startswith("Cairn:") and x.endswith(f'"{name}"'))]
            else:
                lines.insert(lines.index("LINES"), text)
    server.pending.clear()  # type: ignore[attr-defined]
    server.broadcast("mapUpdated")
    server.broadcast("goalsUpdated")
    return [MapChangeReply(10).encode()]


def run_mapedit(server: TestServer, *argv: str, timeout: float = 5.0) -> int:
    with ServerThread(server) as running:
        return main(["mapedit", addr(running.port), "--timeout", str(timeout), *argv])


def test_a_refusal_is_exit_6_with_the_servers_words(capsys: pytest.CaptureFixture[str]) -> None:
    server = change_server(OBJECT_LINES, lambda s, side: [MapChangeReply(0).encode()])
    assert run_mapedit(server, "--remove", "Kitchen") == EXIT_REFUSED
    err = capsys.readouterr().err
    assert "the server refused the change (processMapChanges answered 0 (refused)" in err
    assert [r.name for r in server.received].count("processMapChanges") == 3  # start, objects, finish


def test_a_status_that_is_neither_yes_nor_no_is_a_refusal_that_names_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    server = change_server(OBJECT_LINES, lambda s, side: [MapChangeReply(77).encode()])
    assert run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0") == EXIT_REFUSED
    assert "answered 77, which is neither 10 (applied) nor 0 (refused)" in capsys.readouterr().err


def test_a_server_that_says_applied_but_did_not_change_its_map_is_caught(
    capsys: pytest.CaptureFixture[str],
) -> None:
    def liar(server: TestServer, side: ServerSide) -> list[bytes]:
        server.broadcast("mapUpdated")
        return [MapChangeReply(10).encode()]

    server = change_server(OBJECT_LINES, liar)
    assert (
        run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0", "--remove", "Kitchen")
        == EXIT_NOT_HELD
    )
    err = capsys.readouterr().err
    assert 'goal "Lab" was not added' in err and 'goal "Kitchen" is still there' in err


def test_an_honest_server_with_a_hundred_thousand_objects(capsys: pytest.CaptureFixture[str]) -> None:
    many = [f'Cairn: Goal {i % 3000} {i // 3000} 0.000000 "" ICON "g{i}"' for i in range(100_000)]
    server = change_server(many, honest)
    code = run_mapedit(
        server, "--json", "--add-goal", "Lab", "--x", "5", "--y", "5", "--remove", "g99999", timeout=30
    )
    out = capsys.readouterr()
    assert code == EXIT_OK, out.err
    assert json.loads(out.out)["holds"] is True
    assert any(line.endswith('"Lab"') for line in server.map_lines)
    assert not any(line.endswith('"g99999"') for line in server.map_lines)


def test_a_malformed_verdict_is_a_protocol_failure(capsys: pytest.CaptureFixture[str]) -> None:
    server = change_server(OBJECT_LINES, lambda s, side: [b"\x0a"])
    assert run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0") == EXIT_CONNECTION
    assert "processMapChanges" in capsys.readouterr().err


def test_no_verdict_is_a_timeout_that_says_the_map_may_have_changed(
    capsys: pytest.CaptureFixture[str],
) -> None:
    server = change_server(OBJECT_LINES, lambda s, side: None)
    assert run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0", timeout=0.5) == EXIT_TIMEOUT
    assert "may or may not have changed" in capsys.readouterr().err


def test_the_wait_for_a_verdict_lasts_while_the_server_waits_for_the_robot_to_stand_still() -> None:
    def later(server: TestServer, side: ServerSide) -> None:
        server.broadcast("idleProcessingPending", IdleProcessingPending(True).encode())

        def answer() -> None:
            honest(server, side)
            side.conn.send_data("processMapChanges", MapChangeReply(10).encode())
            side.writer.write(side.conn.data_to_send())
            server.broadcast("idleProcessingPending", IdleProcessingPending(False).encode())

        asyncio.get_running_loop().call_later(2.0, answer)
        return None

    server = change_server(OBJECT_LINES, later)
    assert run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0", timeout=0.5) == EXIT_OK


def test_a_server_without_map_changes_is_exit_4(capsys: pytest.CaptureFixture[str]) -> None:
    server = change_server(OBJECT_LINES, honest, listed=False)
    assert run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0") == EXIT_UNSUPPORTED
    assert "takes no live map changes" in capsys.readouterr().err


def test_a_hostile_map_id_is_refused_before_anything_is_sent(capsys: pytest.CaptureFixture[str]) -> None:
    server = change_server(OBJECT_LINES, honest)
    server.handlers["getMapId"] = lambda s, a: [FieldWriter().string("").string("m").ubyte4(1 << 30).bytes()]
    assert run_mapedit(server, "--add-goal", "Lab", "--x", "0", "--y", "0") == EXIT_CONNECTION
    assert "processMapChanges" not in [r.name for r in server.received]
    assert capsys.readouterr().err
