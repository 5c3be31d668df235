"""Keep the garbage collector's full passes short in a long-lived process that must keep time.

CPython's cyclic collector now and then walks every object the process holds (a "generation 2"
pass), holding the interpreter lock throughout, so every thread of the process stands still. In
the simulator that is the world, the map and the protocol tables — 60 000 objects, 75–90 ms a
forced pass on the busy 2-core lab machine; a bare client core's 69 000 took 35–45 ms, and the
window had a 35 ms pass in 30 s of a drawing flood. Objects built at start-up live as long as the
process; :func:`settle` moves them out of the collector's sight (``gc.freeze``) once they are
built, so later passes walk only what came after. Cycles made later are still collected.
``bench/bench_heap.py`` measures it: the simulator's forced full pass 27–29 ms before, ~0 after.

A precaution, not the cause of the links lab's false stops: the traced soaks saw no pass over
5 ms in the simulator's process; its late status came from a thread waiting for a CPU
(``base.priority.raise_group_priority``).
"""

from __future__ import annotations

import gc


def settle() -> int:
    """Collect once, then freeze what is left: call when a process has built what it keeps for
    its whole life (a server started, a window shown). Returns how many objects were frozen."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()
