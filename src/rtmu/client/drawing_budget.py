"""What a flood of drawings may cost: samples kept raw, decoded late, thinned to a budget.

A server may list 256 drawings of 3 998 points and send each every millisecond — well-formed
data, 20 000 samples a second. Decoding each sample into Python tuples on the network loop
(~0.3 ms apiece) left no time to send ``ratioDrive``, and drawing a million points a frame froze
the window. So the feed keeps only each drawing's newest *raw* sample (:func:`sample_array`
views it as numpy, checking its count against its bytes, only when it is about to be shown), and
:func:`thin` hands the window at most :data:`MAX_SHOWN_POINTS` points a frame over all drawings:
small drawings whole, large ones evenly thinned to a fair share of what is left (pairs kept
together for ``polySegments``). GTK-free and clock-free.
"""

from __future__ import annotations

import numpy as np

from ..protocol.payloads.drawings import MAX_POINTS, Shape
from .drawing_list import decode_points

MAX_SHOWN_POINTS = 6_000
"""Points handed to the window per update over all drawings: a frame of them draws in ~12 ms (12 000
took ~24 ms, and a key pressed during two such frames waited past 100 ms under a drawing flood)."""

Points = tuple[tuple[int, int], ...]


def sample_array(name: str, payload: bytes) -> np.ndarray:
    """One sample's points as an (n, 2) int32 view; a count its bytes cannot hold is refused with
    the decoder's own words (:class:`~rtmu.client.errors.MalformedReply`)."""
    if len(payload) >= 4:
        count = int.from_bytes(payload[:4], "little", signed=True)
        if 0 <= count <= MAX_POINTS and 4 + 8 * count <= len(payload):
            return np.frombuffer(payload, "<i4", count=2 * count, offset=4).reshape(-1, 2)
    decode_points(name, payload)  # raises, naming what is wrong
    raise AssertionError("unreachable: the decoder took a sample the fast path refused")


def thin(samples: dict[str, tuple[str, np.ndarray]], budget: int = MAX_SHOWN_POINTS) -> dict[str, Points]:
    """Each drawing's points within ``budget`` in all: ``samples`` maps a name to (shape, points).

    Smallest first, every drawing gets at most an equal share of what the ones before it left;
    a thinned drawing keeps every k-th point (every k-th segment for ``polySegments``).
    """
    out: dict[str, Points] = {}
    order = sorted(samples, key=lambda name: len(samples[name][1]))
    left = budget
    for i, name in enumerate(order):
        shape, points = samples[name]
        share = left // (len(order) - i)
        kept = _every_kth(points, share, pairs=shape == Shape.POLY_SEGMENTS)
        left -= len(kept)
        out[name] = tuple(map(tuple, kept.tolist()))
    return out


def _every_kth(points: np.ndarray, share: int, *, pairs: bool) -> np.ndarray:
    if len(points) <= share:
        return points
    if share <= 0:
        return points[:0]
    if pairs:
        segments = points[: len(points) // 2 * 2].reshape(-1, 2, 2)
        step = -(-len(segments) * 2 // max(share, 2))
        return segments[::step].reshape(-1, 2)
    step = -(-len(points) // share)
    return points[::step]
