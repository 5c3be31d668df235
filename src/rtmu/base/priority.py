"""A few nice levels up for the threads that stop the robot, where the system allows it.

The loop that sends ``ratioDrive`` and ``stop``, the lease keeper and the guardian do little, but
must do it on time: on a laptop whose other programs keep both cores busy, a thread at the
default niceness waits its turn behind them (tens of ms, now and then hundreds), and a stop
waits with it. Lowering the nice value needs root or ``RLIMIT_NICE``; without them nothing
changes and nothing fails. Niceness, not a real-time class: a bug that spun at real-time
priority would take a core from everything else on the machine.
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
