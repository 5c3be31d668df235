"""The Foxglove bridge (``rtmu bridge``): publish latency, its CPU, and how soon a drive stream's end stops.

The simulator (arena map, robot driving in circles) and a session run in this process; a
WebSocket client (``websockets``, speaking the Foxglove protocol) subscribes to every
channel the bridge advertises.

* ``bridge.pose_latency_ms_p50`` / ``_p95``: from the session publishing a robot update
  (the message's log time) to the client having the pose (same machine clock).
* ``bridge.cpu_pct_of_core``: CPU of this process (simulator, session, bridge, client)
  with the bridge and a subscribed client — baseline: the same without the bridge.
* ``bridge.stop_after_stream_ms_p50`` / ``_max``: ``--allow-drive``: a 10 Hz Twist stream
  drives, then stops; from its last message to the simulator's robot having zero ratios
  (the bridge's lease lives 220 ms; 10 trials).
"""

from __future__ import annotations

import json
import statistics
import struct
import threading
import time

from websockets.sync.client import connect

from bench.common import Result
from rtmu.client.runner import ClientRunner
from rtmu.package_data import project_map
from rtmu.recorder import topics
from rtmu.recorder.bridge import LEASE_TTL, Bridge
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target

ARENA = project_map("arena.map")
WINDOW = 10.0
TWIST = json.dumps({"linear": {"x": 0.5}, "angular": {"z": 0.0}}).encode()


class Client:
    """Subscribes to every channel; keeps the latency of each pose."""

    def __init__(self, url: str) -> None:
        opened = connect(url, subprotocols=["foxglove.sdk.v1"])  # type: ignore[list-item]
        self.ws = opened.__enter__()
        self.latencies: list[float] = []
        self.pose_sub: int | None = None
        self.channels: dict[str, int] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                frame = self.ws.recv(timeout=0.1)
            except TimeoutError:
                continue
            except Exception:
                return
            now = time.time_ns()
            if isinstance(frame, str):
                message = json.loads(frame)
                if message.get("op") == "advertise":
                    subs = []
                    for channel in message["channels"]:
                        sub = len(self.channels) + 1
                        self.channels[channel["topic"]] = sub
                        if channel["topic"] == topics.POSE:
                            self.pose_sub = sub
                        subs.append({"id": sub, "channelId": channel["id"]})
                    self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            elif frame[0] == 1:
                sub, log_time = struct.unpack_from("<IQ", frame, 1)
                if sub == self.pose_sub:
                    self.latencies.append((now - log_time) / 1e6)

    def publish_twists(self, hz: float, seconds: float) -> float:
        channel = {"id": 1, "topic": "/cmd_vel", "encoding": "json", "schemaName": "geometry_msgs/Twist"}
        self.ws.send(json.dumps({"op": "advertise", "channels": [channel]}))
        end = time.monotonic() + seconds
        while True:
            self.ws.send(struct.pack("<BI", 1, 1) + TWIST)
            sent = time.monotonic()
            if sent >= end:
                return sent  # the stream's last message
            time.sleep(1.0 / hz)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2)
        self.ws.__exit__(None, None, None)


def session(with_bridge: bool, drive: bool = False) -> tuple[SimThread, ClientRunner, Bridge | None]:
    sim = SimThread(SimConfig(port=0, map_path=ARENA, seed=4)).start()
    runner = ClientRunner(lease_ttl=LEASE_TTL)
    bridge = Bridge(port=0, lease=runner.lease if drive else None) if with_bridge else None
    if bridge is not None:
        runner.on_publish = bridge.published
        bridge.start()
    runner.start()
    runner.connect(Target("127.0.0.1", sim.port, auto_reconnect=False)).result(15)
    time.sleep(1.0)  # the map loads
    return sim, runner, bridge


def cpu(with_bridge: bool) -> tuple[float, list[float]]:
    sim, runner, bridge = session(with_bridge)
    client = Client(bridge.url) if bridge is not None else None
    try:
        time.sleep(1.0)
        c0, t0 = time.process_time(), time.monotonic()
        end = t0 + WINDOW
        while time.monotonic() < end:
            sim.call(lambda: sim.server.world.ratio_drive(40.0, 25.0, 60.0))  # type: ignore[union-attr]
            time.sleep(0.2)
        pct = (time.process_time() - c0) / (time.monotonic() - t0) * 100
        return pct, list(client.latencies) if client is not None else []
    finally:
        if client is not None:
            client.close()
        if bridge is not None:
            bridge.close()
        runner.close()
        sim.stop()


def stops(trials: int = 10) -> list[float]:
    sim, runner, bridge = session(True, drive=True)
    assert bridge is not None
    client = Client(bridge.url)  # a drive bridge: its URL carries the token
    out: list[float] = []
    try:
        for _ in range(trials):
            last = client.publish_twists(10.0, 1.0)
            while sim.snapshot().trans_ratio != 0:
                time.sleep(0.002)
                if time.monotonic() - last > 5:
                    raise RuntimeError("the bridge drive never stopped")
            out.append((time.monotonic() - last) * 1000)
            time.sleep(0.5)
    finally:
        client.close()
        bridge.close()
        runner.stop_and_wait(1.0)
        runner.close()
        sim.stop()
    return out


def run() -> list[Result]:
    base_cpu, _ = cpu(False)
    with_cpu, latencies = cpu(True)
    latencies.sort()
    stopped = sorted(stops())
    return [
        Result("bridge.pose_latency_ms_p50", statistics.median(latencies), "ms"),
        Result("bridge.pose_latency_ms_p95", latencies[int(0.95 * (len(latencies) - 1))], "ms"),
        Result("bridge.cpu_pct_of_core", with_cpu, "%", baseline=base_cpu),
        Result("bridge.stop_after_stream_ms_p50", statistics.median(stopped), "ms"),
        Result("bridge.stop_after_stream_ms_max", stopped[-1], "ms"),
    ]


if __name__ == "__main__":
    for r in run():
        print(r.as_json())
