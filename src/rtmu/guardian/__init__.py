"""The guardian: a separate process that stops the robot when the window can no longer do it.

The window (and ``rtmu drive``) starts one per connection that may drive
(:class:`~rtmu.guardian.handle.GuardianHandle`). It logs in on its own
connection with credentials read from its stdin pipe, then listens: while the
parent says motion may be commanded ("armed"), heartbeats must keep coming
from the parent's UI and network threads. A parent that dies (EOF on the pipe),
is stopped by a signal, or goes silent for longer than a drive lease can live
gets zero ``ratioDrive`` + ``stop`` at once (:mod:`.halt` — the only thing the
guardian can send). See :mod:`.child` for the thresholds and why.
"""
