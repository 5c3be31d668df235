"""The guardian: a separate process that stops the robot when the window can no longer do it.

The window starts ONE for all its robots (:class:`~rtmu.guardian.shared.SharedGuardian`), armed
for the robot that may drive — the selected one — and armed again for the next one on a new
selection; ``rtmu drive`` and ``rtmu bridge --allow-drive`` start one each
(:class:`~rtmu.guardian.handle.GuardianHandle`). It logs in on its own connection (a plain socket
and the sans-I/O codec, :mod:`.login`: it imports nothing of the client) with credentials read
from its stdin pipe, then listens: while the parent says motion may be commanded ("armed"),
heartbeats must keep coming from the parent's UI and network threads. A parent that dies (EOF on
the pipe), is stopped by a signal, or goes silent for longer than a drive lease can live gets
zero ``ratioDrive`` + ``stop`` at once (:mod:`.halt` — the only thing the guardian can send). See
:mod:`.child` for the thresholds and why.
"""
