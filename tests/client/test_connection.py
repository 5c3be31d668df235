"""AriaClient against scripted servers over real loopback sockets: every call and every failure."""

from __future__ import annotations

import asyncio
import socket
from collections.abc import Callable

import pytest

from rtmu.client.connection import AriaClient
from rtmu.client.errors import (
    ClientError,
    ClientTimeout,
    ConnectionRefused,
    LoginRejected,
    NotSupported,
    ProtocolFault,
    ReplyTooLarge,
    ServerClosed,
)
from rtmu.protocol.auth import UserTable
from rtmu.protocol.fields import FieldReader
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.drive import TurnByAngle
from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.values.target import Target

from .servers import MAP_LINES, TestServer, run, text_map_packets

USERS = UserTable.parse("UserInfoVersion1\nuser alice secret1 all\nuser bob pw2 RobotInfo Stop\n")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


async def until(predicate: Callable[[], bool], timeout: float = 3.0) -> None:
    """Let the loop run until ``predicate()`` holds (bytes in flight); fail after ``timeout`` s."""
    async with asyncio.timeout(timeout):
        while not predicate():
            await asyncio.sleep(0.002)


async def connected(server: TestServer, user: str = "", password: str = "") -> AriaClient:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", server.port, user, password), timeout=5)
    return client


def test_connect_lists_data_and_supports() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        assert client.connected
        assert client.supports("ratioDrive") and not client.supports("wander")
        assert [e.name for e in client.datalist][:2] == ["updateNumbers", "updateStrings"]
        await client.disconnect()
        await server.stop()

    run(go())


def test_request_once_single_reply_and_typed_decode() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        reply = await client.request_once("updateNumbers", timeout=2)
        numbers = reply.decode()
        assert isinstance(numbers, UpdateNumbers)
        assert (numbers.x, numbers.y, numbers.th) == (1000, 2000, 90)
        await client.disconnect()
        await server.stop()

    run(go())


def test_request_once_without_reply_returns_at_once_and_arrives() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        reply = await client.request_once("turnByAngle", 90)
        assert reply.payloads == ()
        await client.request_once("getSafeDrive")  # a round trip: the server has seen the turn by now
        turn = [r for r in server.received if r.name == "turnByAngle"]
        assert FieldReader(turn[0].args).double() == 90.0
        await client.disconnect()
        await server.stop()

    run(go())


def test_a_typed_payload_is_sent_under_its_own_data_name() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        client.send(TurnByAngle(45.0))
        reply = await client.request_once(TurnByAngle(-45.0))  # RETURN_NONE: empty at once
        assert reply.payloads == ()
        await client.request_once("getSafeDrive")  # a round trip: both turns have arrived
        turns = [FieldReader(r.args).double() for r in server.received if r.name == "turnByAngle"]
        assert turns == [45.0, -45.0]
        with pytest.raises(TypeError, match="its own arguments"):
            client.send(TurnByAngle(1.0), 2.0)
        await client.disconnect()
        await server.stop()

    run(go())


def test_subscription_streams_and_stop_request_ends_it() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        got: list[UpdateNumbers] = []
        arrived = asyncio.Event()

        def on_numbers(packet):  # type: ignore[no-untyped-def]
            got.append(packet.decode())
            if len(got) >= 3:
                arrived.set()

        client.request("updateNumbers", 20, on_numbers)
        await asyncio.wait_for(arrived.wait(), 3)
        client.stop_request("updateNumbers")
        await client.request_once("getSafeDrive")  # round trip: REQUESTSTOP processed, task ended
        count = len(got)
        assert "updateNumbers" not in server.sides[0].subs
        await client.request_once("getSafeDrive")  # anything sent before this reply has arrived
        assert len(got) == count
        assert "updateNumbers" in [r.name for r in server.received if r.kind == "stop"]
        await client.disconnect()
        await server.stop()

    run(go())


def test_map_collected_text_and_binary_and_streamed() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        text = await client.request_once("getMap")
        assert [FieldReader(p).string() for p in text.payloads[: len(MAP_LINES)]] == MAP_LINES
        assert text.payloads[-2:] == (b"\x00", b"")
        binary = await client.request_once("getMapBinary")
        assert binary.payloads[-1] == b"" and len(binary.payloads) > 5
        streamed = [p async for p in client.stream("getMapBinary")]
        assert tuple(streamed) == binary.payloads
        # No map: a single 00 ends the reply, and the next request still lines up.
        server.map_lines = []
        none = await client.request_once("getMap")
        assert none.payloads == (b"\x00",)
        assert (await client.request_once("getMapName")).payload == b"test.map\x00"
        await client.disconnect()
        await server.stop()

    run(go())


def test_replies_match_requests_in_order() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        counter = iter(range(100))
        server.handlers["getMapName"] = lambda s, a: [f"map{next(counter)}".encode() + b"\x00"]
        replies = await asyncio.gather(*(client.request_once("getMapName") for _ in range(5)))
        assert [r.payload for r in replies] == [f"map{i}".encode() + b"\x00" for i in range(5)]
        await client.disconnect()
        await server.stop()

    run(go())


def test_not_supported_is_typed() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        with pytest.raises(NotSupported) as info:
            await client.request_once("wander")
        assert info.value.exit_code == 4 and "wander" in str(info.value)
        with pytest.raises(NotSupported):
            client.send("wander")
        await client.disconnect()
        await server.stop()

    run(go())


def test_connection_refused() -> None:
    async def go() -> None:
        with pytest.raises(ConnectionRefused) as info:
            await AriaClient().connect(Target("127.0.0.1", free_port()), timeout=2)
        assert info.value.exit_code == 3 and "refused" in str(info.value)

    run(go())


def test_wrong_password_and_unknown_user_carry_arias_reason() -> None:
    async def go() -> None:
        server = TestServer(users=USERS)
        await server.start()
        for user, password in (("alice", "wrong"), ("mallory", "x"), ("", "")):
            with pytest.raises(LoginRejected) as info:
                await AriaClient().connect(Target("127.0.0.1", server.port, user, password), timeout=2)
            assert info.value.reason == 1 and info.value.bad_credentials
            assert "wrong user name or password" in str(info.value)
        client = await connected(server, user="ALICE", password="secret1")
        assert client.supports("ratioDrive")
        await client.disconnect()
        bob = await connected(server, user="bob", password="pw2")
        assert bob.supports("stop") and not bob.supports("ratioDrive")  # groups limit the list
        await bob.disconnect()
        await server.stop()

    run(go())


def test_server_that_accepts_but_never_answers_times_out() -> None:
    async def go() -> None:
        server = TestServer(silent=True)
        await server.start()
        with pytest.raises(ClientTimeout) as info:
            await AriaClient().connect(Target("127.0.0.1", server.port), timeout=0.3)
        assert info.value.exit_code == 5 and "did not complete the login within 0.3 s" in str(info.value)
        await server.stop()

    run(go(), timeout=5)  # the login timeout, not this bound, must end it


def test_request_that_is_never_answered_times_out() -> None:
    async def go() -> None:
        server = TestServer()
        server.handlers["getMapName"] = lambda s, a: None
        await server.start()
        client = await connected(server)
        with pytest.raises(ClientTimeout):
            await client.request_once("getMapName", timeout=0.2)
        assert client.connected
        await client.disconnect()
        await server.stop()

    run(go())


def test_server_killed_mid_request() -> None:
    async def go() -> None:
        server = TestServer()
        server.handlers["getMapName"] = lambda s, a: None
        await server.start()
        closed: list[Exception] = []
        client = AriaClient(on_close=closed.append)
        await client.connect(Target("127.0.0.1", server.port), timeout=2)
        waiting = asyncio.create_task(client.request_once("getMapName", timeout=5))
        await until(lambda: "getMapName" in server.names())  # the request is at the server
        server.kill(server.sides[0])
        with pytest.raises(ServerClosed):
            await waiting
        assert len(closed) == 1 and isinstance(closed[0], ServerClosed)
        assert not client.connected
        with pytest.raises(ServerClosed):
            await client.request_once("getMapName")
        await client.disconnect()
        await server.stop()

    run(go())


def test_server_closing_during_map_download() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()

        def half_map(side, args):  # type: ignore[no-untyped-def]
            for line in MAP_LINES[:5]:
                side.conn.send_data("getMap", line.encode() + b"\x00")
            side.writer.write(side.conn.data_to_send())
            asyncio.get_running_loop().call_later(0.05, server.kill, side)
            return None

        server.handlers["getMap"] = half_map
        client = await connected(server)
        with pytest.raises(ServerClosed):
            await client.request_once("getMap", timeout=5)
        await client.disconnect()
        await server.stop()

    run(go())


def test_garbage_mid_stream_is_counted_and_the_stream_goes_on() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        got: list[bytes] = []
        client.request("updateNumbers", -1, lambda p: got.append(p.payload))
        await client.request_once("getSafeDrive")
        side = server.sides[0]
        good = encode_packet(client.datalist.number("updateNumbers"), bytes(19))  # type: ignore[arg-type]
        corrupt = bytearray(good)
        corrupt[-1] ^= 0xFF
        side.writer.write(b"\x00\x11\x0f\x22" + bytes(corrupt) + b"\x0f\x0c\x07\x00" + good)
        await client.request_once("getSafeDrive")
        assert got[-1] == bytes(19)
        assert client.drops.bad_checksum == 1 and client.drops.bad_length == 1
        assert client.connected
        await client.disconnect()
        await server.stop()

    run(go())


def test_not_arnetworking_is_a_protocol_error() -> None:
    async def go() -> None:
        async def bad(reader, writer):  # type: ignore[no-untyped-def]
            writer.write(encode_packet(2, b"alpha"))  # an introduction cut short
            await writer.drain()
            await reader.read()

        srv = await asyncio.start_server(bad, "127.0.0.1", 0)
        port = srv.sockets[0].getsockname()[1]
        with pytest.raises(ProtocolFault):
            await AriaClient().connect(Target("127.0.0.1", port), timeout=2)
        srv.close()

    run(go())


async def _garbage_server(opening: bytes, repeat: int = 1) -> asyncio.base_events.Server:
    """Sends ``opening`` ``repeat`` times, then keeps the connection open without a word more."""

    async def serve(reader, writer):  # type: ignore[no-untyped-def]
        writer.write(opening * repeat)
        await writer.drain()
        await reader.read()

    return await asyncio.start_server(serve, "127.0.0.1", 0)


@pytest.mark.parametrize(
    ("opening", "repeat", "said"),
    [
        (b"<html><body>It works!</body></html>\n", 200, "bytes without a single valid packet"),
        (b"\x00\x0f\x0c\x7d\x7d" + bytes(range(256)), 40, "bytes without a single valid packet"),
        (b"SSH-2.0-OpenSSH_9.6\r\n", 1, "SSH-2.0"),
        (b"HTTP/1.1 400 Bad Request\r\n\r\n", 1, "HTTP/1.1 400"),
    ],
)
def test_a_server_that_is_not_arnetworking_is_named_at_once(opening: bytes, repeat: int, said: str) -> None:
    async def go() -> None:
        srv = await _garbage_server(opening, repeat)
        port = srv.sockets[0].getsockname()[1]
        with pytest.raises(ProtocolFault) as info:  # long before the 60 s login timeout
            await AriaClient().connect(Target("127.0.0.1", port), timeout=60)
        assert "not an ArNetworking server" in str(info.value) and said in str(info.value)
        assert info.value.exit_code == 3
        srv.close()

    run(go(), timeout=10)


def test_disconnect_says_goodbye_and_ends_the_reader() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        client.request("updateNumbers", 10, lambda p: None)
        reader = client._read_task
        await client.disconnect()
        assert reader is not None and reader.done()
        await until(lambda: "SHUTDOWN" in server.names())
        assert client.closed_error is None  # our own choice, not a failure
        await client.disconnect()  # twice is fine
        await server.stop()

    run(go())


def test_a_stop_sent_while_the_server_is_slow_to_read_still_arrives_after_disconnect(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Closing with the server's status unread used to reset the socket: a server whose next
    write met the reset dropped our last packets unread — the stop among them (a loaded
    simulator lost it 1 time in 15). Now the client half-closes and reads on until the server
    has read everything and closed. The linger is made long so only the order of events counts.
    """
    monkeypatch.setattr("rtmu.client.goodbye.LINGER_TIMEOUT", 30.0)

    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        client.request("updateNumbers", 10, lambda p: None)  # the server keeps writing to us
        await until(lambda: "updateNumbers" in server.names())
        server.deafen()  # ...but reads nothing for a while, as a busy server does
        await client.request_once("getSafeDrive")  # the read already waiting is the last one it does
        client.send("stop")
        closing = asyncio.create_task(client.disconnect())
        await asyncio.sleep(0.3)  # the server writes on meanwhile: status for a client that has left
        server.undeafen()
        await until(lambda: "SHUTDOWN" in server.names() or server.sides[0].writer.is_closing())
        await asyncio.wait_for(closing, 5)
        assert server.names()[-2:] == ["stop", "SHUTDOWN"]
        assert client.closed_error is None
        await server.stop()

    run(go())


def test_disconnect_from_a_server_that_never_reads_or_closes_still_ends() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        client.request("updateNumbers", 10, lambda p: None)
        await until(lambda: "updateNumbers" in server.names())
        server.deafen()
        await client.request_once("getSafeDrive")  # the read already waiting is the last one it does
        await client.disconnect()  # bounded by LINGER_TIMEOUT + CLOSE_TIMEOUT, not by the server
        assert client._read_task is None or client._read_task.done()
        assert not client.connected
        await server.stop()

    run(go(), timeout=10)


def _numbered_map_names(server: TestServer, lose: set[int]) -> list[int]:
    """getMapName answers ``mapN`` for the N-th request (1-based), except the calls in ``lose``."""
    calls = [0]

    def answer(side, args):  # type: ignore[no-untyped-def]
        calls[0] += 1
        return None if calls[0] in lose else [f"map{calls[0]}".encode() + b"\x00"]

    server.handlers["getMapName"] = answer
    return calls


def test_one_lost_reply_does_not_shift_the_later_ones() -> None:
    async def go() -> None:
        server = TestServer()
        _numbered_map_names(server, lose={1})
        await server.start()
        client = await connected(server)
        with pytest.raises(ClientTimeout):
            await client.request_once("getMapName", timeout=0.1)
        for n in range(2, 7):  # retried at once, as a ping loop or a script would
            assert (await client.request_once("getMapName", timeout=2)).payload == f"map{n}".encode() + b"\0"
        await client.disconnect()
        await server.stop()

    run(go())


def test_a_late_reply_still_lines_up_with_its_abandoned_request() -> None:
    async def go() -> None:
        server = TestServer()
        _numbered_map_names(server, lose={1})
        await server.start()
        client = await connected(server)
        with pytest.raises(ClientTimeout):
            await client.request_once("getMapName", timeout=0.05)
        side = server.sides[0]
        side.conn.send_data("getMapName", b"late\x00")  # the first reply, after its waiter gave up
        side.writer.write(side.conn.data_to_send())
        await client.request_once("getSafeDrive")  # a round trip: the late reply has been read
        assert (await client.request_once("getMapName", timeout=2)).payload == b"map2\x00"
        await client.disconnect()
        await server.stop()

    run(go())


def test_an_abandoned_map_swallows_its_own_late_packets() -> None:
    async def go() -> None:
        server = TestServer()
        calls = [0]
        first: list[object] = []

        def maps(side, args):  # type: ignore[no-untyped-def]
            calls[0] += 1
            packets = text_map_packets(MAP_LINES)
            if calls[0] == 1:
                first.append(side)
                return packets[:4]  # stalls half way
            return packets

        server.handlers["getMap"] = maps
        await server.start()
        client = await connected(server)
        with pytest.raises(ClientTimeout):
            await client.request_once("getMap", timeout=0.1)
        side = server.sides[0]
        for payload in text_map_packets(MAP_LINES)[4:]:  # the rest of the first map, late
            side.conn.send_data("getMap", payload)
        side.writer.write(side.conn.data_to_send())
        second = await client.request_once("getMap", timeout=2)
        assert second.payloads == tuple(text_map_packets(MAP_LINES))
        await client.disconnect()
        await server.stop()

    run(go())


def test_a_map_that_stalled_half_way_is_given_up_after_the_grace() -> None:
    from .fakeclock import FakeClock

    async def go() -> None:
        server = TestServer()
        calls = [0]

        def maps(side, args):  # type: ignore[no-untyped-def]
            calls[0] += 1
            packets = text_map_packets(MAP_LINES)
            return packets[:4] if calls[0] == 1 else packets  # the first never ends

        server.handlers["getMap"] = maps
        await server.start()
        clock = FakeClock()
        client = AriaClient(clock=clock)
        await client.connect(Target("127.0.0.1", server.port), timeout=5)
        with pytest.raises(ClientTimeout):
            await client.request_once("getMap", timeout=0.1)
        clock.advance(client.abandon_grace)
        again = await client.request_once("getMap", timeout=2)
        assert again.payloads == tuple(text_map_packets(MAP_LINES))
        await client.disconnect()
        await server.stop()

    run(go())


def test_requests_waiting_per_data_are_capped() -> None:
    async def go() -> None:
        server = TestServer()
        server.handlers["getMapName"] = lambda s, a: None
        await server.start()
        client = await connected(server)
        client.max_pending = 4
        waiting = [asyncio.create_task(client.request_once("getMapName", timeout=5)) for _ in range(4)]
        await asyncio.sleep(0)
        with pytest.raises(ClientError, match="already waiting"):
            await client.request_once("getMapName", timeout=5)
        for task in waiting:
            task.cancel()
        await asyncio.gather(*waiting, return_exceptions=True)
        await client.disconnect()
        await server.stop()

    run(go())


def test_a_reply_past_its_bound_is_refused_and_the_next_still_lines_up() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        with pytest.raises(ReplyTooLarge, match="5 packets"):
            await client.request_once("getMap", max_packets=5)
        with pytest.raises(ReplyTooLarge, match="20 bytes"):
            await client.request_once("getMap", max_bytes=20)
        whole = await client.request_once("getMap")  # the refused replies were swallowed to their end
        assert whole.payloads == tuple(text_map_packets(MAP_LINES))
        await client.disconnect()
        await server.stop()

    run(go())


def test_a_stream_holds_each_packet_once_and_bounds_what_is_unread() -> None:
    async def go() -> None:
        server = TestServer()
        await server.start()
        client = await connected(server)
        number = client.datalist.number("getMap")
        got = []
        async for payload in client.stream("getMap"):
            got.append(payload)
            waiting = client._conn.replies.waiting(number)  # type: ignore[union-attr,arg-type]
            slot = waiting[0] if waiting else None
            assert slot is None or slot.payloads == []  # yielded packets are not kept a second time
        assert got == text_map_packets(MAP_LINES)
        with pytest.raises(ReplyTooLarge, match="3 packets of 'getMap' not read yet"):
            async for _ in client.stream("getMap", max_packets=3):  # the map arrives faster than that
                await client.request_once("getSafeDrive")  # a slow reader
        assert (await client.request_once("getMap")).payloads == tuple(text_map_packets(MAP_LINES))
        await client.disconnect()
        await server.stop()

    run(go())
