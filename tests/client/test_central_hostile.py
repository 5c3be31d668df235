"""A hostile central server: lying counts, floods of robots, markup and terminal escapes in names.

The server is the project's own ``ServerConnection`` on a real loopback socket (tests/client/servers.py)
listing ARIA's central-server data; only what it says is scripted.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.central import MAX_NAME, CentralRoster
from rtmu.client.roster import RobotAdded, RobotRemoved, RosterEvent, RosterLost
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.central import CentralEntry, ClientAdded, ClientList, ClientRemoved
from rtmu.sim.central import OPERATOR_DATA

from .servers import ServerThread, TestServer
from .uiqueue import eventually

SPECS = [
    (e.name, e.description, e.argument_description, e.return_description, e.command_group, e.flags)
    for e in OPERATOR_DATA
]
MARKUP = '<span foreground="red">evil</span> & <b>'
ESCAPES = "robot\x1b[2J\x1b]0;pwned\x07\r\n"


@pytest.fixture
def central() -> Iterator[tuple[TestServer, ServerThread]]:
    server = TestServer(SPECS)
    server.handlers["clientAdded"] = lambda s, a: None  # broadcasts only, no reply to the REQUEST
    server.handlers["clientRemoved"] = lambda s, a: None
    thread = ServerThread(server)
    with thread:
        yield server, thread


def listing(server: TestServer, payload: bytes) -> None:
    server.handlers["clientList"] = lambda s, a: [payload]


class Heard(list[RosterEvent]):
    def __init__(self) -> None:
        super().__init__()
        self.lock = threading.Lock()

    def __call__(self, event: RosterEvent) -> None:
        with self.lock:
            self.append(event)


def test_a_list_claiming_10000_robots_in_a_few_bytes_is_refused_with_a_clear_error(
    central: tuple[TestServer, ServerThread], capsys: pytest.CaptureFixture[str]
) -> None:
    server, _ = central
    one = CentralEntry("", 7273, "robot1", "", "10.0.0.1")
    lie = FieldWriter().ubyte2(10_000).bytes() + ClientList((one,)).encode()[2:]
    listing(server, lie)
    assert main(["fleet", f"127.0.0.1:{server.port}", "--timeout", cli_timeout(5)]) == EXIT_CONNECTION
    err = capsys.readouterr().err
    assert "malformed robot list" in err and "robot count claims 10000" in err

    heard = Heard()
    roster = CentralRoster("127.0.0.1", server.port, timeout=5)
    roster.start(heard)
    try:
        eventually(lambda: len(heard) > 0, timeout=10)
        assert len(heard) == 1 and isinstance(heard[0], RosterLost)
        assert "robot count claims 10000" in heard[0].reason
    finally:
        roster.close()


def test_a_flood_of_10000_added_robots_is_held_to_the_roster_bound(
    central: tuple[TestServer, ServerThread],
) -> None:
    server, thread = central
    listing(server, ClientList(()).encode())
    heard = Heard()
    roster = CentralRoster("127.0.0.1", server.port, timeout=5, max_robots=1000)
    roster.start(heard)
    try:
        eventually(lambda: bool(server.sides) and len(server.sides[0].conn.subscriptions) == 2, timeout=10)

        def flood() -> None:
            for i in range(10_000):
                server.broadcast(
                    "clientAdded", ClientAdded(CentralEntry("", 1 + i % 60000, f"r{i}")).encode()
                )

        thread.call(flood)
        eventually(lambda: roster.dropped == 9000, timeout=30)
        assert len(roster.robots) == 1000
        with heard.lock:
            added = [e for e in heard if isinstance(e, RobotAdded)]
        assert len(added) == 1000 and not any(isinstance(e, RosterLost) for e in heard)
    finally:
        roster.close()


def test_entries_no_robot_could_send_are_dropped_and_counted(
    central: tuple[TestServer, ServerThread],
) -> None:
    server, _ = central
    entries = (
        CentralEntry("", 0, "no-port"),
        CentralEntry("", 7000, ""),
        CentralEntry("", 7001, "x" * (MAX_NAME + 1)),
        CentralEntry("", 7002, "fine"),
    )
    listing(server, ClientList(entries).encode())
    heard = Heard()
    roster = CentralRoster("127.0.0.1", server.port, timeout=5)
    roster.start(heard)
    try:
        eventually(lambda: len(heard) >= 1, timeout=10)
        eventually(lambda: roster.dropped == 3, timeout=5)
        assert [e.endpoint.name for e in heard if isinstance(e, RobotAdded)] == ["fine"]
    finally:
        roster.close()


def test_markup_and_escapes_in_names_stay_plain_text_and_never_reach_the_terminal(
    central: tuple[TestServer, ServerThread], capsys: pytest.CaptureFixture[str]
) -> None:
    server, _ = central
    entries = (CentralEntry("", 7301, MARKUP), CentralEntry("", 7302, ESCAPES))
    listing(server, ClientList(entries).encode())

    heard = Heard()
    roster = CentralRoster("127.0.0.1", server.port, timeout=5)
    roster.start(heard)
    try:
        eventually(lambda: len(heard) == 2, timeout=10)
        assert [e.endpoint.name for e in heard if isinstance(e, RobotAdded)] == [MARKUP, ESCAPES]
    finally:
        roster.close()

    assert main(["fleet", f"127.0.0.1:{server.port}", "--no-status", "--timeout", cli_timeout(5)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out and "\r" not in out
    assert MARKUP in out  # plain text for a terminal: nothing to interpret there
    assert out.count("\n") == 3  # the header and one line per robot: the newline in a name is escaped

    assert (
        main(["fleet", f"127.0.0.1:{server.port}", "--no-status", "--json", "--timeout", cli_timeout(5)])
        == EXIT_OK
    )
    raw = capsys.readouterr().out
    assert "\x1b" not in raw and raw.count("\n") == 1
    assert [r["name"] for r in json.loads(raw)["robots"]] == [MARKUP, ESCAPES]


def test_unknown_robot_list_names_are_escaped_too(
    central: tuple[TestServer, ServerThread], capsys: pytest.CaptureFixture[str]
) -> None:
    server, _ = central
    listing(server, ClientList((CentralEntry("", 7301, ESCAPES),)).encode())
    code = main(["status", f"127.0.0.1:{server.port}", "--robot", "x", "--once", "--timeout", cli_timeout(5)])
    assert code == 2
    err = capsys.readouterr().err
    assert "\x1b" not in err and err.count("\n") == 1


def test_an_entry_naming_another_host_is_still_reached_at_the_central_servers_host(
    central: tuple[TestServer, ServerThread],
) -> None:
    server, _ = central
    listing(server, ClientList((CentralEntry("evil.example", 7301, "decoy"),)).encode())
    heard = Heard()
    roster = CentralRoster("127.0.0.1", server.port, timeout=5)
    roster.start(heard)
    try:
        eventually(lambda: len(heard) == 1, timeout=10)
        assert isinstance(heard[0], RobotAdded) and heard[0].endpoint.host == "127.0.0.1"
    finally:
        roster.close()


CASES = (CentralEntry("", 7401, "ROBOT"), CentralEntry("", 7402, "robot"), CentralEntry("", 7403, "Robot"))


def test_robot_names_differing_in_case_are_one_robot_the_last_one_listed(
    central: tuple[TestServer, ServerThread], capsys: pytest.CaptureFixture[str]
) -> None:
    """ARIA's central server compares names case-blind: a namesake replaces the old connection."""
    server, _ = central
    listing(server, ClientList(CASES).encode())
    heard = Heard()
    roster = CentralRoster("127.0.0.1", server.port, timeout=5)
    roster.start(heard)
    try:
        eventually(lambda: len(roster.robots) == 1 and len(heard) == 5, timeout=10)
        assert [e.endpoint.port for e in heard if isinstance(e, RobotAdded)] == [7401, 7402, 7403]
        assert [e.name for e in heard if isinstance(e, RobotRemoved)] == ["ROBOT", "robot"]
        (kept,) = roster.robots.values()
        assert (kept.name, kept.port) == ("Robot", 7403)
        # The replaced one's own removal later must not take away the robot that replaced it.
        server.broadcast("clientRemoved", ClientRemoved(CASES[0]).encode())
        server.broadcast("clientAdded", ClientAdded(CentralEntry("", 7404, "other")).encode())
        eventually(lambda: "other" in {e.name for e in roster.robots.values()}, timeout=5)
        assert {e.name for e in roster.robots.values()} == {"Robot", "other"}
    finally:
        roster.close()
    assert (
        main(["fleet", f"127.0.0.1:{server.port}", "--no-status", "--json", "--timeout", cli_timeout(5)])
        == EXIT_OK
    )
    rows = json.loads(capsys.readouterr().out)["robots"]
    assert [(r["name"], r["port"]) for r in rows] == [("Robot", 7403)]


def test_robot_that_fits_several_listed_names_is_refused_with_the_candidates(
    central: tuple[TestServer, ServerThread], capsys: pytest.CaptureFixture[str]
) -> None:
    server, _ = central
    listing(server, ClientList(CASES).encode())
    code = main(
        ["status", f"127.0.0.1:{server.port}", "--robot", "ROBOT", "--once", "--timeout", cli_timeout(5)]
    )
    assert code == EXIT_USAGE
    err = capsys.readouterr().err
    assert "'ROBOT' is ambiguous" in err and err.count("\n") == 1
    assert "'ROBOT' (port 7401)" in err and "'robot' (port 7402)" in err and "'Robot' (port 7403)" in err
