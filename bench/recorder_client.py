"""The client side of ``bench_recorder``: the window's client core driving in circles, recorded or not.

``python -m bench.recorder_client PORT SECONDS CAMERA_HZ OUT`` (OUT ``-``: recording off)
connects, drives a slow circle (the lease renewed at 10 Hz as the window does, so the
pose, status and sonar change every update), asks for a camera picture CAMERA_HZ times
a second, and after SECONDS prints one JSON line: this process's CPU seconds (every
thread: network loop, recorder's writer, foxglove-sdk), the pictures received, the
network loop's worst lag, and the recording's size, items and drops.
"""

from __future__ import annotations

import json
import resource
import sys
import threading
import time
from pathlib import Path

from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.recorder import Recorder, RecorderConfig
from rtmu.values.intents import LoadMap, RequestPicture
from rtmu.values.target import Target

CIRCLE = DriveRatios(30.0, 20.0, 40.0)


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def main() -> int:
    port, seconds, camera_hz, out = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    recorder = None
    if out != "-":
        path = Path(out)
        recorder = Recorder(RecorderConfig(path.parent, path=path, keep_days=0))
    runner = ClientRunner(config=SessionConfig(), opener=recorder.opener() if recorder else None)
    if recorder is not None:
        recorder.attach(runner)
    runner.start()
    runner.connect(Target("127.0.0.1", port)).result(10)
    runner.send(LoadMap()).result(30)  # the map is in the file once, before the measured part
    time.sleep(1.5)  # …and flushed: the measured part's bytes are what a longer session adds
    start_bytes = recorder.recordings[0].path.stat().st_size if recorder is not None else 0
    pictures = picture_bytes = 0
    worst_lag = 0.0
    ending = threading.Event()

    def drive() -> None:  # what the window's 10 Hz timer does while a key is held
        runner.lease.grant(CIRCLE)
        while not ending.wait(0.1):
            if not runner.lease.renew():
                runner.lease.grant(CIRCLE)

    driver = threading.Thread(target=drive, daemon=True)
    driver.start()
    cpu0, t0 = cpu_seconds(), time.monotonic()
    next_picture = t0
    while (now := time.monotonic()) < t0 + seconds:
        if camera_hz > 0 and now >= next_picture:
            try:
                picture_bytes += len(runner.send(RequestPicture()).result(2.0).jpeg)
                pictures += 1
            except Exception:
                pass
            next_picture += 1.0 / camera_hz
        worst_lag = max(worst_lag, runner.loop_lag() or 0.0)
        time.sleep(max(0.0, min(0.02, next_picture - time.monotonic())))
    wall, cpu = time.monotonic() - t0, cpu_seconds() - cpu0
    ending.set()
    driver.join(1)
    runner.close()
    report = {
        "cpu_s": cpu,
        "wall_s": wall,
        "pictures": pictures,
        "picture_bytes": picture_bytes,
        "max_loop_lag_s": worst_lag,
    }
    if recorder is not None:
        recorder.close()
        recording = recorder.recordings[0]
        report |= {
            "bytes": recording.path.stat().st_size - start_bytes,
            "items": recording.written_items,
            "dropped": recording.dropped,
            "stopped": recording.stopped,
        }
    print(json.dumps(report), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
