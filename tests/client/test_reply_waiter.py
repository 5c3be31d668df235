"""How a caller waits for a reply (``client.reply_waiter``) against a scripted server over loopback."""

from __future__ import annotations

from .servers import MAP_LINES, TestServer, run, text_map_packets
from .test_connection import connected


def test_a_stream_closed_early_gives_up_its_request_then_and_there() -> None:
    """A reader that stops after one packet of a reply still coming closes the stream: its request is
    abandoned at that close (nobody waits on it any more), not whenever the garbage collector runs."""

    async def go() -> None:
        server = TestServer()
        server.handlers["getMap"] = lambda s, a: text_map_packets(MAP_LINES)[:2]  # no end: still coming
        await server.start()
        client = await connected(server)
        stream = client.stream("getMap")
        assert await anext(stream) == text_map_packets(MAP_LINES)[0]
        assert len(client._inbox.waiters) == 1
        await stream.aclose()  # type: ignore[attr-defined]
        assert client._inbox.waiters == {}
        assert (await client.request_once("getSafeDrive")).payloads  # the connection goes on
        await client.disconnect()
        await server.stop()

    run(go())
