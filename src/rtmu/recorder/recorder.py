"""The flight recorder of one robot session: a new file per connection target, fed from every side.

A :class:`Recorder` belongs to one :class:`rtmu.fleet.sessions.RobotSession`. Its opener tees
every link the session's client opens; the first link to a robot starts a
:class:`~rtmu.recorder.recording.Recording` (reconnects to the same robot keep
writing the same file, as new connections in it) and a disconnect or a final
failure ends it. Everything else arrives through small hooks, each a non-blocking
queue put: the session's published changes and notices (network thread), the stops
it sent and why, the drive lease's events and the operator's intents (UI thread).
A new file starts with the latest value of every part, so it stands on its own.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from ..base.notices import Kind, Level, Notice
from ..client.lease import LeaseEvent
from ..client.link import Opener, open_tcp
from ..client.runner import ClientRunner
from ..values.state import ConnectionChanged, Phase, StateChange
from . import files, scrub, topics
from .convert import jsonable, notice_record
from .items import Event, Item, LinkOpened, Published, RawChunk
from .recording import Limits, Recording
from .scrub import LoginScrubber
from .tee import RawSink, tee_opener

ENDS_A_RECORDING = (Phase.DISCONNECTED, Phase.FAILED)
WAITING_EVENTS = 64


@dataclass(frozen=True, slots=True)
class RecorderConfig:
    """Where and how much; :mod:`rtmu.settings.store` ``RecordingSettings`` fills it."""

    directory: Path
    path: Path | None = None
    """Write exactly this file (``rtmu record --out``) instead of a new name per session."""
    max_bytes: int = 1 << 30
    keep_days: float = 30.0
    limits: Limits | None = None
    """Writer details (flush and sync periods, queue size); None: the defaults with ``max_bytes``."""


class Recorder:
    """Thread-safe. ``notify`` gets the recorder's own notices (on whatever thread raises them)."""

    def __init__(self, config: RecorderConfig, notify: Callable[[Notice], None] | None = None) -> None:
        self.config = config
        self.notify = notify or (lambda notice: None)
        self.recording: Recording | None = None
        """The file being written now (None between sessions)."""
        self.recordings: list[Recording] = []
        """Every recording this recorder started, oldest first."""
        self._lock = threading.Lock()
        self._target: tuple[str, int] | None = None
        self._conn = 0
        self._latest: dict[type, StateChange] = {}
        self._waiting: deque[Item] = deque(maxlen=WAITING_EVENTS)
        """Events from before the link opened (the connect intent itself): the next file starts with them."""

    def attach(self, runner: ClientRunner) -> None:
        """Hook the runner's taps (changes, notices, stops, lease events) and tell the operator through it.

        The runner must have been built with ``opener=self.opener()`` for the raw bytes.
        """
        runner.on_publish = self.published
        runner.on_notice_sent = self.notice
        runner.on_stop = self.stopped
        runner.lease.on_event = self.lease_event
        self.notify = runner.notify

    # -- the client's links (network thread) ---------------------------------------------------
    def opener(self, inner: Opener = open_tcp) -> Opener:
        """An opener for the session's clients: ``inner``'s links, tee'd into the recording."""
        return tee_opener(inner, self._link_opened)

    def _link_opened(self, host: str, port: int) -> tuple[int, RawSink] | None:
        with self._lock:
            recording = self.recording
            if recording is not None and recording.stopped is not None and self._target == (host, port):
                return None  # stopped for a full disk or its limit: not again on every reconnect
            if recording is None or self._target != (host, port):
                recording = self._start(host, port)
            if recording is None:
                return None
            self._conn += 1
            conn = self._conn
        now = time.time_ns()
        recording.submit(LinkOpened(conn, host, port, now))
        return conn, partial(_raw_to, recording, LoginScrubber())

    def _start(self, host: str, port: int) -> Recording | None:
        old = self.recording
        if old is not None:
            old.end()
        limits = self.config.limits or Limits(max_bytes=self.config.max_bytes)
        path = self.config.path or files.new_path_name(self.config.directory, f"{host}_{port}")
        metadata = {
            "robot": f"{host}:{port}",
            "started_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            **scrub.METADATA,
        }
        recording = Recording(path, metadata=metadata, limits=limits, on_problem=self.notify)
        recording.prune = partial(files.prune, self.config.directory, self.config.keep_days)
        self.recording = recording
        self.recordings.append(recording)
        self._target = (host, port)
        self._conn = 0
        recording.start()
        now = time.time_ns()
        for change in self._latest.values():  # the file starts with the whole picture
            recording.submit(Published(change, now))
        while self._waiting:
            recording.submit(self._waiting.popleft())
        return recording

    # -- what the session publishes (network thread) --------------------------------------------
    def published(self, change: StateChange) -> None:
        with self._lock:
            self._latest[type(change)] = change
            recording = self.recording
            if recording is None:
                return
            recording.submit(Published(change, time.time_ns()))
            if isinstance(change, ConnectionChanged) and change.value.phase in ENDS_A_RECORDING:
                recording.end()
                self.recording = None
                self._target = None

    def notice(self, notice: Notice) -> None:
        now = time.time_ns()
        self._submit(Event(topics.NOTICES, notice_record(notice), now))
        if notice.kind is Kind.SAFETY and notice.level is Level.ERROR:  # the guardian stopped the robot
            self._submit(Event(topics.STOPS, {"by": "guardian", "reason": notice.text}, now))

    def stopped(self, reason: str, sent: bool = True) -> None:
        """The session sent zero ratios + ``stop`` (``sent``: it left; False: no link to send it on)."""
        self._submit(Event(topics.STOPS, {"by": "client", "reason": reason, "sent": sent}, time.time_ns()))

    # -- the UI side ------------------------------------------------------------------------------
    def lease_event(self, event: LeaseEvent) -> None:
        self._submit(Event(topics.LEASE, jsonable(event), time.time_ns()))

    def intent(self, name: str, args: dict[str, Any]) -> None:
        self._submit(Event(topics.INTENTS, {"intent": name, **jsonable(args)}, time.time_ns()))

    def _submit(self, item: Item) -> None:
        with self._lock:
            recording = self.recording
            if recording is None:
                self._waiting.append(item)
                return
        recording.submit(item)

    # -- the end ------------------------------------------------------------------------------------
    def close(self, timeout: float = 5.0) -> None:
        """Finish every file still being written (one bounded wait for them all)."""
        with self._lock:
            self.recording = None
            self._target = None
            recordings = list(self.recordings)
        for recording in recordings:
            recording.end()
        deadline = time.monotonic() + timeout
        for recording in recordings:
            recording.close(max(0.0, deadline - time.monotonic()))


def _raw_to(recording: Recording, scrubber: LoginScrubber, chunk: RawChunk) -> None:
    if chunk.direction == "c2s":
        data = scrubber(chunk.data)  # the login's password digest is never recorded (recorder.scrub)
        if not data:
            return
        if data is not chunk.data:
            chunk = RawChunk(chunk.conn, chunk.direction, data, chunk.at_ns)
    recording.submit(chunk)
