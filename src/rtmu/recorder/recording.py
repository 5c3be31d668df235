"""One recording: one MCAP file, filled by its own writer thread from a bounded queue.

The threads that produce (the network loop that sends the stops, the UI thread) only
append a small item: they never encode, compress, write, wait or wake the writer. When the
writer falls behind and the queue is full, the item is dropped and counted (the file
says how many) — a slow disk can cost recorded data, never a late stop. The writer itself
takes at most a fifth of a CPU (:mod:`.duty`): foxglove-sdk holds the interpreter lock while
it compresses, and a flood recorded at full speed starved every other Python thread of it. A full disk,
a failed write or the size cap ends the recording with one notice; the session goes on.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..capture.recorded import CONNECTION_TOPIC, RAW_TOPICS, connection_record
from . import topics
from .convert import REPEAT_EVERY, Converter
from .duty import DutyCycle
from .files import variant
from .items import Event, Item, LinkOpened, Published, RawChunk
from .mcapfile import McapFile

log = logging.getLogger(__name__)

QUEUE_ITEMS = 4096
"""Items waiting for the writer; at 10 Hz status plus 10 camera frames/s that is minutes of slack."""
QUEUE_BYTES = 32 << 20
"""…and at most this many bytes of raw chunks among them: a flood's 64 KB reads filled 4 096 items
with 256 MB while the writer kept to its share of the CPU."""
FLUSH_SECONDS = 1.0
"""A chunk is closed (and handed to the OS) this often, at the writer's next wake: a crash loses at
most this much and one :data:`GATHER_SECONDS` more (a second and a half)."""
SYNC_SECONDS = 5.0
"""…and ``fsync``-ed this often: a power loss loses at most this much."""
CLOSE_TIMEOUT = 5.0
GATHER_SECONDS = 0.5
"""The writer sleeps this long after emptying its queue: a still robot's dozen packets a second
wake it twice a second rather than at each packet (a thread switch each, on the network loop's
side too; at 0.25 s the idle window's writer cost 0.26 % of a core, at 0.5 s 0.21 %, issue 28);
closing wakes it at once. The chunk that is due to close (:data:`FLUSH_SECONDS`) closes at the
next of these wakes. Nothing else wakes it: an item waits at most this long (or until the next
repeat), and the producers pay a plain append, with no lock handed over."""
IDLE_WAIT = 1.0
"""A stopped recording only drains its queue until it is closed: it waits this long per look."""


@dataclass(frozen=True, slots=True)
class Limits:
    max_bytes: int = 1 << 30
    """The file stops growing here (the recording ends with a notice)."""
    flush_seconds: float = FLUSH_SECONDS
    sync_seconds: float = SYNC_SECONDS
    queue_items: int = QUEUE_ITEMS
    queue_bytes: int = QUEUE_BYTES


class Recording:
    """``Recording(path, …).start()``; ``submit`` from any thread; ``close()`` once."""

    def __init__(
        self,
        path: Path,
        *,
        metadata: dict[str, str] | None = None,
        limits: Limits | None = None,
        on_problem: Callable[[Notice], None] | None = None,
    ) -> None:
        self.path = path
        self.metadata = metadata or {}
        self.limits = limits or Limits()
        self.on_problem = on_problem or (lambda notice: None)
        self.dropped = 0
        """Items not recorded because the queue was full."""
        self.written_items = 0
        self.stopped: str | None = None
        """Why the recording ended early (full disk, size cap); None while it records."""
        self.prune: Callable[[], object] | None = None
        """Run on the writer thread before the file is made (forgetting old recordings)."""
        self._items: deque[object] = deque()
        """Waiting for the writer (at most ``limits.queue_items``, counted under ``_count``)."""
        self._bytes_in = 0
        """Raw bytes queued so far (under ``_count``; the writer counts what it took in ``_bytes_out``)."""
        self._bytes_out = 0
        self._count = threading.Lock()
        self._ending = threading.Event()
        self._thread = threading.Thread(target=self._run, name="rtmu-recorder", daemon=True)
        self._file: McapFile | None = None
        self._opened = threading.Event()
        self._conn: int | None = None
        self._targets: dict[int, tuple[str, int]] = {}
        self._closed = False
        self._converter = Converter()
        self.duty = DutyCycle()
        """Keeps the writer's share of the CPU (and of the interpreter lock) bounded (``duty``)."""

    # -- any thread ----------------------------------------------------------------------------
    def start(self) -> Recording:
        """Start the writer thread; it makes the file (a failure becomes a notice, never an exception)."""
        self._thread.start()
        return self

    def submit(self, item: Item) -> bool:
        """Queue ``item`` without waiting; False (and counted) when the writer is behind or stopped."""
        if self.stopped is not None or self._ending.is_set():
            return False
        size = len(item.data) if isinstance(item, RawChunk) else 0
        with self._count:
            if len(self._items) >= self.limits.queue_items or (
                size and self._bytes_in - self._bytes_out + size > self.limits.queue_bytes
            ):
                self.dropped += 1
                return False
            self._items.append(item)
            self._bytes_in += size
        return True

    def end(self) -> None:
        """Finish soon, without waiting (the network loop's way): what is queued is still written."""
        self._ending.set()

    def close(self, timeout: float = CLOSE_TIMEOUT) -> None:
        """:meth:`end`, then wait (bounded) until the file is finished (its summary written)."""
        self.end()
        if self._thread.is_alive():
            self._thread.join(timeout)

    # -- the writer thread ---------------------------------------------------------------------
    def _run(self) -> None:
        try:
            if self.prune is not None:
                self.prune()
            file = self._file = self._create()
        except Exception as exc:
            why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            self._stop(f"{self.path} could not be created ({why})", started=False)
            return
        now = time.monotonic()
        flush_at, sync_at = now + self.limits.flush_seconds, now + self.limits.sync_seconds
        repeat_at = now + REPEAT_EVERY
        reported_drops = 0
        items = self._items
        while True:
            if not items:
                if self._ending.is_set():
                    break  # closing, and everything queued is written
                due = min(flush_at, repeat_at)
                self._ending.wait(IDLE_WAIT if self.stopped is not None else max(0.0, due - time.monotonic()))
            item = items.popleft() if items else None
            wrote = self.stopped is None and item is not None
            if wrote:
                started = time.thread_time()
                self._write(file, item)  # type: ignore[arg-type]
                rest = self.duty.worked(time.thread_time() - started)
                if rest and not self._ending.is_set():  # (closing drains at full speed)
                    self._ending.wait(rest)
            if self.stopped is not None:
                self._finish(file)  # keep what was written readable at once; drain the rest
                continue
            now = time.monotonic()
            # A parked robot: its pose in every second — only once the writer has caught up, so a
            # repeat never stamps "now" on a pose older than ones still waiting in the queue.
            if self.stopped is None and now >= repeat_at and not items:
                repeat_at = now + REPEAT_EVERY
                at_ns = time.time_ns()
                for topic, message in self._converter.repeat(at_ns):
                    self._log(file, topic, message, at_ns)
            if self.stopped is None and now >= flush_at:
                if self.dropped != reported_drops:
                    reported_drops = self.dropped
                    self._log(
                        file, topics.RECORDER, {"event": "dropped", "items": self.dropped}, time.time_ns()
                    )
                sync = now >= sync_at
                self._guard(file, partial(file.flush, sync=sync))
                flush_at = now + self.limits.flush_seconds
                if sync:
                    sync_at = now + self.limits.sync_seconds
            if wrote and not items:  # let the next items gather: one wake-up for many, not one each
                # (after the repeat above: a repeat is due only while the writer has caught up, and a
                # still robot's raw packets keep the queue from being empty after a gathering wait;
                # it ends at the repeat's time, and a flush waits for it: one wake does all three)
                self._ending.wait(max(0.0, min(GATHER_SECONDS, repeat_at - time.monotonic())))
        if self.stopped is None and self.dropped != reported_drops:
            self._log(file, topics.RECORDER, {"event": "dropped", "items": self.dropped}, time.time_ns())
        self._finish(file)

    def _finish(self, file: McapFile) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            file.close()
        except Exception as exc:  # a failed file: the part before the failure still reads
            if self.stopped is None:
                self._stop(f"the file could not be finished: {exc}")

    def _create(self) -> McapFile:
        """The file, in a private directory; a name taken already (same robot, same second) gets ``-N``."""
        self.path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        first = self.path
        for n in range(1, 100):
            self.path = variant(first, n)
            try:
                return McapFile(self.path, self.metadata)
            except FileExistsError:
                continue
        raise FileExistsError(f"{first} and 98 variants of it exist already")

    def _write(self, file: McapFile, item: Item) -> None:
        if isinstance(item, RawChunk):
            with self._count:
                self._bytes_out += len(item.data)
            if item.conn != self._conn and item.conn in self._targets:  # another connection's chunks
                self._conn = item.conn
                host, port = self._targets[item.conn]
                self._log(file, CONNECTION_TOPIC, connection_record(item.conn, host, port), item.at_ns)
            self._log(file, RAW_TOPICS[item.direction], item.data, item.at_ns)
        elif isinstance(item, LinkOpened):
            self._conn = item.conn
            self._targets[item.conn] = (item.host, item.port)
            self._log(file, CONNECTION_TOPIC, connection_record(item.conn, item.host, item.port), item.at_ns)
        elif isinstance(item, Published):
            try:
                out = self._converter.change(item.change, item.at_ns)
            except Exception:  # a value we cannot convert must not end the recording
                log.exception("recording %s failed", type(item.change).__name__)
                return
            for topic, message in out:
                self._log(file, topic, message, item.at_ns)
        elif isinstance(item, Event):
            self._log(file, item.topic, item.record, item.at_ns)
        self.written_items += 1
        if self.stopped is None and file.written > self.limits.max_bytes:
            self._stop(f"the file reached its size limit ({self.limits.max_bytes / 1e6:g} MB)")

    def _log(self, file: McapFile, topic: str, message: object, at_ns: int) -> None:
        self._guard(file, lambda: file.log(topic, message, at_ns))

    def _guard(self, file: McapFile, action: Callable[[], None]) -> None:
        if self.stopped is not None:
            return
        try:
            action()
        except Exception as exc:
            self._stop(_why(file, exc))
            return
        if file.file.error is not None:  # foxglove-sdk logs a failed write rather than raising it
            self._stop(_why(file, file.file.error))

    def _stop(self, why: str, *, started: bool = True) -> None:
        self.stopped = why
        log.warning("recording %s stopped: %s", self.path, why)
        after = _("; {path} keeps what came before").format(path=self.path) if started else ""
        self.on_problem(
            Notice.warning(
                Kind.RECORDING,
                _("Recording stopped: {why}. The session goes on{after}.").format(why=why, after=after),
            )
        )


def _why(file: McapFile, exc: BaseException) -> str:
    error = file.file.error
    if error is not None:
        return f"writing {file.path.name} failed ({error.strerror or error})"
    return f"writing {file.path.name} failed ({exc})"
