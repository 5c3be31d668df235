"""Keep the garbage collector's full passes short in a long-lived process that must keep time.

CPython's cyclic collector now and then walks every object the process holds (a "generation 2"
pass), holding the interpreter lock throughout, so every thread of the process stands still. In
the simulator that is the world, the map and the protocol tables — 60 000 objects, 75–90 ms a
forced pass on the busy 2-core lab machine; a bare client core's 69 000 took 35–45 ms, and the
window had a 35 ms pass in 30 s of a drawing flood. Objects built at start-up live as long as the
process; :func:`settle` moves them out of the collector's sight (``gc.freeze``) once they are
built, so later passes walk only what came after. Cycles made later are still collected.
``bench/bench_heap.py`` measures it: the simulator's forced full pass 27–29 ms before, ~0 after.

A process that builds for a while before it settles (the window: its modules, GTK's and the first
widgets) calls :func:`hold` first: the collector then does not run at all until :func:`settle`,
which is where every pass made during the build would have ended anyway (its objects survive).
The window's start-up made 141 passes, a 40–47 ms full one among them: 76–92 ms of its launch.

A precaution, not the cause of the links lab's false stops: the traced soaks saw no pass over
5 ms in the simulator's process; its late status came from a thread waiting for a CPU
(``base.priority.raise_group_priority``).
"""

from __future__ import annotations

import gc


def hold() -> None:
    """No collection until :func:`settle` (call before a start-up that builds what it keeps)."""
    gc.disable()


def resume() -> None:
    """Collect again (idempotent): for a start-up that ended before it could :func:`settle`."""
    gc.enable()


def settle() -> int:
    """Collect once, then freeze what is left, and collect again from now on: call when a process
    has built what it keeps for its whole life (a server started, a window shown). Returns how many
    objects were frozen."""
    gc.collect()
    gc.freeze()
    gc.enable()
    return gc.get_freeze_count()
