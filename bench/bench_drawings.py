"""The server's drawings: decoding a sample, refusing a lying one, and drawing them in a frame.

* ``drawings.decode_max_us`` — one packet of 3 998 points (the most one packet holds) decoded
  into ``DrawingPoints``; baseline: the same bytes viewed as a numpy array (no tuples).
* ``drawings.refuse_lying_count_us`` — a packet that claims 1 000 000 points refused; baseline:
  decoding an honest empty sample (both should be a few µs: nothing is allocated for the lie).
* ``drawings.frame_sim_ms`` — an 800×480 frame (no map) with the simulator's laser (181 dots) and
  sonar (16 arrows) drawn; baseline: the same frame without drawings.
* ``drawings.frame_max_ms`` — the same frame with a 3 998-dot drawing (the hostile maximum).
"""

from __future__ import annotations

import math
import struct

import cairo
import numpy as np

from rtmu.protocol.errors import PayloadError
from rtmu.protocol.payloads.drawings import MAX_POINTS, DrawingPoints
from rtmu.ui import overlays
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.viewport import Viewport
from rtmu.values.state import DrawingLayer

from .common import Result, best_time


def _frame_ms(layers: tuple[DrawingLayer, ...]) -> float:
    vp = Viewport(800, 480, 0.5, 0.0, 0.0)
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, vp.width, vp.height)
    ctx = cairo.Context(surface)
    scene = Scene(labels=overlays.LabelCache(), robot=(0.0, 0.0, 0.0), drawings=layers)
    return best_time(lambda: draw_frame(ctx, vp, scene), repeat=5, min_seconds=0.3) * 1000


def run() -> list[Result]:
    points = tuple((i * 3 - 6000, (i % 97) * 40 - 2000) for i in range(MAX_POINTS))
    wire = DrawingPoints(points).encode()
    decode = best_time(lambda: DrawingPoints.decode(wire)) * 1e6
    view = best_time(lambda: np.frombuffer(wire, "<i4", offset=4).reshape(-1, 2)) * 1e6

    lying = struct.pack("<i", 1_000_000) + wire[4:]

    def refuse() -> None:
        try:
            DrawingPoints.decode(lying)
        except PayloadError:
            return
        raise AssertionError("a lying count was accepted")

    refused = best_time(refuse) * 1e6
    empty = DrawingPoints().encode()
    honest_empty = best_time(lambda: DrawingPoints.decode(empty)) * 1e6

    laser = tuple(
        (round(4000 * math.cos(math.radians(a - 90))), round(4000 * math.sin(math.radians(a - 90))))
        for a in range(181)
    )
    sonar = tuple(
        (round(2500 * math.cos(math.radians(a))), round(2500 * math.sin(math.radians(a))))
        for a in range(0, 360, 23)
    )
    sim_layers = (
        DrawingLayer("sonarCurrent", "polyArrows", True, 0x33CCFF, 200, 70, 200, True, True, sonar),
        DrawingLayer("sim_lms2xx_1Current", "polyDots", True, 0x0000FF, 80, 75, 200, True, True, laser),
    )
    max_layer = (DrawingLayer("max", "polyDots", True, 0xFF00FF, 80, 75, 20, True, True, points),)
    plain = _frame_ms(())
    return [
        Result("drawings.decode_max_us", decode, "us", view),
        Result("drawings.refuse_lying_count_us", refused, "us", honest_empty),
        Result("drawings.frame_sim_ms", _frame_ms(sim_layers), "ms", plain),
        Result("drawings.frame_max_ms", _frame_ms(max_layer), "ms", plain),
    ]
