"""base.heap: what a process built at start-up leaves the collector's full passes; later cycles do not."""

from __future__ import annotations

import gc
import weakref

from rtmu.base.heap import settle


class Node:
    def __init__(self) -> None:
        self.me = self  # a cycle: only the cyclic collector frees it


def test_settled_objects_are_out_of_the_full_passes_and_later_cycles_still_go() -> None:
    kept = [Node() for _ in range(1000)]
    try:
        frozen = settle()
        assert frozen >= 1000
        walked = {id(o) for o in gc.get_objects()}  # what a full pass walks now
        assert not any(id(n) in walked for n in kept)
        later = Node()
        gone = weakref.ref(later)
        del later
        gc.collect()
        assert gone() is None  # a cycle made after settling is still collected
    finally:
        gc.unfreeze()  # the rest of the test run as it was
