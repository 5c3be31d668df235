"""What ``rtmu sim`` says about where it listens: one line per server, read by programs and people.

Programs (tests, benchmarks, scripts) read the port of ``--port 0`` from it through a pipe: there it is
the English of its :class:`~rtmu.base.i18n.Said`, the same in every language. At a terminal a person
reads it, in their language, its numbers as their language writes them.
"""

from __future__ import annotations

import sys

from ..base.i18n import Said
from ..base.units import Quantity


def start_line(said: Said) -> str:
    """A line that says where the simulator listens: read by programs when stdout is a pipe or a file
    (the port of ``--port 0``), so then its English, the same in every language; at a terminal a person
    reads it, in their language."""
    return said.words() if sys.stdout.isatty() else str(said)


def plain(value: float) -> Quantity:
    """A whole number in a start line: as it is for programs, the language's digits for people."""
    return Quantity(round(value), "")


def joined(parts: list[Said]) -> Said:
    """``; a; b`` of ``parts``, each said in the operator's language where the line is."""
    template = "".join(f"; {{part{i}}}" for i in range(len(parts)))
    return Said(template, **{f"part{i}": part for i, part in enumerate(parts)})
