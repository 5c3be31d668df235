"""Keep the garbage collector's full passes short in a long-lived process that must keep time.

CPython's cyclic collector now and then walks every object the process holds (a "generation 2"
pass), holding the interpreter lock throughout, so every thread of the process stands still. In
the simulator that is the world, the map and the protocol tables — 60 000 objects, 75–90 ms a
pass on a busy 2-core machine, and longer when the machine takes the core away mid-pass: a
status the simulator should have sent every 50 ms came 437 ms late once in a 15-minute soak,
the simulator's thread neither running nor waiting for a CPU meanwhile, and a client stopped the
robot for a stale link. Objects built at start-up live as long as the process; :func:`settle`
moves them out of the collector's sight (``gc.freeze``) once they are built, so later passes
walk only what came after. Cycles made later are still collected.
"""

from __future__ import annotations

import gc


def settle() -> int:
    """Collect once, then freeze what is left: call when a process has built what it keeps for
    its whole life (a server started, a window shown). Returns how many objects were frozen."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()
