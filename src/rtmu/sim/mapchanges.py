"""The simulator's ``ArMapChanger``: ``processMapChanges`` and ``mapChangesInProgress`` (a data module).

One change set at a time, as ARIA keeps it (:mod:`rtmu.protocol.payloads.mapchange` has the wire
rules): a start from another client while one is open and active in the last 15 s is ignored, and that
client's finish is refused; packets whose first map id no longer names the served map are ignored, and
such a finish is refused and followed by ``getMapId``. The finished set is applied on a worker thread
(:mod:`rtmu.sim.map_apply`: all or nothing), then the new map is served — its walls to the world and
its objects (a new forbidden line, say) to the path planner — and ``mapUpdated`` / ``goalsUpdated`` go
to every subscriber before the verdict, ``mapChangesInProgress`` 0 after it, in ARIA's order.
``SimConfig.save_map_changes`` also writes the changed map into the served file, as ARIA does; by
default the file is left alone and the change lives as long as the simulator.
"""

from __future__ import annotations

import asyncio
import logging
import os
import secrets
import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from weakref import WeakKeyDictionary

from rtmu.mapfile import new_map
from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.fields import FieldReader
from rtmu.protocol.payloads.map import MapId
from rtmu.protocol.payloads.mapchange import (
    CHANGE_FAILED,
    CHANGE_SUCCESS,
    ChangeCommand,
    MapChangeAssembler,
    MapChangePacket,
    MapChangeReply,
    MapChangeSet,
    MapChangesInProgress,
)

from .catalogue import Row
from .context import SimHost
from .geometry import Obstacles
from .handlers import Call, Handler, Other, Reply
from .map_apply import ChangeRefused, apply_changes, check_ids, result_bytes, same_file, same_geometry
from .mapserve import ServedMap, served_map

log = logging.getLogger("rtmu.sim")

IDLE_DROP_S = 15.0
"""A change set whose client has sent nothing for this long may be replaced by another client's."""


@dataclass
class OpenSet:
    """The change set being received: whose, since when, and what came so far."""

    owner: int
    last: float
    assembler: MapChangeAssembler = field(default_factory=MapChangeAssembler)
    broken: str = ""
    """Why the set cannot be applied (a packet that did not decode or broke the set's counts)."""


@dataclass
class ChangerState:
    open: OpenSet | None = None
    applied: int = 0
    refused: list[str] = field(default_factory=list)
    """Why each refused set was refused, in words (ARIA logs them; tests read them)."""


_STATES: WeakKeyDictionary[object, ChangerState] = WeakKeyDictionary()


def state_of(server: object) -> ChangerState:
    state = _STATES.get(server)
    if state is None:
        state = _STATES[server] = ChangerState()
    return state


def served_id(m: ServedMap) -> MapId:
    return MapId("", m.name, m.md5, m.size, m.mtime)


def _header(args: bytes) -> tuple[ChangeCommand, MapId, MapId] | None:
    """Command and ids, when at least those decode (ARIA refuses at once a packet whose header does not)."""
    try:
        r = FieldReader(args)
        value = r.ubyte2("command")
        if value > ChangeCommand.CANCEL:
            return None
        return ChangeCommand(value), MapId.read(r), MapId.read(r)
    except ProtocolError:
        return None


def _process(call: Call) -> Iterable[Reply]:
    head = _header(call.args)
    if head is None:
        return (MapChangeReply(CHANGE_FAILED).encode(),)
    command, orig, new = head
    server, state, now = call.server, state_of(call.server), call.world.time
    here = served_id(server.map)
    if not orig.is_null and (not same_file(here, orig) or here.file_name.lower() != new.file_name.lower()):
        if command is ChangeCommand.FINISH:
            state.refused.append("the change was made against another map")
            return (MapChangeReply(CHANGE_FAILED).encode(), Other("getMapId", server.map.id_payload()))
        return ()
    try:
        packet: MapChangePacket | None = MapChangePacket.decode(call.args)
    except ProtocolError as exc:
        packet, broken = None, f"a packet did not decode: {exc}"
    else:
        broken = ""
    mine = state.open is not None and state.open.owner == call.session.ident
    if command is ChangeCommand.START:
        if state.open is not None and now - state.open.last <= IDLE_DROP_S:
            return ()  # another client's set is open: ARIA ignores this one
        state.open = OpenSet(call.session.ident, now, broken=broken)
        _feed(state.open, packet)
        server.broadcast(MapChangesInProgress.DATA_NAME, MapChangesInProgress(True).encode())
        return ()
    if command is ChangeCommand.CONTINUE:
        if mine and state.open is not None:
            state.open.last = now
            if broken and not state.open.broken:
                state.open.broken = broken
            _feed(state.open, packet)
        return ()
    opened, state.open = (state.open, None) if mine else (None, state.open)
    if command is ChangeCommand.CANCEL:
        return _verdict(server, call, opened is not None)
    if opened is None:
        state.refused.append("a finish without a change set of this client's")
        return _verdict(server, call, False)
    _feed(opened, packet)
    if opened.broken:
        state.refused.append(opened.broken)
        return _verdict(server, call, False)
    _apply_later(server, call, opened.assembler.result())
    return ()


def _feed(opened: OpenSet, packet: MapChangePacket | None) -> None:
    if packet is None or opened.broken:
        return
    try:
        opened.assembler.feed(packet)
    except ProtocolError as exc:
        opened.broken = str(exc)


def _verdict(server: SimHost, call: Call, ok: bool) -> Iterable[Reply]:
    """The reply, then ``mapChangesInProgress`` 0 to everyone (ARIA's order)."""
    call.session.send(call.number, MapChangeReply(CHANGE_SUCCESS if ok else CHANGE_FAILED).encode())
    server.broadcast(MapChangesInProgress.DATA_NAME, MapChangesInProgress(False).encode())
    return ()


def _apply_later(server: SimHost, call: Call, changes: MapChangeSet) -> None:
    before = server.map
    state = state_of(server)
    if not before.present:
        state.refused.append("the simulator serves no map to change")
        _verdict(server, call, False)
        return
    path = before.path
    assert path is not None
    save = server.config.save_map_changes
    binary = server.datalist.number("getMapBinary")

    walls = server.world.obstacles

    def work() -> tuple[ServedMap, Obstacles]:
        data = before.data if before.data is not None else new_map()
        changed = apply_changes(data, changes)
        raw, header = result_bytes(changed, data, before.raw)
        mtime = int(time.time())
        check_ids(changes, raw, before.name, mtime)
        if save:
            _write_file(path, raw)
            mtime = int(os.stat(path).st_mtime)
        served = served_map(path, before.name, raw, changed, mtime, header)
        if binary is not None:  # framed here, not on the server's loop when the clients reload it
            served.binary_stream(binary)
        if same_geometry(data, changed):
            return served, walls  # objects only: the world's walls are the same
        return served, served.obstacles()

    def done(task: asyncio.Future[tuple[ServedMap, Obstacles]]) -> None:
        ok = False
        try:
            served, obstacles = task.result()
        except ChangeRefused as exc:
            state.refused.append(str(exc))
        except Exception:  # a bug must cost this change only
            log.exception("applying a map change failed")
            state.refused.append("the simulator failed to apply the change")
        else:
            if server.map is before:
                if save:
                    server.file_md5 = served.md5
                server.install_map(served, obstacles=obstacles)
                state.applied += 1
                ok = True
            else:
                state.refused.append("the map was replaced while the change was being applied")
        _verdict(server, call, ok)

    future = asyncio.get_running_loop().run_in_executor(None, work)
    future.add_done_callback(done)


def _write_file(path: Path, raw: bytes) -> None:
    """The served file replaced atomically (a reader never sees half a map)."""
    temp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
    try:
        with open(temp, "xb") as f:
            f.write(raw)
        os.replace(temp, path)
    finally:
        temp.unlink(missing_ok=True)


def _in_progress(call: Call) -> Iterable[Reply]:
    return ()  # ARIA registers it with no handler: broadcasts only


ROWS: tuple[Row, ...] = (
    (
        "processMapChanges",
        "Changes the map: a series of packets adding and deleting map objects, lines and points",
        "ubyte2: command (0 start, 1 continue, 2 finish, 3 cancel), two map ids, then what changes",
        "ubyte2: 10 when the change was applied, 0 when it was refused (answers a finish or cancel)",
        "Map",
        "RETURN_SINGLE|IDLE_PACKET",
    ),
    (
        "mapChangesInProgress",
        "Sent to every client when a client starts changing the map, and when it is done",
        "none",
        "ubyte: 1 while a change is being received and applied, 0 after it",
        "Map",
        "RETURN_NONE",
    ),
)

HANDLERS: dict[str, Handler] = {
    "processMapChanges": _process,
    "mapChangesInProgress": _in_progress,
}

__all__ = ["HANDLERS", "ROWS", "ChangerState", "state_of"]
