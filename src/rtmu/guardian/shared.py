"""One guardian process for many robot sessions, armed for the one robot that may drive.

A window of 50 robots used to start 50 guardian processes (~27 MB and a login each). Only the
selected robot takes drive keys, so one process is enough: :class:`SharedGuardian` owns it, every
robot session has a :class:`GuardianSeat` at it, and the fleet :meth:`~SharedGuardian.choose`\\ s
the seat of the selected robot. The guardian then logs in to that robot on its own connection
(a LOGIN record on its pipe, :mod:`.messages`) — "arming it for that robot" — and says ``ready``.

Until then the robot may not drive (:meth:`GuardianSeat.waiting_reason`: the controller refuses
drive keys with it, and the drive loop refuses to send ``ratioDrive``), so a window killed or
frozen a moment after selecting (or connecting to) a robot is still stopped by its guardian. A
robot the guardian could not log in to (the server refused a second login, the process could not
start) may still be driven, with the "Guardian not available" warning as before.

Arming is a login, and a busy robot server takes its time over one; so :meth:`~SharedGuardian.expect`
names the robots likely to be selected next (a window: the ones beside the selected robot in its
list), and the process keeps ready logins to them — and to the robot selected before — beside the
one it watches (:data:`.child.WARM_MAX`, memory independent of the fleet's size). Selecting one of
those arms at once; nothing is watched or sent on them.

Only the chosen seat's records reach the process: a robot that was selected before cannot disarm
(or arm) the guardian for the robot selected now. Threads: seats are offered and withdrawn by
their session's network thread, chosen by the UI thread, and beaten by both; a reader thread
hears the process. Everything here is thread-safe.
"""

from __future__ import annotations

import contextlib
import select
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import replace
from enum import Enum

from ..base.i18n import _
from ..values.target import Target
from . import messages as m
from .handle import GuardianHandle

RESTART_AFTER = 2.0
"""A guardian process that ended is started again for a new login only this long after its last start."""
READ_PERIOD = 0.5
"""Seconds the reader thread sleeps at most between looks (it wakes at once for a report)."""


class SeatState(Enum):
    IDLE = "idle"
    """Not the robot that may drive, or not connected (nothing offered)."""
    ARMING = "arming"
    """The guardian is logging in to this robot: it may not drive yet."""
    READY = "ready"
    """The guardian is logged in to this robot and stops it if this process is killed or frozen."""
    UNAVAILABLE = "unavailable"
    """The guardian could not be armed for it (``reason``): it drives with the warning, unguarded."""


class GuardianSeat:
    """One robot session's place at a :class:`SharedGuardian`. Thread-safe."""

    def __init__(self, guardian: SharedGuardian, name: str) -> None:
        self.guardian = guardian
        self.name = name
        self.hello: m.Hello | None = None
        """Where this robot is and how to log in (its session's connection), None while not connected."""
        self.state = SeatState.IDLE
        self.reason = ""
        self.serial = -1
        """The serial of the login sent for this seat (the guardian's words about it carry it)."""
        self._reports: deque[tuple[str, str]] = deque(maxlen=32)

    # -- the session's side (network thread) --------------------------------------------------
    def offer(self, hello: m.Hello) -> None:
        """The session connected to this robot (``hello``: the same login): arm for it if chosen."""
        self.guardian._offer(self, hello)

    def withdraw(self, *, leave: bool = True) -> None:
        """The session's connection ended. ``leave``: the guardian logs out of it too (a disconnect);
        else it keeps its own login, if alive, for the reconnect (a lost link)."""
        self.guardian._withdraw(self, leave)

    def arm(self) -> None:
        self.guardian._pass(self, "arm")

    def disarm(self) -> None:
        self.guardian._pass(self, "disarm")

    def halt(self) -> None:
        """Our link to the robot died while driving: the guardian stops it on its own connection."""
        self.guardian._pass(self, "halt")

    def beat_net(self) -> None:
        self.guardian._pass(self, "beat_net")

    def beat_ui(self, at: float | None = None) -> None:
        self.guardian._pass(self, "beat_ui", at)

    def take_reports(self) -> list[tuple[str, str]]:
        """What the guardian said about this robot since the last call: (word, text)."""
        out = []
        while True:
            try:
                out.append(self._reports.popleft())
            except IndexError:
                return out

    # -- the rules ---------------------------------------------------------------------------
    @property
    def chosen(self) -> bool:
        return self.guardian.chosen is self

    def waiting_reason(self) -> str | None:
        """Why this robot may not start a drive now (None: it may — guarded, or with the warning)."""
        if not self.chosen:
            return _("{name} is not the robot that may drive").format(name=self.name)
        if self.state in (SeatState.READY, SeatState.UNAVAILABLE):
            return None
        return _("arming the guardian for {name} …").format(name=self.name)

    @property
    def armed(self) -> bool:
        """The guardian process is armed for this robot now: its beats are wanted (a window at rest
        runs no beat timer; it starts with a drive and ends once this is False)."""
        with self.guardian._lock:
            handle = self.guardian._handle
            return self.armed_for_it and handle is not None and handle.armed

    @property
    def armed_for_it(self) -> bool:
        """The guardian is logged in to this robot (it may drive, guarded)."""
        return self.chosen and self.state is SeatState.READY

    def _said(self, word: str, text: str) -> None:
        self._reports.append((word, text))


class SharedGuardian:
    """One guardian process for a window: :meth:`seat` per robot, :meth:`choose` the one that may drive.

    ``start`` makes the process (``GuardianHandle.start``; a test passes its own); ``spawn`` starts
    it now (the window: warm before the first robot is selected) rather than at the first login.
    """

    def __init__(
        self, start: Callable[[], GuardianHandle] = GuardianHandle.start, *, spawn: bool = True
    ) -> None:
        self._start = start
        self._lock = threading.RLock()
        self._handle: GuardianHandle | None = None
        self._started_at = float("-inf")
        self._broken = ""
        """Why no process can be started (then every robot drives with the warning)."""
        self._serial = 0
        self._seats_by_serial: dict[int, GuardianSeat] = {}
        self.chosen: GuardianSeat | None = None
        self._likely: tuple[GuardianSeat, ...] = ()
        """The seats named by the last :meth:`expect` (their logins are kept ready)."""
        self.logins = 0
        """LOGIN records sent (benchmarks and tests)."""
        self.processes = 0
        """Guardian processes started."""
        self._closed = False
        if spawn:
            with self._lock:
                self._ensure_process()

    def seat(self, name: str) -> GuardianSeat:
        return GuardianSeat(self, name)

    @property
    def pid(self) -> int | None:
        handle = self._handle
        return handle.proc.pid if handle is not None and handle.alive else None

    # -- choosing (UI thread) ------------------------------------------------------------------
    def choose(self, seat: GuardianSeat | None) -> None:
        """``seat``'s robot is the one that may drive from now on; the guardian is armed for it."""
        with self._lock:
            if seat is self.chosen:
                return
            old, self.chosen = self.chosen, seat
            if old is not None:
                old.state, old.reason = SeatState.IDLE, ""
            if seat is not None:
                self._log_in(seat)

    def expect(self, likely: Sequence[GuardianSeat | None]) -> None:
        """The seats that may be chosen next: logins to their robots are kept ready (once connected)."""
        with self._lock:
            new = tuple(seat for seat in likely if seat is not None and seat is not self.chosen)
            fresh = [seat for seat in new if seat not in self._likely]
            self._likely = new
            for seat in fresh:
                self._warm(seat)

    def _warm(self, seat: GuardianSeat) -> None:
        """Keep a ready login to ``seat``'s robot, once it is connected (lock held)."""
        handle = self._handle
        if seat.hello is not None and handle is not None and handle.alive:
            handle.warm(replace(seat.hello, serial=0))

    def _log_in(self, seat: GuardianSeat) -> None:
        """Send the chosen seat's login (lock held)."""
        hello = seat.hello
        if hello is None:
            seat.state = SeatState.IDLE  # armed when its session connects
            return
        handle = self._ensure_process()
        if handle is None:
            self._unavailable(seat, self._broken or _("it could not be started"))
            return
        self._serial += 1
        seat.serial = self._serial
        self._seats_by_serial = {self._serial: seat}  # words about older logins are not wanted
        seat.state, seat.reason = SeatState.ARMING, ""
        self.logins += 1
        if not handle.login(replace(hello, serial=self._serial)):
            self._unavailable(seat, handle.reason or _("it ended"))

    def _unavailable(self, seat: GuardianSeat, reason: str) -> None:
        seat.state, seat.reason = SeatState.UNAVAILABLE, reason
        seat._said(m.UNAVAILABLE, reason)

    def _ensure_process(self) -> GuardianHandle | None:
        handle = self._handle
        if handle is not None and handle.alive:
            return handle
        if self._closed or time.monotonic() - self._started_at < RESTART_AFTER:
            return None
        self._started_at = time.monotonic()
        try:
            handle = self._start()
        except OSError as exc:
            self._broken = _("it could not be started: {error}").format(error=exc.strerror or exc)
            return None
        self._broken = ""
        self._handle = handle
        self.processes += 1
        threading.Thread(target=self._read, args=(handle,), name="rtmu-guardian-reports", daemon=True).start()
        return handle

    # -- offering (network threads) ------------------------------------------------------------
    def _offer(self, seat: GuardianSeat, hello: m.Hello) -> None:
        with self._lock:
            seat.hello = hello
            if seat is self.chosen:
                self._log_in(seat)
            elif seat in self._likely:
                self._warm(seat)

    def _withdraw(self, seat: GuardianSeat, leave: bool) -> None:
        with self._lock:
            hello, seat.hello = seat.hello, None
            if seat is not self.chosen:
                handle = self._handle
                if leave and hello is not None and handle is not None and handle.alive:
                    handle.cool(hello)  # no ready login kept to a robot the window let go of
                return
            seat.state, seat.reason = SeatState.IDLE, ""
            handle = self._handle
            if leave and handle is not None and handle.alive:
                self._serial += 1
                self._seats_by_serial = {}
                handle.login(
                    m.Hello(Target("", 0), serial=self._serial)
                )  # an empty address: log out, watch nothing

    def _pass(self, seat: GuardianSeat, what: str, at: float | None = None) -> None:
        """A record from ``seat``: only the chosen seat's, and only once armed for it, reach the process."""
        with self._lock:
            handle = self._handle
            if seat is not self.chosen or seat.state is not SeatState.READY or handle is None:
                return
            if what == "beat_ui":
                handle.beat_ui(at)
            elif what == "beat_net":
                handle.beat_net()
            elif what == "arm":
                handle.arm()
            elif what == "disarm":
                handle.disarm()
            elif what == "halt":
                handle.halt()

    # -- hearing the process (its reader thread) -------------------------------------------------
    def _read(self, handle: GuardianHandle) -> None:
        while True:
            fd = handle.fileno()
            if fd < 0:
                return
            with contextlib.suppress(OSError, ValueError):
                select.select([fd], [], [], READ_PERIOD)
            with self._lock:
                if handle is not self._handle:
                    return
                for word, serial, text in handle.poll():
                    self._heard(word, serial, text)
                if not handle.alive:
                    return

    def _heard(self, word: str, serial: int, text: str) -> None:
        """One report (lock held)."""
        if word == "ended":
            seat = self.chosen
            self._handle = None
            self._broken = text  # said for a login asked before it may be started again
            if seat is not None and not self._closed and seat.state in (SeatState.ARMING, SeatState.READY):
                self._unavailable(seat, text)
            return
        seat = self._seats_by_serial.get(serial)
        if seat is None or seat is not self.chosen:
            return
        if word == m.READY:
            seat.state, seat.reason = SeatState.READY, ""
        elif word in (m.UNAVAILABLE, m.LOST):
            self._unavailable(seat, text)
        elif word == m.STOPPED:
            seat._said(m.STOPPED, text)

    # -- ending --------------------------------------------------------------------------------
    def close(self) -> None:
        """Goodbye to the process (it ends without a stop: the fleet has stopped every robot)."""
        with self._lock:
            self._closed = True
            handle, self._handle = self._handle, None
            self.chosen = None
        if handle is not None:
            handle.close(goodbye=True)
