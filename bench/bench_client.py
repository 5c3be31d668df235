"""What the client core costs in time: key press → packet, status packet → model callback, idle CPU.

* ``client.drive_intent_latency.{p50,p99}`` (ms): from the UI thread granting the drive lease (a
  key press) to the ``ratioDrive`` packet being decoded by the server, on loopback. Path: lease
  → ``call_soon_threadsafe`` wake-up → session heart → governor → socket. Baseline: the simple way,
  a blocking ``sendall`` of a ready-made packet from the calling thread on its own logged-in
  connection (no thread hop, no lease).
* ``client.status_to_model_latency.{p50,p99}`` (ms): from a status packet leaving the server
  (just before its ``write``) to the model's change callback on the UI thread (a thread draining
  the ``post`` queue, as GLib's main loop would). Baseline: the same packet reaching the session's
  publish tap on the network thread (decode + change check, no hop to the UI).
* ``client.idle_cpu`` (% of one core): the whole client process (network thread + a UI thread)
  while connected to ``rtmu sim`` in another process, status at 10 Hz, robot idle, 5 s.

Servers listen on 127.0.0.1 only. Targets: p99 under 5 ms for both latencies, idle CPU under 2 %.
"""

from __future__ import annotations

import asyncio
import contextlib
import queue
import re
import socket
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from bench.common import Result
from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import Phase, RobotModel
from rtmu.protocol.client_connection import ClientConnection, ClientState
from rtmu.protocol.datalist import DataList
from rtmu.protocol.events import RequestOnce, RequestReceived
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.drive import RatioDrive, SafeDrive
from rtmu.protocol.payloads.robot import UpdateNumbers, UpdateStrings
from rtmu.protocol.server_connection import ServerConnection
from rtmu.values.state import RobotChanged, StateChange
from rtmu.values.target import Target

DRIVE_TRIALS = 400
STATUS_SAMPLES = 600
STATUS_INTERVAL_MS = 10
IDLE_SECONDS = 5.0

SPECS = [
    ("updateNumbers", "", "", "", "RobotInfo", "RETURN_SINGLE"),
    ("updateStrings", "", "", "", "RobotInfo", "RETURN_SINGLE"),
    ("getSafeDrive", "", "", "", "Movement", "RETURN_SINGLE"),
    ("ratioDrive", "", "", "", "Movement", "RETURN_NONE"),
    ("stop", "", "", "", "Stop", "RETURN_NONE"),
]


class _TimingServer:
    """A minimal ArNetworking server on its own thread that timestamps what it sends and receives."""

    def __init__(self) -> None:
        self.datalist = DataList.build(SPECS)
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.port = 0
        self.sent_at: dict[int, float] = {}
        """status x → perf_counter just before the write."""
        self.on_drive: Callable[[RatioDrive, float], None] | None = None
        self.on_stop: Callable[[float], None] | None = None
        self._x = 0

    def start(self) -> _TimingServer:
        self.thread.start()
        asyncio.run_coroutine_threadsafe(self._start(), self.loop).result(5)
        return self

    async def _start(self) -> None:
        server = await asyncio.start_server(self._serve, "127.0.0.1", 0)
        self.port = server.sockets[0].getsockname()[1]

    def close(self) -> None:
        async def cancel() -> None:
            tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for t in tasks:
                t.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)

        with contextlib.suppress(Exception):
            asyncio.run_coroutine_threadsafe(cancel(), self.loop).result(5)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5)

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        conn = ServerConnection(self.datalist)
        writer.write(conn.data_to_send())
        tasks: list[asyncio.Task[None]] = []
        try:
            while data := await reader.read(65536):
                now = time.perf_counter()
                for ev in conn.receive_data(data):
                    if isinstance(ev, RequestOnce):
                        if ev.name == "ratioDrive" and self.on_drive is not None:
                            self.on_drive(RatioDrive.decode(ev.args), now)
                        elif ev.name == "stop" and self.on_stop is not None:
                            self.on_stop(now)
                        elif ev.name == "getSafeDrive":
                            conn.send_data("getSafeDrive", SafeDrive(True).encode())
                    elif isinstance(ev, RequestReceived) and ev.new:
                        if ev.name == "updateStrings":
                            conn.send_data("updateStrings", UpdateStrings("Stopped", "Stop", "").encode())
                        elif ev.name == "updateNumbers":
                            tasks.append(asyncio.create_task(self._status(conn, writer, ev.interval_ms)))
                writer.write(conn.data_to_send())
        except (ConnectionError, asyncio.CancelledError):
            pass
        finally:
            for t in tasks:
                t.cancel()
            writer.close()

    async def _status(self, conn: ServerConnection, writer: asyncio.StreamWriter, interval_ms: int) -> None:
        while True:
            self._x += 1
            conn.send_data("updateNumbers", UpdateNumbers(12.5, self._x, 0, 0, 0, 0, 0, 20).encode())
            data = conn.data_to_send()
            self.sent_at[self._x] = time.perf_counter()
            writer.write(data)
            await asyncio.sleep(interval_ms / 1000.0)


class _UiThread:
    """A stand-in for the GTK main loop: runs posted callables one after another."""

    def __init__(self) -> None:
        self.q: queue.Queue[Callable[[], None] | None] = queue.Queue()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def post(self, fn: Callable[[], None]) -> None:
        self.q.put(fn)

    def _run(self) -> None:
        while (fn := self.q.get()) is not None:
            fn()

    def close(self) -> None:
        self.q.put(None)
        self.thread.join(5)


def _ms(values: list[float]) -> tuple[float, float]:
    values = sorted(values)
    p50 = statistics.median(values) * 1000.0
    p99 = values[min(len(values) - 1, round(0.99 * (len(values) - 1)))] * 1000.0
    return p50, p99


def _connected_runner(
    port: int, model: RobotModel, post: Callable[[Callable[[], None]], Any], **cfg: Any
) -> ClientRunner:
    runner = ClientRunner(model, post=post, config=SessionConfig(fetch_map=False, **cfg)).start()
    runner.connect(Target("127.0.0.1", port)).result(10)
    deadline = time.monotonic() + 10
    while model.connection.value.phase is not Phase.CONNECTED:
        if time.monotonic() > deadline:
            raise RuntimeError("the client did not connect")
        time.sleep(0.01)
    return runner


def drive_latency() -> list[Result]:
    server = _TimingServer().start()
    ui = _UiThread()
    model = RobotModel()
    runner = _connected_runner(server.port, model, ui.post)
    got = threading.Event()
    stopped = threading.Event()
    arrival: dict[str, Any] = {}

    def on_drive(r: RatioDrive, t: float) -> None:
        if r.moving and arrival.get("want") == r.trans:
            arrival["t"] = t
            got.set()

    def on_stop(t: float) -> None:
        stopped.set()

    server.on_drive, server.on_stop = on_drive, on_stop
    ours: list[float] = []
    try:
        time.sleep(0.2)
        for i in range(DRIVE_TRIALS):
            trans = float(10 + i % 90)
            arrival["want"] = trans
            got.clear()
            stopped.clear()
            t0 = time.perf_counter()
            runner.lease.grant(DriveRatios(trans, 0.0, 50.0))
            if not got.wait(2):
                raise RuntimeError("ratioDrive never arrived")
            ours.append(arrival["t"] - t0)
            runner.lease.release()
            stopped.wait(2)
            time.sleep(0.002)
    finally:
        runner.close()
        ui.close()
    # Baseline: a logged-in blocking socket, one sendall of a ready packet per trial.
    simple = _simple_send_latency(server, got, arrival)
    server.close()
    p50, p99 = _ms(ours)
    b50, b99 = _ms(simple)
    return [
        Result("client.drive_intent_latency.p50", p50, "ms", b50),
        Result("client.drive_intent_latency.p99", p99, "ms", b99),
    ]


def _simple_send_latency(server: _TimingServer, got: threading.Event, arrival: dict[str, Any]) -> list[float]:
    conn = ClientConnection()
    sock = socket.create_connection(("127.0.0.1", server.port), timeout=5)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    try:
        while conn.state is not ClientState.CONNECTED:
            conn.receive_data(sock.recv(65536))
            sock.sendall(conn.data_to_send())
        number = conn.datalist.number("ratioDrive")
        assert number is not None
        times: list[float] = []
        for i in range(DRIVE_TRIALS):
            trans = float(10 + i % 90)
            packet = encode_packet(number, RatioDrive(trans, 0.0, 50.0).encode())
            arrival["want"] = trans
            got.clear()
            t0 = time.perf_counter()
            sock.sendall(packet)
            if not got.wait(2):
                raise RuntimeError("baseline ratioDrive never arrived")
            times.append(arrival["t"] - t0)
        return times
    finally:
        sock.close()


def status_latency() -> list[Result]:
    server = _TimingServer().start()
    ui = _UiThread()
    model = RobotModel()
    to_model: list[float] = []
    to_tap: list[float] = []
    done = threading.Event()

    def on_robot(old: Any, new: Any) -> None:
        t = time.perf_counter()
        sent = server.sent_at.get(int(new.x))
        if sent is not None and len(to_model) < STATUS_SAMPLES:
            to_model.append(t - sent)
            if len(to_model) >= STATUS_SAMPLES:
                done.set()

    def tap(change: StateChange) -> None:
        if isinstance(change, RobotChanged):
            sent = server.sent_at.get(int(change.value.x))
            if sent is not None:
                to_tap.append(time.perf_counter() - sent)

    model.robot.observe(on_robot)
    runner = ClientRunner(
        model, post=ui.post, config=SessionConfig(fetch_map=False, status_interval_ms=STATUS_INTERVAL_MS)
    )
    runner.on_publish = tap
    runner.start()
    try:
        runner.connect(Target("127.0.0.1", server.port)).result(10)
        time.sleep(0.3)
        to_model.clear()
        to_tap.clear()
        if not done.wait(STATUS_SAMPLES * STATUS_INTERVAL_MS / 1000.0 * 4 + 5):
            raise RuntimeError("not enough status samples")
    finally:
        runner.close()
        ui.close()
        server.close()
    p50, p99 = _ms(to_model)
    b50, b99 = _ms(to_tap[: len(to_model)])
    return [
        Result("client.status_to_model_latency.p50", p50, "ms", b50),
        Result("client.status_to_model_latency.p99", p99, "ms", b99),
    ]


def idle_cpu() -> list[Result]:
    sim = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert sim.stdout is not None
        line = sim.stdout.readline()
        match = re.search(r"127\.0\.0\.1:(\d+)", line)
        if match is None:
            raise RuntimeError(f"the simulator did not say its port: {line!r}")
        ui = _UiThread()
        model = RobotModel()
        runner = _connected_runner(int(match.group(1)), model, ui.post)
        try:
            time.sleep(1.0)  # map, infos, first pings
            c0, w0 = time.process_time(), time.perf_counter()
            time.sleep(IDLE_SECONDS)
            cpu = (time.process_time() - c0) / (time.perf_counter() - w0) * 100.0
        finally:
            runner.close()
            ui.close()
    finally:
        sim.terminate()
        with contextlib.suppress(subprocess.TimeoutExpired):
            sim.wait(5)
        if sim.poll() is None:
            sim.kill()
    return [Result("client.idle_cpu", cpu, "% of a core")]


def run() -> list[Result]:
    return [*drive_latency(), *status_latency(), *idle_cpu()]


if __name__ == "__main__":
    for r in run():
        base = f"  (baseline {r.baseline:.3f})" if r.baseline is not None else ""
        print(f"{r.name:40s} {r.value:10.3f} {r.unit}{base}")
