"""A light driving process for ``bench_safety``: the window's client core without GTK.

``python -m bench.safety_parent PORT GUARDIAN [SOAK_SECONDS]``, GUARDIAN one of ``shared`` (the
window's: a fleet's one :class:`~rtmu.guardian.shared.SharedGuardian`, armed for the selected robot),
``own`` (``rtmu bridge --allow-drive``'s: the session's own, ``SessionConfig(guardian=True)``) or
``none``: runner + lease (+ guardian), a thread that does what the window's timers do (renew the
lease every 100 ms, beat for the guardian every 40 ms), a held drive once the guardian is armed;
prints ``driving``. With SOAK_SECONDS it changes direction every 2 s for that long, then closes cleanly.
"""

from __future__ import annotations

import sys
import threading
import time

from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.fleet.sessions import Fleet
from rtmu.guardian.handle import BEAT_PERIOD
from rtmu.guardian.shared import SharedGuardian
from rtmu.values.target import Target

RATIOS = (DriveRatios(30.0, 20.0, 40.0), DriveRatios(30.0, -20.0, 40.0))


def main() -> int:
    port, mode = int(sys.argv[1]), sys.argv[2]
    soak = float(sys.argv[3]) if len(sys.argv) > 3 else None
    guardian = mode != "none"
    fleet: Fleet | None = None
    if mode == "shared":
        fleet = Fleet(guardian=SharedGuardian())
        runner = fleet.open(config=SessionConfig(fetch_map=False), guardian=fleet.guardian).runner
    else:
        runner = ClientRunner(config=SessionConfig(fetch_map=False, guardian=mode == "own")).start()
    runner.connect(Target("127.0.0.1", port)).result(10)
    deadline = time.monotonic() + 10
    while guardian and time.monotonic() < deadline:  # drive once the guardian is armed (or gave up)
        runner.sync()
        seat = runner.session.guardian if runner.session else None
        if seat is None or seat.waiting_reason() is None:
            break
        time.sleep(0.02)

    def ui() -> None:
        ticks = 0
        while True:
            runner.ui_heartbeat()
            if ticks % 2 == 0:
                runner.lease.renew()
            ticks += 1
            time.sleep(BEAT_PERIOD)

    threading.Thread(target=ui, daemon=True).start()
    runner.lease.grant(RATIOS[0])
    print("driving", flush=True)
    if soak is None:
        threading.Event().wait()
        return 0
    end = time.monotonic() + soak
    turn = 0
    while time.monotonic() < end:
        time.sleep(2.0)
        turn += 1
        runner.lease.change(RATIOS[turn % 2])
    if fleet is not None:
        fleet.close()
    else:
        runner.close()
    print("done", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
