"""Options several subcommands share, each defined once: one name per meaning, real limits, old names kept.

``--fps`` is "ask for camera pictures at most this often" wherever it appears (``video``, ``record``,
``bridge``; ``--camera-hz`` is its old spelling there, still accepted but not shown). ``--quality`` is
the JPEG quality asked of the server. Values out of range are refused with the limits (exit 2),
never clamped silently: a quality of −5 would degrade the camera every client shares.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from ..client.defaults import MAX_FPS, MIN_FPS

QUALITY_MIN = 1
QUALITY_MAX = 100
"""ARIA's JPEG quality, as ``sendVideo`` takes it (0 would ask the camera for nothing usable)."""


def plain(value: float) -> str:
    """A limit as the operator would type it: ``1000000``, ``0.5`` — never ``1e+06``."""
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


def number_in(
    low: float, high: float, *, integer: bool = False, zero: bool = False
) -> Callable[[str], float]:
    """An argparse ``type`` that refuses values outside ``low…high`` (``zero``: 0 is allowed too)."""

    def parse(text: str) -> float:
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            kind = "a whole number" if integer else "a number"
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}") from None
        if zero and value == 0:
            return value
        if not (math.isfinite(value) and low <= value <= high):
            extra = " (or 0)" if zero else ""
            raise argparse.ArgumentTypeError(f"{text} is out of range: use {plain(low)}…{plain(high)}{extra}")
        return value

    parse.__name__ = "number"  # argparse names the type in its messages
    return parse


def add_fps_option(parser: argparse.ArgumentParser, *, default: float, none_means: str = "") -> None:
    """``--fps N``: pictures per second at most; ``--camera-hz`` is its old, hidden spelling."""
    zero = bool(none_means)
    shown = f"{default:g}" + (f" = {none_means}" if zero and default == 0 else "")
    extra = f"; 0: {none_means}" if zero else ""
    kind = number_in(MIN_FPS, MAX_FPS, zero=zero)
    parser.add_argument(
        "--fps",
        type=kind,
        default=default,
        metavar="N",
        help=f"camera pictures per second at most, {MIN_FPS:g}…{MAX_FPS:g}{extra} (default {shown})",
    )
    parser.add_argument("--camera-hz", dest="fps", type=kind, help=argparse.SUPPRESS)


def add_quality_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--quality",
        type=number_in(QUALITY_MIN, QUALITY_MAX, integer=True),
        default=None,
        metavar="Q",
        help=f"JPEG quality to ask the camera for, {QUALITY_MIN}…{QUALITY_MAX} "
        "(default: the server's; it applies to every client of that camera)",
    )
