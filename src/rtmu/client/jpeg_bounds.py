"""A camera picture is checked from its header before anything is decoded, and decoded small.

A 632-byte JPEG whose frame header declares 8192×8192 pixels made ``rtmu image`` decode (and
save) a 200 MB picture of grey: libjpeg fills whatever the data does not cover and says nothing.
Two rules keep a hostile picture cheap:

* **The data must be able to fill the picture.** A Huffman code has at least one bit: in a
  sequential (baseline, extended) picture every 8×8 block of every component costs at least two
  (its DC difference and its end of block), in a progressive one every block of a component costs at
  least one in that component's first scan. A picture whose data after its first scan header is
  shorter than that is cut short, whatever its markers say (:func:`fill_problem`). Only what cameras
  send is taken: baseline, extended and progressive Huffman JPEG; arithmetic, lossless and
  hierarchical ones are refused by name. (ArNetworking carries a picture in one packet of at most
  32 000 bytes, so no whole picture of more than a few megapixels can come at all.)
* **A check decodes at 1/8 scale** (:func:`decode_problem`: libjpeg's DCT scaling still reads all of
  the picture's data), so checking an 8192×8192 picture costs a few MB, not the 200 MB of its pixels;
  a progressive picture, which libjpeg holds whole as coefficients, is refused above
  :data:`MAX_PROGRESSIVE_PIXELS`.

:func:`read_header` is the one walk over a JPEG's header segments (bounded), also used by live video
for the simulator's render stamp.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

STAMP_PREFIX = b"RTMU-T="
"""JPEG comment (COM segment) text the simulator writes: render time in wall-clock nanoseconds."""
MAX_SIDE = 8192
"""Largest width or height accepted from a server; no robot camera comes near it."""
MAX_SCAN_SEGMENTS = 64
"""Markers walked before the picture data."""
MAX_PROGRESSIVE_PIXELS = 2048 * 2048
"""libjpeg keeps a progressive picture's coefficients whole (2 bytes each): 12 MB at this size."""
HUFFMAN_FRAMES = {0xC0: "baseline", 0xC1: "extended", 0xC2: "progressive"}
OTHER_FRAMES = {
    0xC3: "lossless",
    0xC5: "hierarchical",
    0xC6: "hierarchical",
    0xC7: "hierarchical",
    0xC9: "arithmetic-coded",
    0xCA: "arithmetic-coded",
    0xCB: "arithmetic-coded",
    0xCD: "arithmetic-coded",
    0xCE: "arithmetic-coded",
    0xCF: "arithmetic-coded",
}


@dataclass(frozen=True, slots=True)
class JpegHeader:
    stamp: int | None = None
    """The simulator's render time (``RTMU-T=`` comment), wall-clock ns."""
    frame: int | None = None
    """The frame header's marker (0xC0 baseline, 0xC2 progressive …); None: none before the scan."""
    size: tuple[int, int] | None = None
    """(width, height) the frame header declares."""
    sampling: tuple[tuple[int, int], ...] = ()
    """Each component's (horizontal, vertical) sampling factors."""
    data_at: int | None = None
    """Where the first scan's data begins (after its header); None: no scan found."""


def read_header(jpeg: bytes) -> JpegHeader:
    """Walk the header segments up to the first scan (at most :data:`MAX_SCAN_SEGMENTS` of them)."""
    stamp = frame = size = data_at = None
    sampling: tuple[tuple[int, int], ...] = ()
    i = 2
    for _ in range(MAX_SCAN_SEGMENTS):
        if i + 4 > len(jpeg) or jpeg[i] != 0xFF:
            break
        marker = jpeg[i + 1]
        if marker == 0xFF:  # fill byte
            i += 1
            continue
        if marker in (0xD8, 0x01) or 0xD0 <= marker <= 0xD7:
            i += 2
            continue
        length = int.from_bytes(jpeg[i + 2 : i + 4], "big")
        body = jpeg[i + 4 : i + 2 + length]
        if marker == 0xFE and body.startswith(STAMP_PREFIX):
            digits = body[len(STAMP_PREFIX) :].split(b"\x00", 1)[0].strip()
            if digits.isdigit() and len(digits) <= 20:
                stamp = int(digits)
        elif (marker in HUFFMAN_FRAMES or marker in OTHER_FRAMES) and frame is None and len(body) >= 6:
            frame = marker
            size = (int.from_bytes(body[3:5], "big"), int.from_bytes(body[1:3], "big"))
            count = body[5]
            factors = body[6 : 6 + 3 * count]
            sampling = tuple((b >> 4, b & 0x0F) for b in factors[1::3])
        if marker == 0xDA:  # start of scan: the header is over
            data_at = i + 2 + length
            break
        i += 2 + length
    return JpegHeader(stamp, frame, size, sampling, data_at)


def _ceil(a: int, b: int) -> int:
    return -(-a // b)


def _blocks(size: tuple[int, int], sampling: tuple[tuple[int, int], ...]) -> list[int]:
    """The 8×8 blocks of each component (one component of the whole size when the factors are bad)."""
    width, height = size
    if not sampling or any(h < 1 or v < 1 for h, v in sampling):
        return [_ceil(width, 8) * _ceil(height, 8)]
    h_max = max(h for h, _ in sampling)
    v_max = max(v for _, v in sampling)
    return [_ceil(_ceil(width * h, h_max), 8) * _ceil(_ceil(height * v, v_max), 8) for h, v in sampling]


def least_data(header: JpegHeader) -> int:
    """The fewest bytes of picture data that can code the picture its header declares."""
    assert header.size is not None
    blocks = _blocks(header.size, header.sampling)
    if header.frame == 0xC2:  # progressive: one bit a block, in the smallest component's first scan
        return _ceil(min(blocks), 8)
    return _ceil(2 * sum(blocks), 8)  # sequential: a DC code and an end of block, every block


def fill_problem(jpeg: bytes, header: JpegHeader | None = None) -> str | None:
    """Why the picture's data cannot be what its header declares, in plain words; None when it can."""
    header = header or read_header(jpeg)
    if header.frame is None or header.size is None:
        return f"the {len(jpeg)} bytes received are not a complete JPEG picture (no frame header)"
    if header.frame in OTHER_FRAMES:
        return f"the picture is a {OTHER_FRAMES[header.frame]} JPEG, which no robot camera sends"
    width, height = header.size
    if not (0 < width <= MAX_SIDE and 0 < height <= MAX_SIDE):
        return f"the picture declares {width}x{height} pixels, outside 1…{MAX_SIDE}"
    if header.data_at is None:
        return f"the {len(jpeg)} bytes received are not a complete JPEG picture (no picture data)"
    need = least_data(header)
    have = len(jpeg) - header.data_at
    if have < need:
        return (
            f"the picture is cut short: {width}x{height} pixels need at least {need} bytes of data, "
            f"it has {max(have, 0)}"
        )
    if header.frame == 0xC2 and width * height > MAX_PROGRESSIVE_PIXELS:
        return f"the picture is a {width}x{height} progressive JPEG, too big to check (no camera sends one)"
    return None


def decode_problem(jpeg: bytes) -> str | None:
    """Decode the picture at 1/8 scale (all its data read, little memory); why it fails, or None."""
    from PIL import Image

    try:
        with Image.open(io.BytesIO(jpeg)) as img:
            if img.format != "JPEG":
                return f"the server sent a {img.format or 'non-JPEG'} picture, not a JPEG"
            w, h = img.size
            img.draft(img.mode, (max(1, w // 8), max(1, h // 8)))
            img.load()
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombError):
        return f"the {len(jpeg)} bytes the server sent are not a complete JPEG picture"
    return None
