"""base.heap: what a process built at start-up leaves the collector's full passes; later cycles do not."""

from __future__ import annotations

import gc
import weakref

from rtmu.base.heap import hold, resume, settle


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


def test_held_start_up_makes_no_pass_until_it_settles_and_then_collects_again() -> None:
    passes: list[int] = []

    def count(phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            passes.append(info["generation"])

    gc.callbacks.append(count)
    try:
        hold()
        kept = [Node() for _ in range(20_000)]  # far past generation 0's threshold (700)
        assert passes == []  # held: not one pass while the start-up builds
        assert not gc.isenabled()
        settle()
        assert gc.isenabled()  # settling lets the collector run again
        later = Node()
        gone = weakref.ref(later)
        del later
        gc.collect()
        assert gone() is None
        assert len(kept) == 20_000
    finally:
        gc.callbacks.remove(count)
        resume()
        gc.unfreeze()


def test_resume_collects_again_after_a_start_up_that_never_settled() -> None:
    hold()
    try:
        assert not gc.isenabled()
    finally:
        resume()
    assert gc.isenabled()
