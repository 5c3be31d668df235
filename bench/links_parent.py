"""A driving process for ``bench_links``: the window's client core, its UI thread played by a thread.

``python -m bench.links_parent PORT``: runner + lease + lease keeper + guardian, as the window
builds them (``RTMU_LINK_TIMING=fixed`` in its environment: the old fixed limits). A "UI" thread
does what the window's GTK thread does — some work per frame (GIL-free, as GTK renders in C),
a heartbeat every 40 ms and a lease renewal every 100 ms while the key is held — and the drive
is held from the start. It prints ``ui TID`` (so a bench can pin or starve that thread) and
``driving``, then one line per event:

* ``stop T REASON`` — zero ratios + ``stop`` handed to the socket (``T``: ``time.monotonic()``,
  one clock for every process), with the session's reason;
* ``guardian T TEXT`` — a notice of the safety kind (the guardian stopped the robot);
* ``log T TEXT`` — an ``rtmu`` log line at info level (each stop's measured account: status age,
  learned limit, jitter, wake lateness, load).

Commands on stdin: ``press`` (a fresh key press), ``release T`` (the operator lets go at monotonic
``T``; the UI thread acts on it when it next runs, as GTK handles a queued key-up), ``freeze S``
(the UI thread is busy with its own work for S seconds: a truly frozen window), ``quit``.
"""

from __future__ import annotations

import hashlib
import logging
import sys
import threading
import time

from rtmu.base.notices import Kind, Notice
from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.guardian.handle import BEAT_PERIOD
from rtmu.values.target import Target

DRIVE = DriveRatios(40.0, 0.0, 40.0)
FRAME_WORK = 0.008
"""CPU seconds of (GIL-free) work per UI frame: a window redrawing its map and status."""
RENEW_EVERY = 0.1
BLOCK = bytes(256 * 1024)


def frame_work(cpu_seconds: float) -> None:
    start = time.thread_time()
    while time.thread_time() - start < cpu_seconds:
        hashlib.sha256(BLOCK).digest()  # releases the GIL, like GTK's rendering in C


_SAY = threading.Lock()


def say(*words: object) -> None:
    """One whole line at a time (the UI thread and the network thread both report)."""
    with _SAY:
        sys.stdout.write(" ".join(str(w) for w in words) + "\n")
        sys.stdout.flush()


class Ui:
    """The UI thread's loop; see the module notes."""

    def __init__(self, runner: ClientRunner) -> None:
        self.runner = runner
        self.held = True
        self.release_at: float | None = None
        self.freeze_for = 0.0
        self.lock = threading.Lock()

    def run(self) -> None:
        say("ui", threading.get_native_id())
        last_renew = time.monotonic()
        while True:
            with self.lock:
                freeze, self.freeze_for = self.freeze_for, 0.0
                release_at = self.release_at
            if freeze:
                end = time.monotonic() + freeze
                while time.monotonic() < end:  # a truly frozen window: its own work, no events
                    pass
            if release_at is not None and time.monotonic() >= release_at and self.held:
                self.held = False  # the key-up is handled now that the thread runs again
                self.runner.lease.release()
            frame_work(FRAME_WORK)
            self.runner.ui_heartbeat()
            now = time.monotonic()
            if self.held and now - last_renew >= RENEW_EVERY - 0.005:
                last_renew = now
                self.runner.lease.renew()
            time.sleep(BEAT_PERIOD)

    def press(self) -> None:
        with self.lock:
            self.release_at = None
        self.held = True
        self.runner.lease.grant(DRIVE)


class SayLog(logging.Handler):
    """``rtmu`` log lines (a stop's measured account) as ``log T TEXT`` lines for the bench."""

    def emit(self, record: logging.LogRecord) -> None:
        say("log", f"{time.monotonic():.6f}", self.format(record).replace("\n", " "))


def main() -> int:
    port = int(sys.argv[1])
    logger = logging.getLogger("rtmu")
    logger.addHandler(SayLog(logging.INFO))
    logger.setLevel(logging.INFO)
    runner = ClientRunner(config=SessionConfig(fetch_map=False, guardian=True)).start()
    runner.on_stop = lambda reason, sent: say("stop", f"{time.monotonic():.6f}", reason.replace("\n", " "))

    def notice(n: Notice) -> None:
        if n.kind is Kind.SAFETY:
            say("guardian", f"{time.monotonic():.6f}", n.text.replace("\n", " "))

    runner.on_notice_sent = notice
    runner.connect(Target("127.0.0.1", port)).result(15)
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:  # drive once the guardian is up (or gave up)
        runner.sync()
        g = runner.session.guardian if runner.session else None
        if g is None or g.waiting_reason() is None:  # armed, or unavailable (then it drives unguarded)
            break
        time.sleep(0.02)
    ui = Ui(runner)
    threading.Thread(target=ui.run, name="ui", daemon=True).start()
    ui.press()
    say("driving")
    for line in sys.stdin:
        if not line.split():
            continue
        word, *rest = line.split()
        if word == "press":
            ui.press()
        elif word == "release":
            with ui.lock:
                ui.release_at = float(rest[0])
        elif word == "freeze":
            with ui.lock:
                ui.freeze_for = float(rest[0])
        elif word == "quit":
            break
    runner.close()
    say("done")
    return 0


if __name__ == "__main__":
    sys.exit(main())
