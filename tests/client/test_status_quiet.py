"""``rtmu status`` streaming says on stderr when status stops and when it comes back.

A test server of our own answers ``updateNumbers`` over real loopback sockets: a few statuses, then
silence for ``SILENCE`` (it keeps the time itself, so how late the test's own thread runs on a busy
machine changes nothing), then statuses again. Each status differs from the one before (its x), so the
command prints every one and its ``--count`` ends it soon after the statuses resume — with equal statuses
it printed only its once-a-second heartbeat and took 25 s.
"""

from __future__ import annotations

import time

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK
from rtmu.cli import main

from .servers import ServerSide, ServerThread, TestServer, _numbers

BEFORE = 5
"""Statuses sent before the silence (printed before it: the count stays above them)."""
SILENCE = 2.5
"""Seconds without status: past the command's 1 s word on quiet at a 100 ms interval, well inside its
10 s timeout."""


def test_silence_and_resumption_are_announced(capsys) -> None:  # type: ignore[no-untyped-def]
    sent = [0]
    quiet_until: list[float] = []
    server = TestServer()

    def numbers(side: ServerSide, args: bytes) -> list[bytes]:
        if sent[0] == BEFORE and not quiet_until:
            quiet_until.append(time.monotonic() + SILENCE)
        if quiet_until and time.monotonic() < quiet_until[0]:
            return []
        sent[0] += 1
        return [_numbers({"x": sent[0]})]

    server.handlers["updateNumbers"] = numbers
    with ServerThread(server) as running:
        count = str(2 * BEFORE)
        code = main(
            [
                "status",
                f"127.0.0.1:{running.port}",
                "--interval",
                "100",
                "--timeout",
                cli_timeout(10),
                "--count",
                count,
            ]
        )
    err = capsys.readouterr().err
    assert code == EXIT_OK, err
    assert "the server has gone quiet" in err
    assert "status resumed after" in err
    assert err.index("gone quiet") < err.index("resumed")
    assert sent[0] > BEFORE, "the statuses never came back"
