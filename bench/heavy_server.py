"""A server sending the heaviest well-formed data, in its own process, reporting the drive packets.

``python -m bench.heavy_server KIND`` (``drawings``, ``frames``, ``popups`` or ``plain``: one of
``tests/client/heavy_servers.py``, or the ordinary scripted server) on a free loopback port:
prints ``port N``, then ``drive T TRANS ROT`` / ``stop T`` per drive packet as :mod:`bench.soak_server`
does (``T``: ``time.monotonic()``, one clock for every process). Its own process, so the flood it
sends never competes with the client for one interpreter lock.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from client.heavy_servers import big_frame_server, drawing_flood_server, popup_storm_server  # noqa: E402
from client.servers import ServerSide, ServerThread, TestServer  # noqa: E402
from rtmu.protocol.payloads.drive import RatioDrive  # noqa: E402

KINDS = {
    "drawings": drawing_flood_server,
    "frames": big_frame_server,
    "popups": popup_storm_server,
    "plain": TestServer,
}


def main() -> int:
    server = KINDS[sys.argv[1]]()

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
        sys.stdin.read()  # until the bench closes our stdin
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
