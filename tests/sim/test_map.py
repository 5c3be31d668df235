"""Map services over loopback: the text stream byte for byte, the binary stream point for point."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from rtmu.mapfile import read_map
from rtmu.protocol.payloads.map import Goals, MapId, MapName, MapPacketKind, binary_block_kind
from rtmu.protocol.payloads.mapstream import MapBinaryAssembler, MapTextAssembler
from rtmu.sim import SimConfig, SimServer
from testdata import ARIA_MAPS

from .wire import WireClient, run


def file_lines(path) -> list[str]:
    text = path.read_bytes().decode("latin-1")
    return [line.rstrip("\r") for line in text.split("\n") if line.strip()]


async def _fetch(map_path, *names: str) -> dict[str, list[bytes]]:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=map_path))
    await server.start()
    c = await WireClient().open(server.port)
    out = {}
    for name in names:
        if name in ("getMap", "getMapBinary"):
            c.once(name)
            await c.until(
                lambda name=name: (
                    (c.received[name] and c.received[name][-1] == b"")
                    or (name == "getMap" and c.received[name] == [b"\x00"])
                )
            )
        else:
            await c.ask(name)
        out[name] = list(c.received[name])
    await c.close()
    await server.stop()
    return out


def _text_map(payloads: list[bytes]) -> list[str]:
    asm = MapTextAssembler()
    done = False
    for p in payloads:
        done = asm.feed(p)
    assert done
    return asm.result().lines


def _binary_map(payloads: list[bytes]):
    asm = MapBinaryAssembler()
    done = False
    for p in payloads:
        done = asm.feed(p)
    assert done
    return asm.result()


@pytest.mark.parametrize("which", ["arena", "office", "columbia"])
def test_get_map_streams_the_files_lines_and_binary_carries_its_geometry(which, arena_map):
    path = {
        "arena": arena_map,
        "office": arena_map.parent / "office.map",
        "columbia": ARIA_MAPS / "columbia.map",
    }[which]
    got = run(_fetch(path, "getMap", "getMapBinary", "getMapName", "getMapId", "getGoals"), timeout=120)
    # getMap: every line of the file, one per packet, then "" and the empty packet.
    assert got["getMap"][-2:] == [b"\x00", b""]
    assert _text_map(got["getMap"]) == file_lines(path)
    # getMapBinary: the same points and segments as the file, as int32.
    data = read_map(path)
    binary = _binary_map(got["getMapBinary"])
    assert binary.header_lines[0] == "2D-Map"
    np.testing.assert_array_equal(binary.points, np.asarray(data.points).reshape(-1, 2))
    np.testing.assert_array_equal(binary.segments, np.asarray(data.segments).reshape(-1, 4))
    assert MapName.decode(got["getMapName"][0]).file_name == str(path)
    map_id = MapId.decode(got["getMapId"][0])
    raw = path.read_bytes()
    assert (map_id.checksum, map_id.size, map_id.file_name) == (
        hashlib.md5(raw).digest(),
        len(raw),
        str(path),
    )
    assert list(Goals.decode(got["getGoals"][0]).goals) == [g.name for g in data.goals()]


def test_columbia_binary_blocks_are_at_most_1000_points():
    path = ARIA_MAPS / "columbia.map"
    got = run(_fetch(path, "getMapBinary"), timeout=120)
    blocks = [p for p in got["getMapBinary"] if binary_block_kind(p) is MapPacketKind.POINTS]
    counts = [int.from_bytes(p[:4], "little") for p in blocks]
    assert sum(counts) == 63311 and max(counts) == 1000
    assert len(blocks) == 64  # as the captured serverDemo sent columbia


def test_without_a_map_only_the_empty_string_comes():
    got = run(_fetch(None, "getMap", "getMapName", "getGoals"))
    assert got["getMap"] == [b"\x00"]
    assert MapName.decode(got["getMapName"][0]).file_name == ""
    assert Goals.decode(got["getGoals"][0]).goals == ()


def test_broadcast_only_data_give_no_immediate_reply(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map))
        await server.start()
        c = await WireClient().open(server.port)
        other = await WireClient().open(server.port)
        c.request("mapUpdated", -1)
        await c.barrier()
        assert c.received["mapUpdated"] == []
        assert server.broadcast("mapUpdated") == 1  # only the subscriber
        await c.wait_for("mapUpdated")
        await other.barrier()
        assert other.received["mapUpdated"] == []
        for x in (c, other):
            await x.close()
        await server.stop()

    run(scenario())


def test_check_map_reloads_a_changed_file_and_tells_subscribers(arena_map, tmp_path):
    path = tmp_path / "arena.map"
    path.write_bytes(arena_map.read_bytes())

    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=path))
        await server.start()
        c = await WireClient().open(server.port)
        c.request("mapUpdated", -1)
        c.request("goalsUpdated", -1)
        c.once("checkMap")
        await c.barrier()
        assert c.received["mapUpdated"] == []  # unchanged file: nothing to say
        path.write_text(path.read_text().replace('"Far corner"', '"Far away corner"'))
        c.once("checkMap")
        await c.wait_for("mapUpdated")
        await c.wait_for("goalsUpdated")
        goals = Goals.decode((await c.ask("getGoals"))[0]).goals
        assert "Far away corner" in goals
        await c.close()
        await server.stop()

    run(scenario())


def test_a_million_point_binary_map_reaches_a_reading_client_though_it_exceeds_the_queue_limit(
    million_point_map,
):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=million_point_map))
        await server.start()
        number = server.datalist.number("getMapBinary")
        size = sum(len(c) for c in server.map.binary_stream(number))
        assert size > server.config.max_queued_bytes  # 8 MB against a limit of a few MB
        c = await WireClient().open(server.port)
        c.once("getMapBinary")
        await c.until(lambda: c.received["getMapBinary"][-1:] == [b""], timeout=60)
        binary = _binary_map(c.received["getMapBinary"])
        assert len(binary.points) == 1_000_000
        assert len(server.sessions) == 1  # still connected
        await c.close()
        await server.stop()

    run(scenario(), timeout=120)


def test_a_map_asked_for_again_while_it_is_being_sent_comes_once_more():
    columbia = ARIA_MAPS / "columbia.map"

    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=columbia))
        await server.start()
        c = await WireClient().open(server.port)
        for _ in range(5):  # five in one write: the first is still being sent when the others arrive
            c.conn.request_once("getMap")
        c.conn.request_once("getMapBinary")
        c._flush()
        await c.until(lambda: c.received["getMapBinary"][-1:] == [b""], timeout=60)
        await c.barrier()
        text = c.received["getMap"]
        assert text.count(b"") == 2  # the one being sent, then one more; not five 1.2 MB copies
        end = text.index(b"") + 1
        assert _text_map(text[:end]) == _text_map(text[end:]) == file_lines(columbia)
        assert _binary_map(c.received["getMapBinary"]).points.shape[0] == 63311
        await c.close()
        await server.stop()

    run(scenario(), timeout=120)
