"""The ARIA ``.map`` format: read (file, text, ``getMap`` lines, ``getMapBinary`` arrays) and write.

Points are an int32 array of shape (N, 2) and segments (M, 4), in mm. Map
objects (``Cairn:`` lines) are ``MapObject`` dataclasses. Everything else in
the header is kept and written back. A map that cannot be read raises
``MapFormatError`` naming the source and line; tolerable oddities (skipped data
lines) are counted in ``MapData.skipped_lines`` and described in ``warnings``.
"""

from .errors import MapFormatError, MapWarning
from .model import (
    CATEGORIES,
    INFO_KEYWORDS,
    Bounds,
    InfoLine,
    MapData,
    MapObject,
    MapScan,
    Pose,
    ScanClaims,
    new_map,
)
from .reader import (
    DEFAULT_MAX_BYTES,
    DEFAULT_MAX_HEADER_LINES,
    DEFAULT_MAX_LINE,
    from_stream,
    parse_map,
    parse_map_lines,
    read_map,
)
from .tokens import info_fields, split_keyword, split_tokens
from .writer import map_bytes, map_header_lines, map_lines, object_text, write_map

__all__ = [
    "CATEGORIES",
    "DEFAULT_MAX_BYTES",
    "DEFAULT_MAX_HEADER_LINES",
    "DEFAULT_MAX_LINE",
    "INFO_KEYWORDS",
    "Bounds",
    "InfoLine",
    "MapData",
    "MapFormatError",
    "MapObject",
    "MapScan",
    "MapWarning",
    "Pose",
    "ScanClaims",
    "from_stream",
    "info_fields",
    "map_bytes",
    "map_header_lines",
    "map_lines",
    "new_map",
    "object_text",
    "parse_map",
    "parse_map_lines",
    "read_map",
    "split_keyword",
    "split_tokens",
    "write_map",
]
