"""How much of the interpreter the recorder's writer may take: a duty cycle on its CPU time.

foxglove-sdk encodes, compresses and writes a chunk without letting go of Python's interpreter
lock. Under a flood of well-formed data (256 drawings × 3 998 points every 1 ms: tens of MB/s of
raw chunks) the writer thread held that lock nearly half the time, and every other Python
thread — the window's, the network loop that sends ``ratioDrive`` and ``stop`` — waited for it
(py-spy ``--gil``: 731 of 1 593 samples in ``Channel.log``; the window's release-to-stop p95
196 ms). So after each item the writer rests in proportion to the CPU time it just used, keeping
its share of one CPU at :data:`WRITER_SHARE` at most; a writer that falls behind fills its
bounded queue and the rest is dropped and counted (``Recording.dropped``), as for a slow disk.
A robot's normal few hundred KB/s never comes near the limit. Pure arithmetic over times passed in.
"""

from __future__ import annotations

WRITER_SHARE = 0.2
"""At most this share of one CPU (and of the interpreter lock) goes to writing the recording."""
REST_MIN = 0.002
"""Rests are taken once they add up to this much (one sleep per few items, not one per item)."""
DEBT_MAX = 0.25
"""Seconds of rest owed at most: one slow write (a chunk compressed while the machine was busy)
does not silence the writer for longer than this."""


class DutyCycle:
    """Owes ``cpu × (1 / share − 1)`` s of rest for every ``cpu`` s of work."""

    def __init__(self, share: float = WRITER_SHARE) -> None:
        if not 0.0 < share <= 1.0:
            raise ValueError(f"share must be in (0, 1], got {share!r}")
        self.share = share
        self.debt = 0.0
        self.rested = 0.0
        """Seconds of rest taken so far (for tests and figures)."""

    def worked(self, cpu_seconds: float) -> float:
        """Work of ``cpu_seconds`` was done; returns how long to rest now (0: go on)."""
        self.debt = min(DEBT_MAX, self.debt + max(0.0, cpu_seconds) * (1.0 / self.share - 1.0))
        if self.debt < REST_MIN:
            return 0.0
        rest, self.debt = self.debt, 0.0
        self.rested += rest
        return rest
