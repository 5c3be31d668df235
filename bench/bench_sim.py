"""What the simulator costs: serving many clients, rendering camera frames, updating the sonar.

* ``sim.cpu_per_sim_second.clients_{1,10,50}``: CPU seconds this process spends per simulated second
  while serving N logged-in clients, each subscribed to ``updateNumbers`` at 100 ms (10 Hz) and to
  ``updateStrings``/``getModeInfo`` broadcasts, with the robot driving (ratioDrive renewed every
  100 ms). Manual clock, 10 simulated seconds; the clients only drain their sockets, so the figure is
  the server's work (physics at 100 Hz, the 10 ms cycle, encoding and writing). Baseline: the same
  with the per-cycle payload cache switched off (every client gets its own encode).
* ``sim.camera_render.{320x240,640x480}``: one frame ray-cast and JPEG-encoded from a new pose
  (cache miss), on the office map. Baseline: the same frame again (the per-pose cache).
* ``sim.sonar_update``: the 16 sonar rays against the office map's walls from a new pose, and
  ``sim.sonar_update.columbia`` against ARIA's 63 k-point columbia map (points rasterised).
"""

from __future__ import annotations

import asyncio
import time
from pathlib import Path

from bench.common import Result, best_time
from rtmu.protocol.client_connection import ClientConnection, ClientState
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.camera import render_jpeg
from rtmu.sim.sonar import sonar_ranges

REPO = Path(__file__).resolve().parents[1]
OFFICE = REPO / "data" / "maps" / "office.map"
COLUMBIA = REPO.parent / "shared" / "aria-maps" / "columbia.map"
SIM_SECONDS = 10.0


class _Drain(asyncio.Protocol):
    """A client that logs in with the real codec, subscribes, then only counts bytes."""

    def __init__(self, subscribe: bool) -> None:
        self.conn = ClientConnection()
        self.subscribe = subscribe
        self.transport: asyncio.Transport | None = None
        self.ready = asyncio.get_running_loop().create_future()
        self.bytes = 0

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]

    def data_received(self, data: bytes) -> None:
        self.bytes += len(data)
        if self.ready.done():
            return
        self.conn.receive_data(data)
        if self.conn.state is ClientState.CONNECTED:
            if self.subscribe:
                self.conn.request("updateNumbers", 100)
                self.conn.request("updateStrings", -1)
                self.conn.request("getModeInfo", -1)
            self.ready.set_result(True)
        out = self.conn.data_to_send()
        if out and self.transport is not None:
            self.transport.write(out)


async def _serve(clients: int, cache: bool) -> float:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=OFFICE if OFFICE.exists() else None))
    await server.start()
    if not cache:
        server.cycle_cached = lambda key, make: make()  # type: ignore[method-assign]
    loop = asyncio.get_running_loop()
    protos = []
    for _ in range(clients):
        _, proto = await loop.create_connection(lambda: _Drain(True), "127.0.0.1", server.port)
        protos.append(proto)
    await asyncio.gather(*(p.ready for p in protos))
    await server.advance(0.5)
    drive = RatioDrive(40, 10, 100).encode()
    t0 = time.process_time()
    for _ in range(round(SIM_SECONDS / 0.1)):
        server.world.ratio_drive(*(float(v) for v in drive.split(b"\x00")[:3]))
        await server.advance(0.1)
    cpu = time.process_time() - t0
    for p in protos:
        p.transport.close()
    await server.stop()
    return cpu / SIM_SECONDS


def _camera(size: tuple[int, int]) -> tuple[float, float]:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=OFFICE if OFFICE.exists() else None))
    world = server.world
    x0, y0, _ = server.home
    step = [0]

    def fresh() -> None:
        step[0] += 1
        render_jpeg(world.camera.view(x0 + (step[0] % 200), y0, (step[0] * 7) % 360, size), 75)

    latest = render_jpeg(world.camera.view(x0, y0, 0.0, size), 75)

    def cached() -> None:
        len(latest)

    return best_time(fresh, repeat=3), best_time(cached, repeat=3)


def _sonar(path: Path | None) -> float:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=path))
    obstacles = server.world.obstacles
    x0, y0, _ = server.home
    step = [0]

    def once() -> None:
        step[0] += 1
        sonar_ranges(obstacles, x0 + step[0] % 300, y0, (step[0] * 13) % 360)

    return best_time(once, repeat=3)


def run() -> list[Result]:
    results: list[Result] = []
    for n in (1, 10, 50):
        fast = asyncio.run(_serve(n, cache=True))
        simple = asyncio.run(_serve(n, cache=False))
        results.append(Result(f"sim.cpu_per_sim_second.clients_{n}", fast, "s/s", simple))
    for size in ((320, 240), (640, 480)):
        miss, hit = _camera(size)
        results.append(Result(f"sim.camera_render.{size[0]}x{size[1]}", miss * 1000, "ms", hit * 1000))
    results.append(Result("sim.sonar_update", _sonar(OFFICE if OFFICE.exists() else None) * 1e6, "us"))
    if COLUMBIA.exists():
        results.append(Result("sim.sonar_update.columbia", _sonar(COLUMBIA) * 1e6, "us"))
    return results


if __name__ == "__main__":
    for r in run():
        print(r.as_json())
