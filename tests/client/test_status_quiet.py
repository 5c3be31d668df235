"""``rtmu status`` streaming says on stderr when status stops and when it comes back.

A test server of our own sends ``updateNumbers`` only while ``talking`` is set, over real
loopback sockets; the command runs on a thread so the test can silence and restore it.
"""

from __future__ import annotations

import threading
import time

from rtmu.base.exit_codes import EXIT_OK
from rtmu.cli import main

from .servers import ServerSide, ServerThread, TestServer, _numbers


def test_silence_and_resumption_are_announced(capsys) -> None:  # type: ignore[no-untyped-def]
    talking = threading.Event()
    talking.set()
    sent = [0]
    server = TestServer()

    def numbers(side: ServerSide, args: bytes) -> list[bytes]:
        if not talking.is_set():
            return []
        sent[0] += 1
        return [_numbers({})]

    server.handlers["updateNumbers"] = numbers
    result: list[int] = []
    with ServerThread(server) as running:
        cmd = ["status", f"127.0.0.1:{running.port}", "--interval", "100", "--timeout", "10", "--count", "25"]
        worker = threading.Thread(target=lambda: result.append(main(cmd)))
        worker.start()
        deadline = time.monotonic() + 20
        while sent[0] < 5 and time.monotonic() < deadline:
            time.sleep(0.05)
        talking.clear()
        time.sleep(2.5)
        talking.set()
        worker.join(30)
    err = capsys.readouterr().err
    assert result == [EXIT_OK], err
    assert "the server has gone quiet" in err
    assert "status resumed after" in err
    assert err.index("gone quiet") < err.index("resumed")
