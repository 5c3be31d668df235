"""Scanning for a map (``ArServerHandlerMapping``): start and stop a laser scan log, ask whether one runs.

``mappingStart`` takes the scan's name; the server lowers its case and writes ``<name>.2d`` (unless the
name already holds ``.2d``) into its files folder while the robot is driven, and answers one ``byte``.
``mappingEnd`` closes it. ARIA answers an end with a ``ubyte2`` 0 or 2 but "nothing to end" with a one-byte
1, so both widths are read. ``mappingStatus`` names the scan (``""`` when none); ``mappingStatusBroadcast``
is the same data, and is also sent to its subscribers when a scan starts (carrying the *file* name) and
ends (``""``). ``mappingLoopStart`` / ``mappingLoopEnd`` are simple string commands that put a loop tag
in the log, to help the map builder close loops.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from enum import IntEnum
from typing import Final, Self

from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, SingleField, register

MAX_SCAN_NAME: Final = 511
"""ARIA reads the name into a 512-byte buffer."""
SCAN_SUFFIX: Final = ".2d"
_ASCII_LOWER: Final = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")


def scan_file_name(name: str) -> str:
    """The file a server writes for a scan named ``name`` (lower case, ``.2d`` added unless present)."""
    lowered = name[:MAX_SCAN_NAME].translate(_ASCII_LOWER)
    return lowered if SCAN_SUFFIX in lowered else lowered + SCAN_SUFFIX


class MappingStartCode(IntEnum):
    STARTED = 0
    ALREADY = 1
    FAILED = 2


class MappingEndCode(IntEnum):
    ENDED = 0
    NOT_MAPPING = 1
    NOT_MOVED = 2


MAPPING_START_WORDS: Final[Mapping[int, str]] = {
    MappingStartCode.ALREADY: "a scan is already running on the robot",
    MappingStartCode.FAILED: "the robot could not start the scan (it could not open the scan file)",
}
MAPPING_END_WORDS: Final[Mapping[int, str]] = {
    MappingEndCode.NOT_MAPPING: "no scan is running on the robot",
    MappingEndCode.NOT_MOVED: "the robot ended the scan but could not move its file into place",
}


@register
@dataclass(frozen=True, slots=True)
class MappingStart(SingleField):
    """``mappingStart`` args: the scan's name (the server makes the file name of it)."""

    DATA_NAME = "mappingStart"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "scan name"

    name: str


@register
@dataclass(frozen=True, slots=True)
class MappingStartReply(SingleField):
    """``mappingStart`` reply: ``byte`` :class:`MappingStartCode`."""

    DATA_NAME = "mappingStart"
    SIDE = Side.REPLY
    FIELD_KIND = "byte"
    FIELD_LABEL = "return code"

    code: int


@register
@dataclass(frozen=True, slots=True)
class MappingEndReply(Payload):
    """``mappingEnd`` reply: ``ubyte2`` 0 (ended) or 2 (file not moved), but a one-``byte`` 1 (no scan)."""

    DATA_NAME = "mappingEnd"
    SIDE = Side.REPLY

    code: int

    def encode(self) -> bytes:
        w = FieldWriter()
        return (w.byte(self.code) if self.code == MappingEndCode.NOT_MAPPING else w.ubyte2(self.code)).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.ubyte2("return code") if len(data) >= 2 else r.byte("return code"))


@register
@dataclass(frozen=True, slots=True)
class MappingStatus(SingleField):
    """``mappingStatus`` reply: the scan's name while one runs, else ``""``."""

    DATA_NAME = "mappingStatus"
    SIDE = Side.REPLY
    FIELD_KIND = "string"
    FIELD_LABEL = "scan name"

    name: str


@register
@dataclass(frozen=True, slots=True)
class MappingStatusBroadcast(MappingStatus):
    """``mappingStatusBroadcast``: as ``mappingStatus`` when asked; broadcast with the scan's *file* name
    when a scan starts and ``""`` when it ends."""

    DATA_NAME = "mappingStatusBroadcast"


@register
@dataclass(frozen=True, slots=True)
class MappingLoopStart(SingleField):
    """``mappingLoopStart`` (a string command): the log gets ``loop start <tag>`` where the robot is."""

    DATA_NAME = "mappingLoopStart"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "loop tag"

    tag: str


@register
@dataclass(frozen=True, slots=True)
class MappingLoopEnd(MappingLoopStart):
    """``mappingLoopEnd`` (a string command): the log gets ``loop stop <tag>``."""

    DATA_NAME = "mappingLoopEnd"
