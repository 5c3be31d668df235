"""Servers that send the heaviest well-formed data a server may send, as fast as the link takes it.

Scripted :class:`~tests.client.servers.TestServer` s (real loopback sockets, the project's codec)
beside the ordinary robot data (status at the rate asked, ``ratioDrive`` and ``stop`` heard):

* :func:`drawing_flood_server` — 256 drawings of 3 998 points (the most one packet holds), each
  sent again every 1 ms whatever period was asked, paced only by the socket (``drain``), the
  points shifting from one sample to the next;
* :func:`big_frame_server` — every picture a 632-byte JPEG that declares 4096×4096 pixels (a full
  50 MB decode each), answered at once, again and again;
* :func:`popup_storm_server` — 200 popups a second, each carrying 31.8 KB of text.

Nothing here is malformed: a client must stay responsive by budgeting what it does with it.

:func:`main` runs one in a process of its own (so its flood never competes with the client for
one interpreter lock): ``KIND`` is ``drawings``, ``frames``, ``popups`` or ``plain``; it prints
``port N``, then ``drive T TRANS ROT`` / ``stop T`` for every drive packet it hears (``T``:
``time.monotonic()``, one clock for every process), until its stdin closes.
"""

from __future__ import annotations

import asyncio
import contextlib
import io
import itertools
import subprocess
import sys
import threading
import time
from pathlib import Path

from rtmu.protocol.events import RequestReceived
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.drawings import MAX_POINTS, Drawing, DrawingListPacket, DrawingPoints
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.popup import PopupCreate

from .servers import SPECS, ServerSide, ServerThread, TestServer

FLOOD_DRAWINGS = 256
FLOOD_PERIOD = 0.001
POPUPS_PER_S = 200
POPUP_TEXT = 31_800
FLOOD_TASK = "(flood)"
TESTS = Path(__file__).resolve().parents[1]


def _row(name: str, returns: str = "RETURN_SINGLE") -> tuple[str, str, str, str, str, str]:
    return (name, "", "none", "drawing", "SensorInfo", returns)


class _FloodServer(TestServer):
    """A :class:`TestServer` that, once a client asks for one of its ``flooded`` data (periodic or
    broadcast), sends it again every ``period`` s whatever was asked, paced by the socket only (it
    waits for the client to read, so it cannot outgrow its own memory)."""

    def __init__(self, specs: list[tuple[str, str, str, str, str, str]], flooded: set[str], period: float):
        super().__init__(specs)
        self.flooded = flooded
        self.period = period
        self.sent = 0
        self._asked: dict[int, dict[str, bytes]] = {}

    def _handle(self, side: ServerSide, event: object) -> None:
        super()._handle(side, event)
        if isinstance(event, RequestReceived) and event.name in self.flooded:
            old = side.subs.pop(event.name, None)
            if old is not None:
                old.cancel()
            asked = self._asked.setdefault(id(side), {})
            asked[event.name] = event.args
            if len(asked) == 1:  # one sender per connection sends every flooded data asked for
                side.subs[FLOOD_TASK] = asyncio.get_running_loop().create_task(self._flood(side, asked))

    async def _flood(self, side: ServerSide, asked: dict[str, bytes]) -> None:
        while True:
            await asyncio.sleep(self.period)
            for name, args in list(asked.items()):
                self.reply(side, name, args)
                self.sent += 1
            with contextlib.suppress(ConnectionError):
                await side.writer.drain()


def drawing_flood_server(count: int = FLOOD_DRAWINGS, period: float = FLOOD_PERIOD) -> _FloodServer:
    drawings = [
        Drawing(f"flood{i:03d}", "polyDots", 0xFF00FF, 3, 80 + i % 20, 50, 0, "DefaultOn")
        for i in range(count)
    ]
    specs = [*SPECS, ("getDrawingList", "drawings", "none", "list", "SensorInfo", "RETURN_UNTIL_EMPTY")]
    specs += [_row(d.name) for d in drawings]
    server = _FloodServer(specs, {d.name for d in drawings}, period)
    listing = [DrawingListPacket(d).encode() for d in drawings] + [DrawingListPacket(None).encode()]

    def sample(k: int) -> bytes:
        points = tuple((1000 + i % 400 * 5 + k, 2000 + i // 400 * 50) for i in range(MAX_POINTS))
        return DrawingPoints(points).encode()

    samples = [sample(k) for k in range(8)]  # in turn: a client cannot skip one as "the same again"
    turn = itertools.cycle(samples)
    server.handlers["getDrawingList"] = lambda s, a: listing
    for d in drawings:
        server.handlers[d.name] = lambda s, a: [next(turn)]
    return server


def big_jpeg(side: int = 4096) -> bytes:
    """A 632-byte JPEG whose header declares ``side``×``side`` pixels (its data is cut short)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.new("RGB", (16, 16), (90, 120, 200)).save(buf, "JPEG", quality=50)
    small = bytearray(buf.getvalue())
    sof = small.find(b"\xff\xc0")
    small[sof + 5 : sof + 9] = side.to_bytes(2, "big") + side.to_bytes(2, "big")
    return bytes(small)


def big_frame_server(side: int = 4096) -> TestServer:
    server = TestServer()
    frame = FieldWriter().ubyte2(side).ubyte2(side).bytes() + big_jpeg(side)
    server.handlers["getPictureCam1"] = lambda s, a: [frame]
    return server


def popup_storm_server(per_second: int = POPUPS_PER_S, text: int = POPUP_TEXT) -> _FloodServer:
    specs = [*SPECS, ("popupCreate", "popup", "none", "popup", "Popups", "RETURN_SINGLE")]
    specs += [("popupClose", "popup closed", "none", "id text", "Popups", "RETURN_SINGLE")]
    specs += [("popupClicked", "clicked", "id button", "none", "Popups", "RETURN_NONE")]
    server = _FloodServer(specs, {"popupCreate"}, 1.0 / per_second)
    counter = iter(range(1, 1 << 31))
    words = ("storm " * (text // 6 + 1))[:text]

    def create(side: ServerSide, args: bytes) -> list[bytes]:
        n = next(counter)
        popup = PopupCreate(n, "", f"Storm {n}", words, 0, ("OK", "", ""), 0, 0)
        return [popup.encode()]

    server.handlers["popupCreate"] = create
    return server


def main(kind: str) -> int:
    """Serve one kind of flood (see the module notes) until stdin closes."""
    makers = {"drawings": drawing_flood_server, "frames": big_frame_server, "popups": popup_storm_server}
    server = makers[kind]() if kind in makers else TestServer()

    def tap(side: ServerSide, name: str, args: bytes) -> None:
        now = time.monotonic()
        if name == "ratioDrive":
            r = RatioDrive.decode(args)
            print(f"drive {now:.6f} {r.trans:g} {r.rot:g}", flush=True)
        elif name == "stop":
            print(f"stop {now:.6f}", flush=True)

    server.on_once = tap
    with ServerThread(server):
        print(f"port {server.port}", flush=True)
        sys.stdin.read()
    return 0


class FloodProcess:
    """:func:`main` (``kind``) in a process of its own — a robot's server is never in the client's
    process, and an in-process flood would take the client's interpreter lock; the drive packets it
    reports, on the shared monotonic clock."""

    def __init__(self, kind: str) -> None:
        code = f"import sys; sys.path.insert(0, {str(TESTS)!r}); from client.heavy_servers import main; "
        code += f"main({kind!r})"
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        )
        assert self.proc.stdout is not None
        word, port = self.proc.stdout.readline().split()
        assert word == "port"
        self.port = int(port)
        self.events: list[tuple[str, float]] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            parts = line.split()
            if parts and parts[0] in ("drive", "stop"):
                stop = parts[0] == "stop" or (float(parts[2]) == 0 and float(parts[3]) == 0)
                self.events.append(("stop" if stop else "drive", float(parts[1])))

    def since(self, kind: str, t0: float) -> list[float]:
        """When each ``kind`` packet (``drive`` or ``stop``) came at or after ``t0``."""
        return [t for k, t in list(self.events) if k == kind and t >= t0]

    def close(self) -> None:
        from bench.common import end_by_stdin  # here: the served process imports this module without bench

        end_by_stdin(self.proc)
