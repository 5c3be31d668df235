"""The simulator for the video benchmark, in its own process (as a robot would be): a turning robot.

``python -m bench.video_server WxH HZ`` serves the office map with its camera at WxH, at most HZ new
frames per second, on a free loopback port, prints ``port N``, keeps the robot turning on the spot
(so every frame shows something new and is really rendered), and when its stdin closes prints
``cpu S`` — its own CPU seconds — and ends.
"""

from __future__ import annotations

import sys
import threading
import time

from rtmu.package_data import project_map
from rtmu.sim.config import SimConfig
from rtmu.sim.thread import SimThread


def main(argv: list[str]) -> int:
    w, h = (int(v) for v in argv[0].split("x"))
    hz = float(argv[1])
    office = project_map("office.map")
    cfg = SimConfig(port=0, map_path=office, camera_size=(w, h), camera_hz=hz, drive_timeout=0)
    sim = SimThread(cfg).start()
    assert sim.server is not None
    world = sim.server.world
    done = threading.Event()

    def keep_turning() -> None:  # a client connecting stops the robot: turn it again, twice a second
        while not done.wait(0.5):
            sim.call(lambda: world.ratio_drive(0, 25, 100))

    turner = threading.Thread(target=keep_turning, daemon=True)
    turner.start()
    cpu0 = time.process_time()
    print(f"port {sim.server.port}", flush=True)
    try:
        sys.stdin.read()
    finally:
        done.set()
        turner.join(2)
        print(f"cpu {time.process_time() - cpu0:.3f}", flush=True)
        sim.stop()
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
