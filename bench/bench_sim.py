"""What the simulator costs: serving many clients, rendering camera frames, updating the sonar.

* ``sim.cpu_per_sim_second.clients_{1,10,50}``: CPU seconds this process spends per simulated second
  while serving N logged-in clients, each subscribed to ``updateNumbers`` at 100 ms (10 Hz) and to
  ``updateStrings``/``getModeInfo`` broadcasts, with the robot driving (ratioDrive renewed every
  100 ms). Manual clock, 10 simulated seconds; the clients only drain their sockets, so the figure is
  the server's work (physics at 100 Hz, the 10 ms cycle, encoding and writing). Baseline: the same
  with the per-cycle payload cache switched off (every client gets its own encode).
* ``sim.camera_render.{320x240,640x480}``: one frame ray-cast and JPEG-encoded from a new pose, on
  the office map. Baseline: the same frame made the simple way — a Python loop over the columns, one
  ray cast and one column of pixels at a time (checked to give the same picture), then the same JPEG
  encoding.
* ``sim.status_rate_under_camera_load``: the rate (Hz) at which a client subscribed to
  ``updateNumbers`` every 100 ms receives it from a real-time simulator while another client asks
  for a 640x480 picture every 10 ms cycle and the robot turns (a new view every cycle), measured over
  4 s of wall time; ``sim.cycles_per_second_under_camera_load`` (the server should keep 100) and
  ``sim.frames_rendered_per_second_under_camera_load`` (ARIA's video forwarder: about 10) in the
  same run. The server runs on its own thread; both clients are light (the picture client only
  counts bytes), so the figures are the server's.
* ``sim.sonar_update``: the 16 sonar rays against the office map's walls from a new pose, and
  ``sim.sonar_update.columbia`` against ARIA's 63 k-point columbia map (points rasterised).
"""

from __future__ import annotations

import asyncio
import math
import time
from pathlib import Path

import numpy as np

from bench.common import Result, best_time
from rtmu.package_data import project_map
from rtmu.protocol.client_connection import ClientConnection, ClientState
from rtmu.protocol.events import DataReceived
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim import SimConfig, SimServer, SimThread
from rtmu.sim.camera import (
    CAMERA_HEIGHT_MM,
    CAMERA_X_MM,
    VIEW_RANGE_MM,
    WALL_HEIGHT_MM,
    PanTiltZoom,
    View,
    encode_jpeg,
    render_jpeg,
    render_view,
)
from rtmu.sim.sonar import sonar_ranges

REPO = Path(__file__).resolve().parents[1]
OFFICE = project_map("office.map")
COLUMBIA = REPO / "tests" / "data" / "aria-maps" / "columbia.map"
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


def _render_column_by_column(view: View) -> np.ndarray:
    """The renderer written the simple way: one ray and one column of pixels per loop iteration."""
    w, h = view.size
    fov = PanTiltZoom(view.pan, view.tilt, view.zoom).fov_deg
    f = (w / 2) / math.tan(math.radians(fov) / 2)
    t = math.radians(view.th)
    cx, cy = view.x + CAMERA_X_MM * math.cos(t), view.y + CAMERA_X_MM * math.sin(t)
    horizon = h / 2 + f * math.tan(math.radians(view.tilt))
    rows = np.arange(h, dtype=np.float64)
    sky = np.array([170.0, 180.0, 195.0])
    floor = np.array([95.0, 85.0, 75.0])
    background = np.where(
        (rows < horizon)[:, None],
        sky * (0.75 + 0.25 * np.clip((horizon - rows) / h, 0.0, 1.0))[:, None],
        floor * (0.55 + 0.9 * np.clip((rows - horizon) / h, 0.0, 1.0))[:, None],
    )
    img = np.empty((h, w, 3), dtype=np.float64)
    for col in range(w):
        offset = math.atan((w / 2 - col - 0.5) / f)
        angle = np.array([math.radians(view.th + view.pan) + offset])
        dist = float(view.obstacles.cast(cx, cy, angle, VIEW_RANGE_MM)[0])
        column = background.copy()
        if math.isfinite(dist):
            perp = max(dist * math.cos(offset), 1.0)
            top = horizon - f * (WALL_HEIGHT_MM - CAMERA_HEIGHT_MM) / perp
            bottom = horizon + f * CAMERA_HEIGHT_MM / perp
            wall = (rows >= top) & (rows <= bottom)
            light = min(max(1.15 - perp / 9000.0, 0.25), 1.0)
            column[wall] = np.array([225.0, 205.0, 170.0]) * light
            column[wall & (rows > bottom - max((bottom - top) * 0.06, 1.0))] *= 0.6
        img[:, col] = column
    return np.clip(img, 0, 255).astype(np.uint8)


def _camera(size: tuple[int, int]) -> tuple[float, float]:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=OFFICE if OFFICE.exists() else None))
    world = server.world
    x0, y0, _ = server.home
    step = [0]

    def view() -> View:
        step[0] += 1
        return world.camera.view(x0 + (step[0] % 200), y0, (step[0] * 7) % 360, size)

    sample = view()
    difference = np.abs(render_view(sample).astype(int) - _render_column_by_column(sample)).mean()
    assert difference < 1.0, f"the column-by-column baseline draws another picture ({difference:.2f})"
    fast = best_time(lambda: render_jpeg(view(), 75), repeat=3)
    simple = best_time(lambda: encode_jpeg(_render_column_by_column(view()), 75), repeat=3)
    return fast, simple


class _Client(asyncio.Protocol):
    """Logs in with the real codec, asks for its data, then counts status packets (or only bytes)."""

    def __init__(self, requests: list[tuple[str, int | None]], count_status: bool) -> None:
        self.conn = ClientConnection()
        self.requests = requests
        self.count_status = count_status
        self.transport: asyncio.Transport | None = None
        self.ready = asyncio.get_running_loop().create_future()
        self.counting = False
        self.status = 0
        self.bytes = 0

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]

    def data_received(self, data: bytes) -> None:
        self.bytes += len(data)
        if self.ready.done() and not self.count_status:
            return
        for event in self.conn.receive_data(data):
            if self.counting and isinstance(event, DataReceived) and event.name == "updateNumbers":
                self.status += 1
        if self.conn.state is ClientState.CONNECTED and not self.ready.done():
            for name, interval in self.requests:
                if interval is None:
                    self.conn.request_once(name)
                else:
                    self.conn.request(name, interval)
            self.ready.set_result(True)
        out = self.conn.data_to_send()
        if out and self.transport is not None:
            self.transport.write(out)


async def _camera_load(seconds: float = 4.0) -> tuple[float, float, float]:
    cfg = SimConfig(port=0, map_path=OFFICE if OFFICE.exists() else None, drive_timeout=0)
    with SimThread(cfg) as sim:
        server = sim.server
        assert server is not None
        loop = asyncio.get_running_loop()
        _, watcher = await loop.create_connection(
            lambda: _Client([("updateNumbers", 100)], True), "127.0.0.1", sim.port
        )
        _, hammer = await loop.create_connection(
            lambda: _Client([("SimulatorVideo640x480", None), ("getPictureCam1", 10)], False),
            "127.0.0.1",
            sim.port,
        )
        await asyncio.gather(watcher.ready, hammer.ready)
        sim.call(lambda: server.world.ratio_drive(0, 60, 100))  # turn on the spot, for good
        await asyncio.sleep(0.5)
        cycles, renders = server.cycles, server.video.renders
        watcher.counting = True
        t0 = time.monotonic()
        await asyncio.sleep(seconds)
        watcher.counting = False
        elapsed = time.monotonic() - t0
        cycles, renders = server.cycles - cycles, server.video.renders - renders
        for p in (watcher, hammer):
            if p.transport is not None:
                p.transport.close()
    return watcher.status / elapsed, cycles / elapsed, renders / elapsed


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
        fast, simple = _camera(size)
        results.append(Result(f"sim.camera_render.{size[0]}x{size[1]}", fast * 1000, "ms", simple * 1000))
    status_hz, cycles_per_s, frames_per_s = asyncio.run(_camera_load())
    results.append(Result("sim.status_rate_under_camera_load", status_hz, "Hz"))
    results.append(Result("sim.cycles_per_second_under_camera_load", cycles_per_s, "1/s"))
    results.append(Result("sim.frames_rendered_per_second_under_camera_load", frames_per_s, "1/s"))
    results.append(Result("sim.sonar_update", _sonar(OFFICE if OFFICE.exists() else None) * 1e6, "us"))
    if COLUMBIA.exists():
        results.append(Result("sim.sonar_update.columbia", _sonar(COLUMBIA) * 1e6, "us"))
    return results


if __name__ == "__main__":
    for r in run():
        print(r.as_json())
