"""The threads that stop the robot run a few nice levels up where the system allows it.

On a laptop whose other programs keep both cores busy, a stop sent by a thread at the default
niceness waits its turn behind them; measured in ``bench/bench_safety.py`` (a killed window's
stop) and ``bench/bench_links.py`` (false stops under load). Here: that the levels are asked
for and, where allowed (root or ``RLIMIT_NICE``), granted — never how fast anything ran.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import threading
import time

from rtmu.base.priority import GUARDIAN_BOOST, NETWORK_BOOST, raise_priority
from rtmu.guardian.handle import GuardianHandle


def _may_lower_to(nice: int) -> bool:
    """Whether this process may set a nice value as low as ``nice`` (what the kernel checks)."""
    if os.geteuid() == 0:
        return True
    soft, _hard = resource.getrlimit(resource.RLIMIT_NICE)
    return soft == resource.RLIM_INFINITY or 20 - soft <= nice


def _nice_of(pid: int) -> int:
    with open(f"/proc/{pid}/stat") as f:
        return int(f.read().rsplit(")", 1)[1].split()[16])


def test_a_thread_raises_only_itself() -> None:
    before = os.getpriority(os.PRIO_PROCESS, 0)
    seen: dict[str, object] = {}

    def body() -> None:
        seen["granted"] = raise_priority()
        seen["nice"] = os.getpriority(os.PRIO_PROCESS, threading.get_native_id())

    thread = threading.Thread(target=body)
    thread.start()
    thread.join()
    wanted = max(-20, before - NETWORK_BOOST)
    if _may_lower_to(wanted):
        assert seen == {"granted": True, "nice": wanted}
    else:
        assert seen == {"granted": False, "nice": before}
    assert os.getpriority(os.PRIO_PROCESS, 0) == before  # the calling thread only, not the process


def test_the_guardian_runs_above_its_parent_where_allowed() -> None:
    before = os.getpriority(os.PRIO_PROCESS, 0)
    wanted = max(-20, before - GUARDIAN_BOOST) if _may_lower_to(before - GUARDIAN_BOOST) else before
    handle = GuardianHandle.start()
    try:
        deadline = time.monotonic() + 30.0  # it raises itself once its interpreter has started
        while _nice_of(handle.proc.pid) != wanted and time.monotonic() < deadline:
            time.sleep(0.05)
        assert _nice_of(handle.proc.pid) == wanted
    finally:
        handle.close()
        handle.proc.wait(10)


def test_a_raised_job_gives_its_thread_its_level_back() -> None:
    """``rtmu drive`` runs its loop on the caller's thread: called twice in one process, the levels
    must not pile up (once they did: a test's load spinners, started after two in-process drives,
    inherited -20 from the main thread and could no longer be niced to 19 by an increment)."""
    from rtmu.base.priority import raised_priority

    def body() -> None:
        tid = threading.get_native_id()
        start.append(os.getpriority(os.PRIO_PROCESS, tid))
        for _ in range(5):
            with raised_priority() as granted:
                inside = os.getpriority(os.PRIO_PROCESS, tid)
                raised.append(inside == (max(-20, start[0] - NETWORK_BOOST) if granted else start[0]))
            seen.append(os.getpriority(os.PRIO_PROCESS, tid))

    start: list[int] = []
    raised: list[bool] = []
    seen: list[int] = []
    thread = threading.Thread(target=body)
    thread.start()
    thread.join()
    assert raised == [True] * 5  # raised (where allowed) inside each job…
    assert seen == start * 5  # …and given back after each


GROUP_CHILD = """
import os, sys
from rtmu.base.priority import raise_group_priority
granted = raise_group_priority(5)
path = "/proc/self/autogroup"
print(granted, open(path).read().split()[-1] if os.path.exists(path) else "-")
"""


def test_a_session_leader_raises_its_session_group_where_allowed() -> None:
    """A process in a session of its own (``start_new_session``) lowers its group's nice value; a
    process without the rights, or a kernel without autogroup, changes nothing and fails nothing."""
    argv = [sys.executable, "-c", GROUP_CHILD]
    out = subprocess.run(argv, start_new_session=True, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    granted, nice = out.stdout.split()
    if not os.path.exists("/proc/self/autogroup"):
        assert (granted, nice) == ("False", "-")
    elif os.geteuid() == 0:
        assert (granted, nice) == ("True", "-5")
