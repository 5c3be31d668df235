"""The simulator's ArMapChanger over loopback, on the manual clock: applied, refused, busy, stale, hostile.

Every change set is sent packet by packet with the project's own codec (``change_packets``), as ARIA's
client sends it; what comes back is read as the wire has it — the order of the broadcasts included.
"""

from __future__ import annotations

import itertools
import shutil
from collections import defaultdict
from pathlib import Path

import numpy as np

from rtmu.mapfile import MapObject, object_text, read_map
from rtmu.package_data import project_map
from rtmu.protocol.payloads.map import Goals, MapId
from rtmu.protocol.payloads.mapchange import (
    ChangeCommand,
    ChangeData,
    CoordChange,
    FileLine,
    FileLineGroup,
    LineChange,
    LineSetChange,
    MapChangePacket,
    MapChangeReply,
    MapChangeSet,
    MapChangesInProgress,
    change_packets,
)
from rtmu.protocol.payloads.navigation import GotoGoal, PlannedPath
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.mapchanges import state_of

from .wire import WireClient, run

ARENA = project_map("arena.map")
WATCHED = ("mapUpdated", "goalsUpdated", "mapChangesInProgress")


class _Logged(list):
    def __init__(self, name: str, log: list[str]) -> None:
        super().__init__()
        self.name, self.log = name, log

    def append(self, item: bytes) -> None:
        self.log.append(self.name)
        super().append(item)


async def _client(server: SimServer) -> tuple[WireClient, list[str]]:
    """A client hearing the map broadcasts, with every arrival logged in order."""
    c = await WireClient().open(server.port)
    log: list[str] = []
    c.received = defaultdict(lambda: _Logged("?", log))  # type: ignore[assignment]
    for name in (*WATCHED, "processMapChanges", "getMapId", "getGoals", "getSafeDrive", "getPath"):
        c.received[name] = _Logged(name, log)
    for name in WATCHED:
        c.request(name, -1)
    await c.barrier()
    return c, log


async def _start(map_path: Path = ARENA, **kw) -> SimServer:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=map_path, **kw))
    await server.start()
    return server


def _objects(*lines: str, change: LineChange = LineChange.ADDITIONS) -> LineSetChange:
    groups = tuple(FileLineGroup(FileLine(i, text)) for i, text in enumerate(lines, start=1))
    return LineSetChange(ChangeData.OBJECTS, change, groups)


def _cairn(obj: MapObject) -> str:
    return "Cairn: " + object_text(obj)


def _send(c: WireClient, packets: list[MapChangePacket]) -> None:
    for p in packets:
        c.once("processMapChanges", p.encode())


async def _verdict(c: WireClient, count: int = 1, timeout: float = 30.0) -> int:
    got = await c.wait_for("processMapChanges", count, timeout)
    return MapChangeReply.decode(got[count - 1]).status


def _served_id(server: SimServer) -> MapId:
    m = server.map
    return MapId("", m.name, m.md5, m.size, m.mtime)


LAB = MapObject("GoalWithHeading", 1000, 2000, 45, name="Lab")


def test_an_applied_change_reaches_every_client_before_the_verdict() -> None:
    async def scenario() -> None:
        server = await _start()
        a, a_log = await _client(server)
        b, b_log = await _client(server)
        goal = next(o for o in server.map.objects if o.name == "Goal")
        changes = MapChangeSet((_objects(_cairn(goal), change=LineChange.DELETIONS), _objects(_cairn(LAB))))
        _send(a, change_packets(changes, _served_id(server)))
        assert await _verdict(a) == 10
        await a.wait_for("mapChangesInProgress", 2)
        # ARIA's order: in progress, the map's broadcasts, the verdict, no longer in progress
        assert a_log[-5:] == [
            "mapChangesInProgress", "mapUpdated", "goalsUpdated", "processMapChanges", "mapChangesInProgress",
        ]  # fmt: skip
        assert [MapChangesInProgress.decode(p).in_progress for p in a.received["mapChangesInProgress"]] == [
            True,
            False,
        ]
        await b.wait_for("mapChangesInProgress", 2)
        assert b_log[-4:] == ["mapChangesInProgress", "mapUpdated", "goalsUpdated", "mapChangesInProgress"]
        names = Goals.decode((await b.ask("getGoals"))[0]).goals
        assert names == ("Far corner", "Lab")
        assert LAB in server.map.objects and goal not in server.map.objects
        assert server.map.data is not None and LAB in server.map.data.objects
        assert state_of(server).applied == 1
        await a.close()
        await b.close()
        await server.stop()

    run(scenario())


def test_a_deletion_that_matches_nothing_refuses_the_whole_set_and_the_map_stays() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        before = server.map.md5
        ghost = MapObject("Goal", 9, 9, 0, name="Nowhere")
        changes = MapChangeSet((_objects(_cairn(ghost), change=LineChange.DELETIONS), _objects(_cairn(LAB))))
        _send(a, change_packets(changes))
        assert await _verdict(a) == 0
        await a.barrier()
        assert server.map.md5 == before and LAB not in server.map.objects
        assert a.received["mapUpdated"] == [] and "Nowhere" in state_of(server).refused[-1]
        await a.close()
        await server.stop()

    run(scenario())


def test_unnamed_objects_are_matched_by_their_shape_and_named_ones_by_name_ignoring_case() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        wall = MapObject("ForbiddenLine", 0, -1000, 0, from_xy=(0, -1000), to_xy=(3000, -1000))
        _send(a, change_packets(MapChangeSet((_objects(_cairn(wall)),))))
        assert await _verdict(a) == 10
        renamed = MapObject("Goal", 0, 0, 0, name="FAR CORNER")  # another pose and type: the name decides
        shifted = MapObject("ForbiddenLine", 0, -1000, 0, from_xy=(0, -1000), to_xy=(3001, -1000))
        _send(a, change_packets(MapChangeSet((_objects(_cairn(shifted), change=LineChange.DELETIONS),))))
        assert await _verdict(a, 2) == 0
        _send(
            a,
            change_packets(
                MapChangeSet((_objects(_cairn(renamed), _cairn(wall), change=LineChange.DELETIONS),))
            ),
        )
        assert await _verdict(a, 3) == 10
        assert wall not in server.map.objects and "Far corner" not in server.map.goals
        await a.close()
        await server.stop()

    run(scenario())


def test_while_one_client_changes_the_map_another_is_refused_until_the_first_is_idle_for_15_s() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        b, _ = await _client(server)
        a_packets = change_packets(MapChangeSet((_objects(_cairn(LAB)),)))
        _send(a, a_packets[:1])  # a starts and says nothing more for now
        await b.wait_for("mapChangesInProgress")
        assert MapChangesInProgress.decode(b.received["mapChangesInProgress"][0]).in_progress
        porch = MapObject("Goal", 3000, 1500, 0, name="Porch")
        _send(b, change_packets(MapChangeSet((_objects(_cairn(porch)),))))
        assert await _verdict(b) == 0
        _send(a, a_packets[1:])
        assert await _verdict(a) == 10
        assert LAB in server.map.objects and porch not in server.map.objects
        _send(a, a_packets[:1])  # a starts again and goes quiet for good
        await a.barrier()
        await server.advance(16.0)
        _send(b, change_packets(MapChangeSet((_objects(_cairn(porch)),))))
        assert await _verdict(b, 2) == 10
        assert porch in server.map.objects
        await a.close()
        await b.close()
        await server.stop()

    run(scenario())


def test_a_change_made_against_another_map_is_refused_and_the_servers_map_id_follows() -> None:
    async def scenario() -> None:
        server = await _start()
        a, log = await _client(server)
        stale = MapId("", server.map.name, b"\x00" * 16, server.map.size, server.map.mtime)
        _send(a, change_packets(MapChangeSet((_objects(_cairn(LAB)),)), stale))
        assert await _verdict(a) == 0
        assert MapId.decode((await a.wait_for("getMapId"))[0]) == _served_id(server)
        assert log[-2:] == ["processMapChanges", "getMapId"]
        assert LAB not in server.map.objects
        _send(a, [MapChangePacket(ChangeCommand.CANCEL)])  # what RTMU's client does after a stale refusal
        assert await _verdict(a, 2) == 10
        _send(a, change_packets(MapChangeSet((_objects(_cairn(LAB)),)), _served_id(server)))
        assert await _verdict(a, 3) == 10 and LAB in server.map.objects
        await a.close()
        await server.stop()

    run(scenario())


def test_malformed_packets_are_refused_and_a_broken_set_is_not_applied() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        a.once("processMapChanges", b"\x09\x00garbage")  # a header that does not decode: refused at once
        assert await _verdict(a) == 0
        packets = change_packets(
            MapChangeSet((_objects(_cairn(LAB), _cairn(MapObject("Goal", 1, 1, 0, name="x"))),))
        )
        broken = packets[1].encode()[:-3]  # the second object line cut short
        _send(a, packets[:1])
        a.once("processMapChanges", broken)
        _send(a, packets[2:])
        assert await _verdict(a, 2) == 0
        assert LAB not in server.map.objects and state_of(server).refused
        await a.close()
        await server.stop()

    run(scenario())


def _crosses(path: tuple[tuple[int, int], ...], x: float, y0: float, y1: float) -> bool:
    """Whether the polyline crosses the vertical segment at ``x`` between ``y0`` and ``y1``."""
    for (ax, ay), (bx, by) in itertools.pairwise(path):
        if (ax - x) * (bx - x) < 0:
            y = ay + (by - ay) * (x - ax) / (bx - ax)
            if y0 <= y <= y1:
                return True
    return False


def _path(replies: list[bytes]) -> tuple[tuple[int, int], ...]:
    return PlannedPath.decode(replies[0]).points


def test_a_new_forbidden_line_changes_the_next_planned_path() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        a.once("gotoGoal", GotoGoal("Goal").encode())
        await server.advance(0.1)
        before = ((round(server.robot.x), round(server.robot.y)), *_path(await a.ask("getPath")))
        assert len(before) >= 2 and _crosses(before, 2000, -2500, 600)
        a.once("stop")
        line = MapObject("ForbiddenLine", 2000, -2500, 0, from_xy=(2000, -2500), to_xy=(2000, 600))
        _send(a, change_packets(MapChangeSet((_objects(_cairn(line)),)), _served_id(server)))
        assert await _verdict(a) == 10
        a.once("gotoGoal", GotoGoal("Goal").encode())
        await server.advance(0.1)
        after = ((round(server.robot.x), round(server.robot.y)), *_path(await a.ask("getPath")))
        assert len(after) >= 2 and not _crosses(after, 2000, -2500, 600)
        assert after != before and max(y for _, y in after) > 600  # around the line's northern end
        await a.close()
        await server.stop()

    run(scenario())


def test_points_segments_and_info_lines_are_changed_too() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        points = server.map.points
        gone, new_points = points[:10], np.array([[9000, 9000], [9001, 9001]], np.int32)
        wall = server.map.segments[:1]
        info = LineSetChange(
            ChangeData.INFO,
            LineChange.ADDITIONS,
            (FileLineGroup(FileLine(2, "MapInfo: GoalType Name=Lab")),),
            info_index=0,
        )
        changes = MapChangeSet(
            (info,),
            (
                CoordChange(ChangeData.POINTS, LineChange.DELETIONS, gone),
                CoordChange(ChangeData.POINTS, LineChange.ADDITIONS, new_points),
                CoordChange(ChangeData.LINES, LineChange.DELETIONS, wall),
            ),
        )
        _send(a, change_packets(changes, _served_id(server)))
        assert await _verdict(a) == 10
        m = server.map
        assert len(m.points) == len(points) - 10 + 2 and len(m.segments) == 19
        rows = {tuple(p) for p in m.points.tolist()}
        assert (9000, 9000) in rows and tuple(gone[0]) not in rows
        assert m.data is not None and ("MapInfo", "GoalType Name=Lab") in m.data.info
        assert "MapInfo: GoalType Name=Lab" in m.lines
        await a.close()
        await server.stop()

    run(scenario())


def test_the_file_is_left_alone_unless_asked_and_check_map_keeps_the_change(tmp_path: Path) -> None:
    async def scenario() -> None:
        copy = tmp_path / "arena.map"
        shutil.copy(ARENA, copy)
        original = copy.read_bytes()
        server = await _start(copy)
        a, _ = await _client(server)
        _send(a, change_packets(MapChangeSet((_objects(_cairn(LAB)),)), _served_id(server)))
        assert await _verdict(a) == 10
        assert copy.read_bytes() == original
        a.once("checkMap")
        await a.barrier()
        assert LAB in server.map.objects  # the file did not change, so nothing is re-read
        await a.close()
        await server.stop()

        saving = await _start(copy, save_map_changes=True)
        b, _ = await _client(saving)
        _send(b, change_packets(MapChangeSet((_objects(_cairn(LAB)),)), _served_id(saving)))
        assert await _verdict(b) == 10
        assert LAB in read_map(copy).objects
        b.once("checkMap")
        await b.barrier()
        assert b.received["mapUpdated"] == [b""]  # only the change's own: checkMap found nothing new
        await b.close()
        await saving.stop()

    run(scenario())


def test_a_hundred_thousand_objects_in_one_change_set_are_taken_within_bounds() -> None:
    async def scenario() -> None:
        server = await _start()
        a, _ = await _client(server)
        lines = [_cairn(MapObject("Goal", i % 4000, i // 4000, 0, name=f"g{i}")) for i in range(100_000)]
        packets = change_packets(MapChangeSet((_objects(*lines),)))
        assert len(packets) > 100
        _send(a, packets)
        assert await _verdict(a, timeout=100) == 10
        assert len(server.map.objects) == 3 + 100_000
        await a.close()
        await server.stop()

    run(scenario(), timeout=120)


def test_map_changes_in_progress_is_broadcast_only() -> None:
    async def scenario() -> None:
        server = await _start()
        c = await WireClient().open(server.port)
        c.once("mapChangesInProgress")
        await c.barrier()
        assert c.received["mapChangesInProgress"] == []
        entry = server.datalist.entry(server.datalist.number("processMapChanges"))
        assert entry is not None and entry.flags == "RETURN_SINGLE|IDLE_PACKET"
        await c.close()
        await server.stop()

    run(scenario())


def test_the_crossing_helper_tells_a_crossing_from_a_detour() -> None:
    assert _crosses(((0, 0), (4000, 0)), 2000, -100, 100)
    assert not _crosses(((0, 0), (1000, 2000), (4000, 0)), 2000, -2500, 600)
