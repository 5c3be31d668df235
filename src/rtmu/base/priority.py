"""A few nice levels up for the threads that stop the robot, where the system allows it.

The loop that sends ``ratioDrive`` and ``stop``, the lease keeper and the guardian do little, but
must do it on time: on a laptop whose other programs keep both cores busy, a thread at the
default niceness waits its turn behind them (tens of ms, now and then hundreds), and a stop
waits with it. Lowering the nice value needs root or ``RLIMIT_NICE``; without them nothing
changes and nothing fails. Niceness, not a real-time class: a bug that spun at real-time
priority would take a core from everything else on the machine.

Where Linux groups processes by session (``autogroup``, on by default on desktops), a nice value
counts only against the other threads of the same session: the kernel first shares the CPUs
between sessions. A thread at nice −10 in a session whose group is behind waits with the whole
group — in a soak beside two other engineers' test runs, the simulator's thread (nice −10) waited
283–392 ms for a CPU while a real-time probe saw the machine run. :func:`raise_group_priority`
raises a process's session group as well; meant for a process that leads a session of its own,
since it raises every process of that session.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterator

NETWORK_BOOST = 5
"""Nice levels for the client's network thread and the lease keeper (above the UI thread)."""
GUARDIAN_BOOST = 10
"""Nice levels for the guardian process: it sleeps until a stop is due, then must send it at once."""


def raise_priority(boost: int = NETWORK_BOOST) -> bool:
    """Lower the calling thread's nice value by ``boost`` where allowed; True if it was. For a thread
    that lives as long as its job (the network thread, the keeper, the guardian's process)."""
    tid = threading.get_native_id()
    with contextlib.suppress(OSError, AttributeError):
        current = os.getpriority(os.PRIO_PROCESS, tid)
        os.setpriority(os.PRIO_PROCESS, tid, max(-20, current - boost))
        return True
    return False


def raise_group_priority(boost: int) -> bool:
    """Lower this process's session group's nice value (``/proc/self/autogroup``) by ``boost``
    where allowed; True if it was. False without autogroup or the rights to lower it."""
    path = "/proc/self/autogroup"
    with contextlib.suppress(OSError, ValueError, IndexError):
        with open(path) as f:
            current = int(f.read().split()[-1])  # "/autogroup-123 nice 0"
        with open(path, "w") as f:
            f.write(str(max(-20, current - boost)))
        return True
    return False


@contextlib.contextmanager
def raised_priority(boost: int = NETWORK_BOOST) -> Iterator[bool]:
    """:func:`raise_priority` for one job on a thread that goes on after it (``rtmu drive``'s loop runs on
    the caller's thread): its nice value is given back after, so calls in one process never pile up
    (a nice value may always be raised again without privileges)."""
    tid = threading.get_native_id()
    try:
        before: int | None = os.getpriority(os.PRIO_PROCESS, tid)
    except (OSError, AttributeError):
        before = None
    raised = raise_priority(boost)
    try:
        yield raised
    finally:
        if raised and before is not None:
            with contextlib.suppress(OSError):
                os.setpriority(os.PRIO_PROCESS, tid, before)
