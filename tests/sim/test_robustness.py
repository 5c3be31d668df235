"""Many clients, vanishing clients, garbage and clients that stop reading: none of it costs the others."""

from __future__ import annotations

import asyncio
import random

from rtmu.protocol.client_connection import ClientState
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.server import REFUSING_SLOTS
from testdata import ARIA_MAPS

from .wire import WireClient, eventually, run

COLUMBIA = ARIA_MAPS / "columbia.map"


def test_fifty_clients_each_get_their_own_interval(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map))
        await server.start()
        clients = await asyncio.gather(*(WireClient().open(server.port) for _ in range(50)))
        intervals = [100, 200, 500, 0, -5]
        for i, c in enumerate(clients):
            c.request("updateNumbers", intervals[i % 5])
            c.request("updateStrings", -1)
        await asyncio.gather(*(c.wait_for("updateNumbers") for c in clients))
        await server.advance(1.0)
        expected = {100: 11, 200: 6, 500: 3, 0: 101, -5: 101}  # the first reply + the periodic ones
        for i, c in enumerate(clients):
            want = expected[intervals[i % 5]]
            await c.wait_for("updateNumbers", want)
            assert len(c.received["updateNumbers"]) == want, (i, intervals[i % 5])
            assert len(c.received["updateStrings"]) == 1  # no change happened: no broadcast
        assert len(server.sessions) == 50
        await asyncio.gather(*(c.close() for c in clients))
        await server.stop()

    run(scenario(), timeout=120)


def test_vanishing_and_garbage_clients_cost_the_others_nothing(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=COLUMBIA))
        await server.start()
        watcher = await WireClient().open(server.port)
        watcher.request("updateNumbers", 100)
        await watcher.wait_for("updateNumbers")

        # 1. A client asks for a 1 MB map and vanishes (reset) while it streams.
        leaver = await WireClient().open(server.port)
        leaver.once("getMap")
        leaver.writer.transport.abort()
        # 2. A client dies half-way through a packet.
        half = await WireClient().open(server.port)
        half.send_raw(encode_packet(half.conn.number_of("ratioDrive"), b"50\x000\x00100\x00")[:9])
        await asyncio.sleep(0)
        half.writer.transport.abort()
        # 3. Garbage, before and after a login: random bytes, false syncs, absurd lengths, bad checksums.
        rng = random.Random(7)
        _, junk_writer = await asyncio.open_connection("127.0.0.1", server.port)
        junk = bytes(rng.getrandbits(8) for _ in range(20000))
        junk += b"\x0f\x0c\xff\xff" + b"\x0f\x0c\x07\x00" + b"\x0f\x0c\x20\x00\x01\x01" + bytes(30)
        junk_writer.write(junk)
        garbled = await WireClient().open(server.port)
        garbled.send_raw(junk)
        await garbled.barrier()  # still served after all that

        await server.advance(1.0)
        got = await watcher.wait_for("updateNumbers", 11)
        assert len(got) == 11
        assert UpdateNumbers.decode(got[-1]).battery > 12
        await asyncio.sleep(0.05)
        assert leaver.writer.transport.is_closing() and half.writer.transport.is_closing()
        assert server.robot.vel == 0  # the half ratioDrive never counted
        junk_writer.close()
        for c in (watcher, garbled):
            await c.close()
        await server.stop()

    run(scenario(), timeout=120)


def test_a_client_flooding_fake_headers_gets_one_slice_per_loop_turn(arena_map):
    """Its input is handled a slice at a time between everybody else's turns, so others keep their service."""
    flood = b"\x0f\x0c\x20\x00" * (2_000_000 // 4)  # a header every 4 bytes, none with a good checksum

    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map))
        await server.start()
        watcher = await WireClient().open(server.port)
        watcher.request("updateNumbers", 100)
        await watcher.wait_for("updateNumbers")
        _, flood_writer = await asyncio.open_connection("127.0.0.1", server.port)
        port = flood_writer.get_extra_info("sockname")[1]
        await watcher.barrier()
        flooder = next(s for s in server.sessions if s.peer.endswith(f":{port}"))

        per_turn: list[int] = []
        cycles_while_flooding: list[int] = []

        async def probe() -> None:
            last = flooder.bytes_in
            while flooder.bytes_in < len(flood) and not flooder.closed:
                await asyncio.sleep(0)
                per_turn.append(flooder.bytes_in - last)
                last = flooder.bytes_in
                if 0 < flooder.bytes_in < len(flood):
                    cycles_while_flooding.append(server.cycles)

        flood_writer.write(flood)
        watching = asyncio.create_task(probe())
        await server.advance(2.0)
        await asyncio.wait_for(watching, 60)

        assert max(per_turn) <= 4096
        assert len(set(cycles_while_flooding)) > 10  # the cycle ran while the flood was being read
        await watcher.barrier()
        assert len(watcher.received["updateNumbers"]) == 21
        assert flooder in server.sessions  # garbage costs only its sender's bytes, not the link
        flood_writer.close()
        await watcher.close()
        await server.stop()

    run(scenario(), timeout=120)


def test_a_client_that_stops_reading_is_dropped_after_the_backup_timeout(million_point_map):
    async def scenario() -> None:
        cfg = SimConfig(port=0, realtime=False, map_path=million_point_map, backup_timeout=5.0)
        server = SimServer(cfg)
        await server.start()
        watcher = await WireClient().open(server.port)
        watcher.request("updateNumbers", 100)
        stuck = await WireClient().open(server.port)
        stuck._task.cancel()  # stop reading, keep the socket open
        stuck.once("getMapBinary")  # 8 MB: more than the kernel's socket buffers hold
        await watcher.barrier()
        port = str(stuck.writer.get_extra_info("sockname")[1])
        stuck_session = [s for s in server.sessions if s.peer.endswith(":" + port)]
        assert stuck_session
        await eventually(lambda: stuck_session[0].buffered > 0, what="the download to stall")
        await server.advance(3.0)
        assert stuck_session[0] in server.sessions  # not yet
        await server.advance(3.0)
        assert stuck_session[0] not in server.sessions
        got = await watcher.wait_for("updateNumbers", 61)
        assert len(got) >= 61
        await watcher.close()
        await stuck.close(goodbye=False)
        await server.stop()

    run(scenario(), timeout=120)


def test_a_client_that_queues_more_than_a_few_megabytes_is_dropped_at_once(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map))
        await server.start()
        assert server.config.max_queued_bytes <= 8 * 1024 * 1024
        watcher = await WireClient().open(server.port)
        greedy = await WireClient().open(server.port)
        greedy.once("SimulatorVideo640x480")
        await greedy.barrier()
        greedy._task.cancel()  # it stops reading and asks for 1600 pictures (about 16 MB)
        for _ in range(1600):
            greedy.conn.request_once("getPictureCam1")
        greedy._flush()
        port = str(greedy.writer.get_extra_info("sockname")[1])
        session = next(s for s in server.sessions if s.peer.endswith(":" + port))
        await eventually(lambda: session.closed, what="the greedy client to be dropped")
        assert session not in server.sessions
        assert session.bytes_out <= server.config.max_queued_bytes + 8 * 1024 * 1024  # kernel buffers
        await watcher.barrier()  # the others are still served
        await watcher.close()
        await greedy.close(goodbye=False)
        await server.stop()

    run(scenario(), timeout=120)


def test_connections_beyond_the_client_limit_are_refused_then_closed_at_once():
    async def scenario() -> None:
        assert SimConfig().max_clients == 100  # there is a limit unless one asks for none
        server = SimServer(SimConfig(port=0, realtime=False, max_clients=2))
        await server.start()
        admitted = [await WireClient().open(server.port) for _ in range(2)]
        refused = await WireClient().open(server.port)
        assert refused.rejected is not None and refused.rejected.reason == 5  # ARIA's "too many clients"
        await refused.until(lambda: refused.eof)
        # Sockets that never introduce themselves are kept only up to a few refusal slots.
        silent = [await asyncio.open_connection("127.0.0.1", server.port) for _ in range(40)]
        await admitted[0].barrier()
        assert len(server.sessions) <= 2 + REFUSING_SLOTS
        closed_at_once = 0
        for reader, _ in silent:
            first = await asyncio.wait_for(reader.read(1), 5)
            closed_at_once += first == b""  # no INTRODUCTION, just closed
        assert closed_at_once >= 40 - REFUSING_SLOTS
        for c in admitted:
            await c.barrier()
            assert c.conn.state is ClientState.CONNECTED
        for _, writer in silent:
            writer.close()
        for c in (*admitted, refused):
            await c.close(goodbye=False)
        await server.stop()

    run(scenario())


def test_shutdown_tells_every_client():
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False))
        await server.start()
        clients = [await WireClient().open(server.port) for _ in range(3)]
        await server.stop()
        for c in clients:
            await c.until(lambda c=c: c.eof)
            assert c.shutdown
            await c.close(goodbye=False)

    run(scenario())
