"""Did the whole machine stand still? A probe for ``bench_links``' traced soaks.

``python -m bench.stall_probe OUT SECONDS``: a thread at the highest real-time priority the system
allows (else the lowest nice value) wakes every :data:`PERIOD` s and writes to ``OUT`` (JSON) every
wake-up that came more than :data:`LATE` s late, with the CPU time the hypervisor took meanwhile
(``steal`` in ``/proc/stat``), at once, so it may be ended any time. Nothing in the guest
outranks it: a late wake here means no process of ours could have run either — a stall no
priority of RTMU's can fix (a virtual machine's host, firmware, a frozen kernel), as against one
that the scheduler gave to someone else.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import time
from pathlib import Path

PERIOD = 0.005
LATE = 0.03


def _steal() -> float:
    with open("/proc/stat") as f:
        fields = f.readline().split()
    return int(fields[8]) / os.sysconf("SC_CLK_TCK") if len(fields) > 8 else 0.0


def main(argv: list[str]) -> int:
    out, seconds = Path(argv[0]), float(argv[1])
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(os.sched_get_priority_max(os.SCHED_FIFO)))
        how = "SCHED_FIFO"
    except (OSError, AttributeError):
        with contextlib.suppress(OSError):
            os.setpriority(os.PRIO_PROCESS, 0, -20)
        how = f"nice {os.getpriority(os.PRIO_PROCESS, 0)}"
    late: list[tuple[float, float, float]] = []
    out.write_text(json.dumps({"how": how, "late": late}))
    end = time.monotonic() + seconds
    due = time.monotonic() + PERIOD
    steal = _steal()
    while due < end:
        time.sleep(max(0.0, due - time.monotonic()))
        now = time.monotonic()
        stolen = _steal()
        if now - due > LATE:  # written at once: the probe may be ended at any time
            late.append((due, now - due, stolen - steal))
            out.write_text(json.dumps({"how": how, "late": late}))
        steal = stolen
        due = max(due + PERIOD, now)
    out.write_text(json.dumps({"how": how, "late": late}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
