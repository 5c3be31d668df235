"""The test's side of ``fake_desktop``: start it on the session bus, read what the window asked of it."""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from .harness import pump

HERE = Path(__file__).parent


class Desktop:
    def __init__(self) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, str(HERE / "fake_desktop.py")],
            stdout=subprocess.PIPE, text=True, env=dict(os.environ),
        )  # fmt: skip
        self.lines: queue.Queue[dict[str, Any]] = queue.Queue()
        self.calls: list[dict[str, Any]] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.put(json.loads(line))

    def heard(self) -> list[dict[str, Any]]:
        while not self.lines.empty():
            self.calls.append(self.lines.get())
        return [c for c in self.calls if "call" in c]

    def of(self, *names: str) -> list[dict[str, Any]]:
        """The calls heard so far with these method names."""
        return [c for c in self.heard() if c["call"] in names]

    def ready(self) -> bool:
        self.heard()
        return any(c.get("ready") for c in self.calls)


@contextmanager
def fake_desktop() -> Iterator[Desktop]:
    """Started before the window (GTK looks for the session manager at start-up), ended after it."""
    sm = Desktop()
    try:
        pump(sm.ready, 15, "the fake desktop to own its names")
        yield sm
    finally:
        sm.proc.terminate()
        sm.proc.wait(10)
