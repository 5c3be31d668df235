"""The guardian process's main loop (``python -m rtmu.guardian``).

Thresholds, and why they cannot cause a false stop:

* **EOF on the pipe while armed** (the parent was killed, crashed, OOM-killed):
  stop at once — nobody is left to stop the robot.
* **a heartbeat :data:`QUICK_LATE` s late while armed** and the parent's
  threads are stopped by a signal or traced (``T``/``t`` in ``/proc``), or it
  is gone: stop at once. A running process is never in that state, however
  busy, slow or starved it is, so GC pauses and CPU contention cannot trip it.
* **a heartbeat late past what this parent normally does, while armed**, from a
  parent that still runs: stop. How late is learned per heartbeat source by the
  link's own rule (:mod:`rtmu.client.link_timing`): at least :data:`SILENT_LATE`
  s — the parent's own drive lease lapses 0.3 s after its UI last renewed it, so
  by then the parent would stop the robot itself — and at most
  :data:`SILENT_CEILING` s on a parent whose threads a busy machine often keeps
  waiting. The UI's beats carry the lease keeper's credited time
  (:mod:`rtmu.client.lease_keeper`): a UI thread that only waits for a CPU is not
  silent, one that is frozen is.

Heartbeats carry the sender's monotonic time (one clock for all processes on
Linux), and the pipe is drained before every decision, so a guardian that was
itself starved of CPU judges by when beats were sent, not when it read them.
After a stop it is disarmed until the parent arms it again (a new drive).
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import struct
import sys
import time
from pathlib import Path

from ..client.connection import AriaClient
from ..client.errors import ClientError
from ..client.link_timing import Deadline
from ..client.roles import Role
from . import messages as m
from .halt import Halter
from .handle import BEAT_PERIOD

QUICK_LATE = 0.1
SILENT_LATE = 0.4
SILENT_CEILING = 1.0
CHECK_PERIOD = 0.02


def parent_frozen(pid: int) -> bool:
    """True when process ``pid`` is gone, a zombie, or any of its threads is stopped or traced."""
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
    except OSError:
        return True
    for task in tasks:
        try:
            stat = (task / "stat").read_text()
        except OSError:
            continue
        state = stat.rsplit(")", 1)[1].split()[0]
        if state in ("T", "t", "Z", "X"):
            return True
    return False


def read_hello(fd: int) -> m.Hello:
    def exactly(n: int) -> bytes:
        data = b""
        while len(data) < n:
            chunk = os.read(fd, n - len(data))
            if not chunk:
                raise EOFError("the parent closed the pipe before its hello")
            data += chunk
        return data

    (size,) = struct.unpack(">I", exactly(4))
    if size > m.MAX_HELLO:
        raise ValueError("hello too large")
    return m.Hello.decode(exactly(size))


def say(word: str, text: str = "") -> None:
    try:
        sys.stdout.write(f"{word} {text}".rstrip().replace("\n", " ") + "\n")
        sys.stdout.flush()
    except (OSError, ValueError):
        _parent_stopped_listening()


def _parent_stopped_listening() -> None:
    """Point stdout at /dev/null: the unsent line would otherwise fail again at exit and print a
    traceback into the stderr we share with the parent (a script's one-line error would grow)."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


class Watch:
    """Armed/disarmed state and the heartbeats' last send times; decides when to stop."""

    def __init__(self, parent: int) -> None:
        self.parent = parent
        self.armed = False
        self.last: dict[bytes, float] = {}
        self.timing: dict[bytes, Deadline] = {}
        """Per source: how late its beats normally come (learned; floor SILENT_LATE)."""
        self.bye = False
        self.eof = False

    def take(self, kind: bytes, at: float) -> None:
        if kind == m.ARM:
            self.armed = True
            for source in list(self.last) or [m.BEAT_NET]:
                self.last[source] = at
        elif kind == m.DISARM:
            self.armed = False
        elif kind == m.BYE:
            self.armed = False
            self.bye = True
        else:  # a source is watched once it has beaten
            last = self.last.get(kind)
            timing = self.timing.setdefault(kind, Deadline(BEAT_PERIOD, SILENT_LATE, SILENT_CEILING))
            if last is not None and at > last:
                timing.note(at - last, at)
            self.last[kind] = max(at, last if last is not None else at)

    def limit(self, kind: bytes, now: float) -> float:
        timing = self.timing.get(kind)
        return timing.limit(now) if timing is not None else SILENT_LATE

    def why_stop(self, now: float) -> str | None:
        if not self.armed:
            return None
        if self.eof:
            return "the process driving the robot ended without saying goodbye"
        late = now - min(self.last.values()) if self.last else 0.0
        if late > QUICK_LATE and parent_frozen(self.parent):
            return f"the process driving the robot is stopped or gone (no heartbeat for {late * 1000:.0f} ms)"
        for kind, at in self.last.items():
            limit = self.limit(kind, now)
            if now - at > limit:
                thread = "UI" if kind == m.BEAT_UI else "network"
                return (
                    f"no heartbeat from the {thread} thread of the process driving the robot for "
                    f"{(now - at) * 1000:.0f} ms (its beats normally come within {limit * 1000:.0f} ms)"
                )
        return None


async def run(fd: int = 0) -> int:
    parent = os.getppid()
    try:
        hello = read_hello(fd)
    except (EOFError, ValueError, KeyError, OSError) as exc:
        say(m.UNAVAILABLE, f"bad hello: {exc}")
        return 2
    client = AriaClient()
    try:
        await client.connect(
            hello.host, hello.port, hello.user, hello.password, timeout=hello.timeout, role=Role.OPERATOR
        )
    except ClientError as exc:
        say(m.UNAVAILABLE, str(exc))
        return 3
    del hello  # the password is not needed any more
    halter = Halter(client)
    say(m.READY)
    watch = Watch(parent)
    reader = m.RecordReader()
    os.set_blocking(fd, False)

    def drain() -> None:
        while not watch.eof:
            try:
                data = os.read(fd, 4096)
            except BlockingIOError:
                return
            except OSError:
                data = b""
            if not data:
                watch.eof = True
                return
            for kind, at in reader.feed(data):
                watch.take(kind, at)

    try:
        while True:
            drain()
            why = watch.why_stop(time.monotonic())
            if why is not None:
                halter.halt()
                await halter.flush()
                watch.armed = False
                say(m.STOPPED, why)
            if watch.eof or watch.bye:
                return 0
            if not halter.connected:
                say(m.LOST, str(client.closed_error or "the guardian's connection closed"))
                return 3
            await asyncio.sleep(CHECK_PERIOD)
    finally:
        await client.disconnect()


def main() -> int:
    import signal

    # Its own session (no terminal signals); the parent's pipe decides when it ends.
    for signum in (signal.SIGINT, signal.SIGTSTP, signal.SIGHUP):
        with contextlib.suppress(OSError, ValueError):
            signal.signal(signum, signal.SIG_IGN)
    return asyncio.run(run())
