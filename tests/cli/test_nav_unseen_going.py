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

from client.servers import SPECS, ServerThread, TestServer, in_one_write
from patience import cli_timeout
from rtmu.cli import main
from rtmu.protocol.payloads.robot import ModeInfo
from rtmu.subcommands._nav_args import EXIT_NAV_CANCELLED

GOTO_POSE = ("gotoPose", "go to a point", "byte4 byte4 byte4", "none", "Navigation", "RETURN_NONE")
WENT_AND_STOPPED = in_one_write(  # the navigation starts and is stopped at once: no status between
    ("getModeInfo", ModeInfo("Goto").encode()),
    ("getModeInfo", ModeInfo("stop").encode()),
)


@pytest.fixture
def server() -> Iterator[TestServer]:
    srv = TestServer([*SPECS, GOTO_POSE])
    srv.handlers["gotoPose"] = WENT_AND_STOPPED
    with ServerThread(srv) as running:
        yield running


def test_a_drive_stopped_between_two_status_packets_is_cancelled(
    server: TestServer, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["goto", f"127.0.0.1:{server.port}", "--x", "2000", "--y", "1000"]
    code = main([*argv, "--timeout", cli_timeout(5), "--limit", "20"])
    assert code == EXIT_NAV_CANCELLED, capsys.readouterr()
    assert any(r.name == "gotoPose" for r in server.received)
