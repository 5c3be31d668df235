"""A navigation stopped before any status said "Going to" still ends ``rtmu goto`` as cancelled.

The command reads the server's status every 250 ms; a drive that another client stops sooner may
never show in it (the loaded fresh-machine runs made the simulator's "Going to" that short). The
server's mode changes are sent as they happen, so the command also goes by them: a navigation mode
begun after our command and left again, without the arrival we asked for, is someone else's stop.
A scripted server on loopback answers ``gotoPose`` with exactly that — the mode ``Goto`` and then
``stop``, in one write — while its status reads "Stopped" throughout. Without the mode the command
would wait out its ``--limit`` (exit 5).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from client.servers import SPECS, ServerSide, ServerThread, TestServer
from patience import cli_timeout
from rtmu.cli import main
from rtmu.protocol.payloads.robot import ModeInfo
from rtmu.subcommands._nav_args import EXIT_NAV_CANCELLED

GOTO_POSE = ("gotoPose", "go to a point", "byte4 byte4 byte4", "none", "Navigation", "RETURN_NONE")


def went_and_stopped(side: ServerSide, _args: bytes) -> list[bytes]:
    """The navigation starts and is stopped at once: two mode changes, no status between them."""
    side.conn.send_data("getModeInfo", ModeInfo("Goto").encode())
    side.conn.send_data("getModeInfo", ModeInfo("stop").encode())
    return []  # both are in the connection's buffer: ``reply`` writes them in one write


@pytest.fixture
def server() -> Iterator[TestServer]:
    srv = TestServer([*SPECS, GOTO_POSE])
    srv.handlers["gotoPose"] = went_and_stopped
    with ServerThread(srv) as running:
        yield running


def test_a_drive_stopped_between_two_status_packets_is_cancelled(
    server: TestServer, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["goto", f"127.0.0.1:{server.port}", "--x", "2000", "--y", "1000"]
    code = main([*argv, "--timeout", cli_timeout(5), "--limit", "20"])
    assert code == EXIT_NAV_CANCELLED, capsys.readouterr()
    assert any(r.name == "gotoPose" for r in server.received)
