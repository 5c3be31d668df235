"""The guardian process's main loop (``python -m rtmu.guardian``).

It starts idle and logs in to the robot each :data:`~.messages.LOGIN` record names (the window's
one guardian follows the robot that may drive; ``rtmu drive`` and ``rtmu bridge`` log in once),
on its own connection (:mod:`.login`). It says ``ready`` once logged in; from then on, while the
parent says motion may be commanded ("armed"), heartbeats must keep coming from the parent's UI
and network threads.

Thresholds, and why they cannot cause a false stop:

* **EOF on the pipe while armed** (the parent was killed, crashed, OOM-killed):
  stop at once — nobody is left to stop the robot.
* **a heartbeat :data:`QUICK_LATE` s late while armed** and the parent's
  threads are stopped by a signal or traced (``T``/``t`` in ``/proc``), or it
  is gone: stop at once. A running process is never in that state, however
  busy, slow or starved it is, so GC pauses and CPU contention cannot trip it.
* **a heartbeat late past its source's limit while armed** from a parent that
  still runs: stop. The limit is at least :data:`SILENT_LATE` s for the UI thread — the parent's
  own drive lease lapses 0.3 s after its UI last renewed it — and :data:`SILENT_LATE_NETWORK` for
  the network thread, which stops a drive itself once status is 0.45 s old: by then the parent
  would stop the robot itself when it runs again — the guardian never ends a drive the parent
  would have continued.
  How late each source may be is asked of a :class:`BeatLimit` per source (the ``limits`` of
  :class:`Watch`). The process learns it (:func:`learned_limit`) by the link's own rule
  (:mod:`rtmu.base.link_timing`): at most :data:`SILENT_CEILING` s on a parent whose threads a busy
  machine often keeps waiting. The UI's beats carry the lease keeper's credited time
  (``rtmu.client.lease_keeper``): a UI thread that only waits for a CPU is not silent, one that is
  frozen is.

Heartbeats carry the sender's monotonic time (one clock for all processes on
Linux), and the pipe is drained before every decision, so a guardian that was
itself starved of CPU judges by when beats were sent, not when it read them.
After a stop it is disarmed until the parent arms it again (a new drive). A new login while
armed first stops the robot watched so far (the parent switched robots in the middle of a drive,
and its own stop for that robot may not have left yet). Disarmed, it sleeps on its pipe and its
sockets instead of waking 50 times a second.

Arming for a newly selected robot is a login (a connection, the server's introduction, the data
list) and a busy server takes its time over it. So the guardian keeps up to :data:`WARM_MAX` ready
logins beside the watched one — the robot watched before, and the ones the parent names in
:data:`~.messages.WARM` records (a window: the robots beside the selected one in its list). A LOGIN
for one of them is ready at once. It watches nothing and sends nothing on them; they only keep a
connection open, and a failed or closed one is let go quietly.
"""

from __future__ import annotations

import contextlib
import os
import select
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from ..base.i18n import N_, Said
from ..base.link_timing import STATUS_PROMISE, Deadline
from ..base.priority import GUARDIAN_BOOST, raise_priority
from ..base.units import Quantity
from . import messages as m
from .halt import Halter
from .handle import BEAT_PERIOD
from .login import LoginState, RobotLogin

QUICK_LATE = 0.06
"""Beats come every 40 ms: one 20 ms late is enough to look whether the parent is stopped (a few
``/proc`` reads, only then). 0.1 s kept a SIGSTOPped window driving 85 ms (p50) before the look."""
SILENT_LATE = 0.4
SILENT_LATE_NETWORK = STATUS_PROMISE
"""The network thread's floor: it is the thread that stops a drive on a stale link, after up to
0.45 s without status (``base.link_timing``) — silent for less, it has ended nothing it would not
continue. Measured with a floor of :data:`SILENT_LATE` (bench_links, "good" Wi-Fi at a load of 9–13):
"no heartbeat from the network thread … for 419 ms (its beats normally come within 400 ms)" while the
parent's own stale limit was 450 ms."""
SILENT_CEILING = 1.0
"""The learned silent limit's ceiling (:func:`learned_limit`): a busy machine may delay a beat this much."""
CHECK_PERIOD = 0.02
"""Seconds between looks while armed, once a beat is :data:`QUICK_LATE` late (before that nothing but
the pipe or a socket, which wake the loop themselves, can call for a stop: see :meth:`Watch.next_look`)."""
IDLE_PERIOD = 1.0
"""Seconds between looks while disarmed: nothing can call for a stop then, and a record on the pipe
(ARM first of all) or a byte on the socket wakes the loop at once."""
WARM_MAX = 3
"""Ready logins kept beside the watched one (the robot watched before, and two the parent named)."""


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


def say(word: str, serial: int, text: str = "") -> None:
    """One word to the parent; its text in the operator's language (the parent shows it as it comes)."""
    shown = text.words() if isinstance(text, Said) else text
    try:
        sys.stdout.write(m.report(word, serial, shown) + "\n")
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


class BeatLimit(Protocol):
    """How late one heartbeat source may be: learns from the gaps between its beats."""

    def note(self, sample: float, now: float) -> None: ...

    def limit(self, now: float) -> float: ...


class FixedLimit:
    """A source may be :data:`SILENT_LATE` s late, whatever it did before (the default)."""

    def __init__(self, seconds: float = SILENT_LATE) -> None:
        self.seconds = seconds

    def note(self, sample: float, now: float) -> None:
        pass

    def limit(self, now: float) -> float:
        return self.seconds


def learned_limit(source: bytes) -> BeatLimit:
    """How late one source's beats come, learned as a link's status is (``base.link_timing``): from
    its floor (:data:`SILENT_LATE`, the network thread's :data:`SILENT_LATE_NETWORK`) for a calm
    parent up to :data:`SILENT_CEILING` for one a busy machine delays."""
    floor = SILENT_LATE_NETWORK if source == m.BEAT_NET else SILENT_LATE
    return Deadline(BEAT_PERIOD, floor, SILENT_CEILING)


LimitFor = Callable[[bytes], BeatLimit]
"""``limits(source)``: the limit of one heartbeat source (``BEAT_UI`` or ``BEAT_NET``), made once."""


class Watch:
    """Armed/disarmed state and the heartbeats' last send times; decides when to stop."""

    def __init__(self, parent: int, limits: LimitFor | None = None) -> None:
        self.parent = parent
        self.armed = False
        self.last: dict[bytes, float] = {}
        self.limits: LimitFor = limits or (lambda _source: FixedLimit())
        self.timing: dict[bytes, BeatLimit] = {}
        """Per source: how late its beats may come (``limits``)."""
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
        elif kind in (m.BEAT_UI, m.BEAT_NET):  # a source is watched once it has beaten
            last = self.last.get(kind)
            timing = self.timing.get(kind)
            if timing is None:
                timing = self.timing[kind] = self.limits(kind)
            if last is not None and at > last:
                timing.note(at - last, at)
            self.last[kind] = max(at, last if last is not None else at)

    def limit(self, kind: bytes, now: float) -> float:
        timing = self.timing.get(kind)
        return timing.limit(now) if timing is not None else SILENT_LATE

    def next_look(self, now: float) -> float:
        """Seconds the armed loop may sleep (unless the pipe or a socket wakes it): until the oldest
        beat is :data:`QUICK_LATE` late, then :data:`CHECK_PERIOD`. Before that :meth:`why_stop` cannot
        say stop — every limit is longer — so looking every 20 ms between beats that come every 40 ms
        only woke the process (about 50 times a second of its 75 while a window drove)."""
        if not self.last or min(self.limit(kind, now) for kind in self.last) < QUICK_LATE:
            return CHECK_PERIOD
        due = min(self.last.values()) + QUICK_LATE - now
        return due if due > 0 else CHECK_PERIOD

    def why_stop(self, now: float) -> str | None:
        if not self.armed:
            return None
        if self.eof:
            return Said(N_("the process driving the robot ended without saying goodbye"))
        late = now - min(self.last.values()) if self.last else 0.0
        if late > QUICK_LATE and parent_frozen(self.parent):
            return Said(
                N_("the process driving the robot is stopped or gone (no heartbeat for {late})"),
                late=Quantity(late * 1000, "ms"),
            )
        for kind, at in self.last.items():
            limit = self.limit(kind, now)
            if now - at > limit:
                silent = (
                    N_(
                        "no heartbeat from the UI thread of the process driving the robot for {late} "
                        "(its beats normally come within {limit})"
                    )
                    if kind == m.BEAT_UI
                    else N_(
                        "no heartbeat from the network thread of the process driving the robot for {late} "
                        "(its beats normally come within {limit})"
                    )
                )
                return Said(
                    silent, late=Quantity((now - at) * 1000, "ms"), limit=Quantity(limit * 1000, "ms")
                )
        return None


class Guardian:
    """The loop's state: the pipe, the watch, and the login to the robot watched now."""

    def __init__(self, fd: int, watch: Watch) -> None:
        self.fd = fd
        self.watch = watch
        self.reader = m.RecordReader()
        self.login: RobotLogin | None = None
        self.halter: Halter | None = None
        self.spares: list[RobotLogin] = []
        """Ready (or readying) logins to robots that may be watched next, oldest first."""
        self.serial = -1
        """The serial of the login asked for last (every word about it carries this number)."""

    # -- the pipe ------------------------------------------------------------------------------
    def drain(self) -> None:
        while not self.watch.eof:
            try:
                data = os.read(self.fd, 65536)
            except BlockingIOError:
                return
            except OSError:
                data = b""
            if not data:
                self.watch.eof = True
                return
            try:
                records = self.reader.feed(data)
            except ValueError:  # out of step with the parent: as good as gone
                self.watch.eof = True
                return
            for kind, at, hello in records:
                if kind == m.LOGIN and hello is not None:
                    self.log_in(hello)
                elif kind == m.WARM and hello is not None:
                    self.warm(hello)
                elif kind == m.COLD and hello is not None:
                    self.cool(hello)
                elif kind == m.HALT:
                    self.stop(Said(N_("the program driving it lost its own link to the robot while driving")))
                else:
                    self.watch.take(kind, at)

    # -- the robot -----------------------------------------------------------------------------
    def log_in(self, hello: m.Hello) -> None:
        """Watch the robot ``hello`` names from now on; the one watched before is left."""
        if self.watch.armed:  # a switch in the middle of a drive: that robot is stopped first, quietly
            self.halt()
        self.watch.armed = False
        self.serial = hello.serial
        if not hello.target.host:  # log out: the parent's robot is gone and no other is to be watched yet
            self.leave()
            return
        login = self.login
        if login is not None and login.state is LoginState.READY and hello.same_robot(login.hello):
            say(m.READY, self.serial)  # logged in to that robot already
            return
        self.login, self.halter = None, None
        if login is not None:
            self._keep(login)  # the robot watched before is a likely next one
        spare = self._take_spare(hello)
        self.login = spare if spare is not None else RobotLogin(hello)  # a ready spare says READY at once

    def warm(self, hello: m.Hello) -> None:
        """Keep a login to ``hello``'s robot ready (the newest spare; the oldest beyond WARM_MAX goes)."""
        login = self.login
        if login is not None and login.active and hello.same_robot(login.hello):
            return
        spare = self._take_spare(hello)
        self._keep(spare if spare is not None else RobotLogin(hello))

    def cool(self, hello: m.Hello) -> None:
        """Let go of the spare login to ``hello``'s robot, if one is kept."""
        spare = self._take_spare(hello)
        if spare is not None:
            spare.close()

    def _take_spare(self, hello: m.Hello) -> RobotLogin | None:
        for i, spare in enumerate(self.spares):
            if hello.same_robot(spare.hello):
                return self.spares.pop(i)
        return None

    def _keep(self, login: RobotLogin) -> None:
        if not login.active:
            login.close()
            return
        self.spares.append(login)
        while len(self.spares) > WARM_MAX:
            self.spares.pop(0).close()

    def leave(self) -> None:
        login, self.login, self.halter = self.login, None, None
        if login is not None:
            login.close()

    def leave_all(self) -> None:
        """Log out of the watched robot and every spare (the guardian ends)."""
        self.leave()
        spares, self.spares = self.spares, []
        for spare in spares:
            spare.close()

    def halt(self) -> bool:
        halter = self.halter
        if halter is None:
            return False
        halter.halt()
        return halter.flush()

    def stop(self, why: str) -> None:
        """Stop the robot watched now (if logged in) and say so; disarmed afterwards."""
        if self.halt():
            say(m.STOPPED, self.serial, why)
        self.watch.armed = False

    def progress(self, now: float) -> None:
        """Say what the login did: ready, refused, or its connection ended (spares go quietly)."""
        for spare in self.spares:
            spare.check_deadline(now)
        if any(not spare.active for spare in self.spares):
            self.spares = [spare for spare in self.spares if spare.active]
        login = self.login
        if login is None:
            return
        login.check_deadline(now)
        if login.state is LoginState.READY and self.halter is None:
            self.halter = Halter(login)
            say(m.READY, self.serial)
        elif login.state is LoginState.FAILED:
            say(m.UNAVAILABLE, self.serial, login.error)
            self.login = None
        elif login.state is LoginState.CLOSED:
            say(m.LOST, self.serial, login.error or Said(N_("the guardian's connection closed")))
            self.login, self.halter = None, None

    # -- the loop ------------------------------------------------------------------------------
    def wait(self) -> None:
        """Sleep until the pipe or a socket has something, or it is time to look again."""
        logins = [login for login in (self.login, *self.spares) if login is not None and login.active]
        readers: list[int] = [self.fd]
        writers: list[int] = []
        period = self.watch.next_look(time.monotonic()) if self.watch.armed else IDLE_PERIOD
        for login in logins:
            readers.append(login.fileno())
            if login.wants_write():
                writers.append(login.fileno())
            if login.state is not LoginState.READY:
                period = min(period, max(0.0, login.deadline - time.monotonic()) + 0.01)
        try:
            readable, writable, _ = select.select(readers, writers, [], period)
        except (OSError, ValueError):
            return
        for login in logins:
            fd = login.fileno()
            if fd in writable:
                login.on_writable()
            if fd in readable:
                login.on_readable(time.monotonic())

    def run(self) -> int:
        try:
            while True:
                self.drain()
                now = time.monotonic()
                self.progress(now)
                why = self.watch.why_stop(now)
                if why is not None:
                    self.stop(why)
                if self.watch.eof or self.watch.bye:
                    return 0
                self.wait()
        finally:
            self.leave_all()


def run(fd: int = 0, limits: LimitFor | None = learned_limit) -> int:
    os.set_blocking(fd, False)
    raise_priority(GUARDIAN_BOOST)  # where allowed: a killed parent's stop must not wait for a core
    return Guardian(fd, Watch(os.getppid(), limits)).run()


def main() -> int:
    import signal

    # Its own session (no terminal signals); the parent's pipe decides when it ends.
    for signum in (signal.SIGINT, signal.SIGTSTP, signal.SIGHUP):
        with contextlib.suppress(OSError, ValueError):
            signal.signal(signum, signal.SIG_IGN)
    return run()
