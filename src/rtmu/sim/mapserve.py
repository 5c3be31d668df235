"""The map a simulator serves: its obstacles, goals, home, id, and the two map streams pre-encoded.

``getMap`` sends the file's own lines, one per packet, unchanged (so ARIA's
maps and ours reach the client byte for byte); ``getMapBinary`` sends the
header ARIA's way and the geometry as int32 blocks. Both streams are framed
once per data number and shared by every client, cut into chunks of whole
packets so a big map can be sent a chunk at a time as the client reads it
(a 1 M-point map is 8 MB binary, 21 MB as text).
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.map import Goals, MapId, MapName
from rtmu.protocol.payloads.mapstream import map_binary_payloads, map_text_payloads

from ..mapfile import MapData, MapObject, map_header_lines
from .geometry import Obstacles

DEFAULT_POINT_CELL_MM = 40.0
MIN_POINT_CELL_MM = 20.0
STREAM_CHUNK_BYTES = 64 * 1024
"""Framed map streams are cut into chunks of whole packets of about this size."""

Chunks = tuple[bytes, ...]


def frame_in_chunks(number: int, payloads: Iterable[bytes], chunk: int = STREAM_CHUNK_BYTES) -> Chunks:
    """Packets for data ``number``, framed and grouped into chunks of about ``chunk`` bytes (never split)."""
    out: list[bytes] = []
    buf = bytearray()
    for payload in payloads:
        buf += encode_packet(number, payload)
        if len(buf) >= chunk:
            out.append(bytes(buf))
            buf.clear()
    if buf:
        out.append(bytes(buf))
    return tuple(out)


@dataclass
class ServedMap:
    path: Path | None
    name: str
    """As configured (ARIA sends the path it was given)."""
    raw: bytes = field(default=b"", repr=False)
    """The file's bytes: ``getMap`` sends its lines (split only when first asked for: a 1 M-point map
    is a million lines)."""
    header: list[str] = field(default_factory=list)
    segments: np.ndarray = field(default_factory=lambda: np.zeros((0, 4), np.int32))
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int32))
    home: tuple[float, float, float] = (0.0, 0.0, 0.0)
    has_home: bool = False
    goals: tuple[str, ...] = ()
    objects: tuple[MapObject, ...] = ()
    """Every cairn (goals, docks, forbidden lines and areas), for navigation."""
    md5: bytes = b""
    size: int = 0
    mtime: int = 0
    resolution: int | None = None
    access_point: tuple[float, float] | None = None
    data: MapData | None = field(default=None, repr=False)
    """The map as read (kept so a map change can be applied to it)."""
    _lines: list[str] | None = field(default=None, repr=False)
    _framed: dict[tuple[str, int], Chunks] = field(default_factory=dict, repr=False)

    @property
    def present(self) -> bool:
        return self.path is not None

    @property
    def lines(self) -> list[str]:
        """The file's non-blank lines without line ends, as ``getMap`` sends them."""
        if self._lines is None:
            text = self.raw.decode("latin-1")
            self._lines = [s for s in (line.rstrip("\r") for line in text.split("\n")) if s.strip()]
        return self._lines

    def obstacles(self) -> Obstacles:
        cell = float(self.resolution) if self.resolution and self.resolution > 0 else DEFAULT_POINT_CELL_MM
        return Obstacles(self.segments, self.points, point_cell_mm=max(cell, MIN_POINT_CELL_MM))

    # -- replies -----------------------------------------------------------------
    def name_payload(self) -> bytes:
        return MapName(self.name).encode()

    def id_payload(self) -> bytes:
        return MapId("", self.name, self.md5, self.size, self.mtime).encode()

    def goals_payload(self) -> bytes:
        return Goals(self.goals).encode()

    def text_stream(self, number: int) -> Chunks:
        """Every ``getMap`` reply packet, framed for data ``number``."""
        key = ("text", number)
        if key not in self._framed:
            payloads = map_text_payloads(self.lines if self.present else None)
            self._framed[key] = frame_in_chunks(number, payloads)
        return self._framed[key]

    def binary_stream(self, number: int, first_line: str | None = None) -> Chunks:
        """Every ``getMapBinary`` reply packet (``getMapWithMaxCategory`` may rename the first line)."""
        key = ("binary:" + (first_line or ""), number)
        if key not in self._framed:
            if self.present:
                header = list(self.header) or ["2D-Map"]
                header[0] = first_line or "2D-Map"
                payloads = map_binary_payloads(header, self.segments, self.points)
            else:
                payloads = map_binary_payloads(None)
            self._framed[key] = frame_in_chunks(number, payloads)
        return self._framed[key]


def load_map(path: Path | None) -> ServedMap:
    """Read ``path`` with the project's map reader; None = serve no map (an empty 10 m room to drive in)."""
    if path is None:
        return ServedMap(None, "")
    from rtmu.mapfile import read_map

    raw = path.read_bytes()
    return served_map(path, str(path), raw, read_map(path), int(os.stat(path).st_mtime))


def served_map(
    path: Path, name: str, raw: bytes, data: MapData, mtime: int, header: list[str] | None = None
) -> ServedMap:
    """A map to serve: the file's bytes ``raw`` (sent line by line by ``getMap``) and what they read as
    (``header``: ``data``'s header lines, when already written)."""
    home = data.home()
    goals = tuple(obj.name for obj in data.goals())
    ap = None
    for obj in data.objects:
        label = f"{obj.type} {obj.name}".lower()
        if "access point" in label or "accesspoint" in label or "wifi" in label:
            ap = (float(obj.pose.x), float(obj.pose.y))
            break
    return ServedMap(
        path=path,
        name=name,
        raw=raw,
        header=header if header is not None else map_header_lines(data),
        segments=np.asarray(data.segments, dtype=np.int32).reshape(-1, 4),
        points=np.asarray(data.points, dtype=np.int32).reshape(-1, 2),
        home=(float(home.x), float(home.y), float(home.th)) if home is not None else (0.0, 0.0, 0.0),
        has_home=home is not None,
        goals=goals,
        objects=tuple(data.objects),
        md5=hashlib.md5(raw).digest(),
        size=len(raw),
        mtime=mtime,
        resolution=data.resolution,
        access_point=ap,
        data=data,
    )
