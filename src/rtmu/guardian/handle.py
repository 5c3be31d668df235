"""The parent's side of a guardian process: start it, send it logins, arm, beat, disarm, say goodbye.

Every method that writes is thread-safe and never blocks: records go to a non-blocking pipe under
one lock (the UI thread and the network thread both beat). A full pipe means the guardian has
stopped reading: it is then ended and reported unavailable rather than let a lost disarm become a
false stop later.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable

from ..base import i18n
from ..base.i18n import _
from . import messages as m

BEAT_PERIOD = 0.04
"""Seconds between heartbeats from each thread (the guardian wants one at least every 50 ms)."""


class GuardianHandle:
    """One guardian process. :meth:`start` it, :meth:`login` it, then :meth:`poll` its reports."""

    def __init__(self, proc: subprocess.Popen[bytes], clock: Callable[[], float] = time.monotonic) -> None:
        self.proc = proc
        self.clock = clock
        self._lock = threading.Lock()
        assert proc.stdin is not None and proc.stdout is not None
        self._fd = proc.stdin.fileno()
        self._out = proc.stdout.fileno()
        os.set_blocking(self._out, False)
        os.set_blocking(self._fd, False)
        self._partial = b""
        self.armed = False
        self.serial = -1
        """The serial of the last login sent (:meth:`login`)."""
        self.state = "starting"
        """Of the last login: starting → ready, or unavailable/lost (with :attr:`reason`);
        ended when the process is gone."""
        self.reason = ""

    @classmethod
    def start(cls, hello: m.Hello | None = None) -> GuardianHandle:
        """Spawn ``python -m rtmu.guardian`` in its own session; credentials go down the pipe only."""
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu.guardian"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            start_new_session=True,
            env={**os.environ, **i18n.child_environment()},  # it says why it stopped in our language
        )
        handle = cls(proc)
        if hello is not None:
            handle.login(hello)
        return handle

    @property
    def alive(self) -> bool:
        return self._fd >= 0 and self.state != "ended"

    # -- records ---------------------------------------------------------------------------
    def _write(self, data: bytes) -> bool:
        with self._lock:
            if self._fd < 0:
                return False
            try:
                view = memoryview(data)
                while view:  # a login is longer than one record; the pipe has room for it (64 KiB)
                    view = view[os.write(self._fd, view) :]
                return True
            except BlockingIOError:
                stuck = True
            except OSError:
                stuck = False
        self._gone("ended", _("the guardian stopped reading its pipe") if stuck else _("the guardian ended"))
        return False

    def _send(self, kind: bytes, at: float | None = None) -> bool:
        return self._write(m.record(kind, self.clock() if at is None else at))

    def login(self, hello: m.Hello) -> bool:
        """Watch the robot ``hello`` names from now on (its serial names the answers about it)."""
        with self._lock:
            self.armed = False
            self.serial = hello.serial
            if self.state != "ended":
                self.state, self.reason = "starting", ""
        return self._write(m.login_record(hello, self.clock()))

    def warm(self, hello: m.Hello) -> bool:
        """Keep a login to ``hello``'s robot ready (it may be chosen next); nothing is watched there."""
        return self._write(m.login_record(hello, self.clock(), m.WARM))

    def cool(self, hello: m.Hello) -> bool:
        """Let go of the ready login to ``hello``'s robot (its session disconnected)."""
        return self._write(m.login_record(hello, self.clock(), m.COLD))

    def arm(self) -> None:
        """Before the first nonzero ``ratioDrive`` of a drive."""
        if not self.armed:
            self.armed = True
            self._send(m.ARM)

    def disarm(self) -> None:
        """After our own zero ratios + ``stop`` have been sent."""
        if self.armed:
            self.armed = False
            self._send(m.DISARM)

    def halt(self) -> None:
        """Our own link to the robot died while driving: the guardian stops it on its connection."""
        self.armed = False
        self._send(m.HALT)

    def beat_ui(self, at: float | None = None) -> None:
        """The UI thread is alive (as of ``at``; default now)."""
        if self.armed:
            self._send(m.BEAT_UI, at)

    def beat_net(self) -> None:
        if self.armed:
            self._send(m.BEAT_NET)

    # -- reports ---------------------------------------------------------------------------
    def fileno(self) -> int:
        """Where its reports come from (for a ``select``); -1 once closed."""
        return self._out

    def poll(self) -> list[tuple[str, int, str]]:
        """The guardian's reports since the last call, as (word, serial, text); never blocks.

        Call from one thread only. EOF while the process was wanted is reported as ``ended``
        (serial -1)."""
        out: list[tuple[str, int, str]] = []
        while self._out >= 0:
            try:
                data = os.read(self._out, 4096)
            except BlockingIOError:
                break
            except OSError:
                data = b""
            if not data:
                self._out = -1
                if self.state != "ended":
                    code = self.proc.poll()
                    self._gone(
                        "ended", _("the guardian ended unexpectedly (exit code {code})").format(code=code)
                    )
                    out.append(("ended", -1, self.reason))
                break
            self._partial += data
            *lines, self._partial = self._partial.split(b"\n")
            for line in lines:
                word, serial, text = m.parse_report(line.decode("utf-8", "replace"))
                out.append((word, serial, text))
                if serial != self.serial:
                    continue  # about a robot it has left
                if word == m.READY:
                    self.state, self.reason = "ready", ""
                elif word in (m.UNAVAILABLE, m.LOST):
                    self.state, self.reason = word, text
        return out

    # -- ending ----------------------------------------------------------------------------
    def close(self, *, goodbye: bool = True) -> None:
        """End the guardian: with ``goodbye`` it exits without a stop; without it and while armed,
        the closed pipe makes it stop the robot (our own connection died while driving)."""
        if goodbye:
            self.armed = False
            self._send(m.BYE)
        self._close_pipe()
        out, self._out = self._out, -1  # poll() runs on the same thread as close() (or has ended)
        if out >= 0 and self.proc.stdout is not None:
            with contextlib.suppress(OSError, ValueError):
                self.proc.stdout.close()
        self.state = "ended"
        threading.Thread(target=self._reap, name="rtmu-guardian-reap", daemon=True).start()

    def _reap(self) -> None:
        try:
            self.proc.wait(3.0)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.proc.wait(1.0)

    def _close_pipe(self) -> None:
        """Close our end of its stdin once (the fd number must never be closed twice)."""
        with self._lock:
            fd, self._fd = self._fd, -1
            if fd >= 0 and self.proc.stdin is not None:
                with contextlib.suppress(OSError, ValueError):
                    self.proc.stdin.close()

    def _gone(self, state: str, reason: str) -> None:
        self._close_pipe()
        if state == "ended" and self.proc.poll() is None:
            with contextlib.suppress(OSError):
                self.proc.kill()
        self.state, self.reason = state, reason


class GuardianUnavailable(Exception):
    """The guardian could not log in (client limit, rights) or start; the text says why."""


async def start_ready(hello: m.Hello, timeout: float) -> GuardianHandle:
    """For scripts (``rtmu drive``): start a guardian and wait until it has logged in."""
    import asyncio

    try:
        handle = GuardianHandle.start(hello)
    except OSError as exc:
        raise GuardianUnavailable(
            _("it could not be started: {error}").format(error=exc.strerror or exc)
        ) from None
    deadline = time.monotonic() + timeout + 5.0  # its own login has ``timeout``; plus its start-up
    while handle.state == "starting":
        handle.poll()
        if time.monotonic() > deadline:
            handle.close(goodbye=True)
            raise GuardianUnavailable(_("it did not log in in time"))
        await asyncio.sleep(0.02)
    if handle.state != "ready":
        handle.close(goodbye=True)
        raise GuardianUnavailable(handle.reason or _("it ended"))
    return handle


async def beat_network(handle: GuardianHandle) -> None:
    """A script's network-loop heartbeat: every :data:`BEAT_PERIOD` s until cancelled."""
    import asyncio

    while True:
        handle.beat_net()
        await asyncio.sleep(BEAT_PERIOD)
