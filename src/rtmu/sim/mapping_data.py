"""Scanning for a map in the simulator, as ARIA's ``ArServerHandlerMapping`` does (``ROWS`` + ``HANDLERS``).

``mappingStart NAME`` opens ``name.2d`` (lower case; ``.2d`` added unless the name holds it) in the
files folder and answers 0, or 1 while a scan runs, or 2 when the file cannot be opened; it then
broadcasts ``mappingStatusBroadcast`` with the *file* name. ``mappingEnd`` closes the log and answers a
``ubyte2`` 0 (a one-``byte`` 1 when no scan runs, as ARIA does), then broadcasts ``""``.
``mappingStatus`` and ``mappingStatusBroadcast`` name the scan (not the file) while one runs. The loop
commands put ``loop start TAG`` / ``loop stop TAG`` in the log at the robot's next look. Like ARIA's
handler, a scan refuses nothing else: the robot is driven as usual, and a scan outlives the client that
started it. ARIA writes wherever the name points (``../x`` or ``/tmp/x``); the simulator refuses such a
name with 2. The log itself: :mod:`.scanlog`.
"""

from __future__ import annotations

import asyncio
import contextlib
import weakref
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from rtmu.base.textsafe import visible
from rtmu.protocol.fields import FieldReader
from rtmu.protocol.payloads.mapping import (
    MAX_SCAN_NAME,
    MappingEndCode,
    MappingEndReply,
    MappingStartCode,
    MappingStartReply,
    MappingStatus,
    MappingStatusBroadcast,
    scan_file_name,
)

from .catalogue import Row
from .files_folder import disk, files_folder
from .handlers import Call, Handler, Reply
from .scanlog import ScanLog

if TYPE_CHECKING:
    from .context import SimHost

ROWS: tuple[Row, ...] = (
    ("mappingStart", "Starts a laser scan log for building a map", "string: scan name",
     "byte: 0 started, 1 a scan already runs, 2 could not start", "Mapping", "RETURN_SINGLE"),
    ("mappingEnd", "Ends the laser scan log", "none",
     "ubyte2: 0 ended, 2 could not move the file (byte: 1 when no scan runs)", "Mapping", "RETURN_SINGLE"),
    ("mappingStatus", "Names the scan running now", "none", "string: scan name, empty when none",
     "RobotInfo", "RETURN_SINGLE"),
    ("mappingStatusBroadcast", "Names the scan running now; also sent when one starts or ends", "none",
     "string: scan name (the file name when broadcast), empty when none", "RobotInfo", "RETURN_SINGLE"),
    ("mappingLoopStart", "Marks in the scan log that a loop starts here", "string: argumentToCommand", "none",
     "CustomCommands", "RETURN_NONE"),
    ("mappingLoopEnd", "Marks in the scan log that a loop ends here", "string: argumentToCommand", "none",
     "CustomCommands", "RETURN_NONE"),
)  # fmt: skip


@dataclass
class Scan:
    name: str
    """As ``mappingStatus`` reports it: the name asked for, in lower case."""
    file_name: str
    log: ScanLog


_SCANS: weakref.WeakKeyDictionary[SimHost, Scan] = weakref.WeakKeyDictionary()


def current_scan(server: SimHost) -> Scan | None:
    """The scan this simulator is writing, if any (tests read its log)."""
    return _SCANS.get(server)


def _bad_file_name(file_name: str) -> bool:
    """Where ARIA would write outside its folder, or a file nobody could list or fetch."""
    return (
        "/" in file_name or "\\" in file_name or file_name.startswith(".") or visible(file_name) != file_name
    )


def _broadcast_later(server: SimHost, name: str) -> None:
    """After the answer has gone, as ARIA broadcasts after replying."""
    payload = MappingStatusBroadcast(name).encode()
    asyncio.get_running_loop().call_soon(server.broadcast, MappingStatusBroadcast.DATA_NAME, payload)


def _start(call: Call) -> Iterable[Reply]:
    if call.server in _SCANS:
        return (MappingStartReply(MappingStartCode.ALREADY).encode(),)
    asked = FieldReader(call.args).string("scan name", default="")[:MAX_SCAN_NAME]
    file_name = scan_file_name(asked)
    if _bad_file_name(file_name):
        return (MappingStartReply(MappingStartCode.FAILED).encode(),)
    world = call.world
    try:
        log = ScanLog(files_folder(call.server).root / disk(file_name), world)
    except OSError:
        return (MappingStartReply(MappingStartCode.FAILED).encode(),)
    name = file_name if len(file_name) == len(asked) else file_name[: -len(".2d")]  # ARIA's lower-cased name
    _SCANS[call.server] = Scan(name, file_name, log)
    world.step_hooks.append(log.tick)
    log.tick()  # ARIA's first reading is taken at once
    _broadcast_later(call.server, file_name)
    return (MappingStartReply(MappingStartCode.STARTED).encode(),)


def _end(call: Call) -> Iterable[Reply]:
    scan = _SCANS.pop(call.server, None)
    if scan is None:
        return (MappingEndReply(MappingEndCode.NOT_MAPPING).encode(),)
    with contextlib.suppress(ValueError):
        call.world.step_hooks.remove(scan.log.tick)
    scan.log.close()
    _broadcast_later(call.server, "")
    return (MappingEndReply(MappingEndCode.ENDED).encode(),)


def _status(call: Call) -> Iterable[Reply]:
    scan = _SCANS.get(call.server)
    return (MappingStatus("" if scan is None else scan.name).encode(),)


def _loop(call: Call) -> Iterable[Reply]:
    scan = _SCANS.get(call.server)
    if scan is not None:
        words = " ".join(FieldReader(call.args).string("tag", default="").split())
        scan.log.tag(f"loop {'start' if call.name == 'mappingLoopStart' else 'stop'} {words}")
    return ()


HANDLERS: dict[str, Handler] = {
    "mappingStart": _start,
    "mappingEnd": _end,
    "mappingStatus": _status,
    "mappingStatusBroadcast": _status,
    "mappingLoopStart": _loop,
    "mappingLoopEnd": _loop,
}
