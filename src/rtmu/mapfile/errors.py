"""The map format's one exception and its warning record: a map is whole or refused, never half-built."""

from __future__ import annotations

from typing import NamedTuple


class MapFormatError(Exception):
    """A map file (or a streamed map) cannot be used; says which source and, when known, which line."""

    def __init__(self, message: str, source: str = "<map>", line: int | None = None) -> None:
        where = f"{source}:{line}" if line is not None else source
        super().__init__(f"{where}: {message}")
        self.message = message
        self.source = source
        self.line = line


class MapWarning(NamedTuple):
    """Something odd that ARIA tolerates too (a garbage data line is skipped), kept for reporting."""

    line: int
    message: str


MAX_KEPT_WARNINGS = 100
"""Warnings beyond this are only counted: a hostile file with millions of bad lines must not cost memory."""


class WarningLog:
    """Collects warnings while a map is read: keeps the first few, counts them all."""

    def __init__(self, limit: int = MAX_KEPT_WARNINGS) -> None:
        self.limit = limit
        self.kept: list[MapWarning] = []
        self.count = 0
        self.skipped_lines = 0

    def add(self, line: int, message: str) -> None:
        self.count += 1
        if len(self.kept) < self.limit:
            self.kept.append(MapWarning(line, message))

    def skip(self, line: int, message: str) -> None:
        """A data line was skipped."""
        self.skipped_lines += 1
        self.add(line, message)

    def skip_unreported(self, how_many: int) -> None:
        """Lines skipped beyond what is worth describing one by one."""
        self.skipped_lines += how_many
        self.count += how_many
