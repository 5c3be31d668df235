"""A packet over ARIA's 32 000-byte limit is named, not reported as a bare timeout.

A hostile test server of our own answers ``getPictureCam1`` with one well-formed 40 000-byte
packet (correct checksum, length field beyond the limit), which every ArNetworking receiver drops.
"""

from __future__ import annotations

import pytest

from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_TIMEOUT
from rtmu.cli import main
from rtmu.client.connection import AriaClient
from rtmu.client.errors import ClientTimeout, ProtocolFault
from rtmu.protocol.checksum import checksum
from rtmu.values.target import Target

from .servers import ServerSide, ServerThread, TestServer, run

OVER = 40_000


def oversized(command: int, total: int = OVER) -> bytes:
    body = b"\x0f\x0c" + total.to_bytes(2, "little") + command.to_bytes(2, "little") + bytes(total - 8)
    c = checksum(body)
    return body + bytes((c >> 8, c & 0xFF))


def hostile() -> TestServer:
    server = TestServer()

    def too_big(side: ServerSide, args: bytes) -> None:
        side.writer.write(oversized(side.conn.datalist.number("getPictureCam1") or 0))

    server.handlers["getPictureCam1"] = too_big
    return server


def test_the_client_names_the_oversized_packet() -> None:
    async def go() -> str:
        with ServerThread(hostile()) as server:
            client = AriaClient()
            await client.connect(Target("127.0.0.1", server.port), timeout=5)
            try:
                with pytest.raises(ProtocolFault) as caught:
                    await client.request_once("getPictureCam1", timeout=1.0)
                assert client.drops.over_limit == 1
                return str(caught.value)
            finally:
                await client.disconnect()

    message = run(go())
    assert f"the server sent a packet of {OVER} bytes, over ArNetworking's 32 000-byte limit" in message


def test_a_plain_silence_is_still_a_timeout() -> None:
    server = TestServer()
    server.handlers["getPictureCam1"] = lambda side, args: None

    async def go() -> None:
        with ServerThread(server) as running:
            client = AriaClient()
            await client.connect(Target("127.0.0.1", running.port), timeout=5)
            try:
                with pytest.raises(ClientTimeout):
                    await client.request_once("getPictureCam1", timeout=0.5)
            finally:
                await client.disconnect()

    run(go())


def test_rtmu_image_prints_the_reason_instead_of_a_timeout(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    with ServerThread(hostile()) as server:
        code = main(["image", f"127.0.0.1:{server.port}", "--out", str(tmp_path / "p.jpg"), "--timeout", "1"])
    err = capsys.readouterr().err
    assert code == EXIT_CONNECTION and code != EXIT_TIMEOUT
    assert f"packet of {OVER} bytes, over ArNetworking's 32 000-byte limit" in err
    assert not (tmp_path / "p.jpg").exists()
