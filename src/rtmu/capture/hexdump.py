"""Turn a hex dump back into bytes.

Accepted: plain hex (``0f 0c 08 00``, ``0f0c0800``, ``0f:0c:08``, ``0x0f, 0x0c``),
and dumps with an offset column — ``xxd``, ``hexdump -C``, ``od -A x -t x1z``,
``tshark -x`` / Wireshark's "copy as hex dump" — whose ASCII column is
recognised (it must spell the line's bytes) and ignored. ``od -x`` and plain
``hexdump`` print little-endian 16-bit words; those are swapped back, ``*``
(repeated lines) is expanded and the final offset-only line trims the padding.
Offsets must follow on from each other, so a mangled dump is reported, not guessed.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator

from .base import CaptureError

_TOKEN = re.compile(r"\S+")
_HEX = re.compile(r"[0-9a-fA-F]+")


def _ascii(data: bytes | bytearray) -> str:
    return "".join(chr(b) if 32 <= b < 127 else "." for b in data)


def _is_ascii_column(rest: str, line_bytes: bytearray) -> bool:
    text = rest.strip()
    if len(text) >= 2 and ((text[0] == "|" and text[-1] == "|") or (text[0] == ">" and text[-1] == "<")):
        text = text[1:-1]
    return bool(line_bytes) and text.strip() == _ascii(line_bytes).strip()


class HexDumpParser:
    """Feed lines with :meth:`lines`; bytes come out line by line."""

    def __init__(self) -> None:
        self._offsets: bool | None = None
        self._swap = False
        self._radix: int | None = None
        self._base = 0
        self._count = 0
        self._repeat: bytes | None = None
        self._star = False

    def lines(self, lines: Iterable[str]) -> Iterator[bytes]:
        held: bytes | None = None  # one line held back: a final offset line may trim it
        for number, line in enumerate(lines, 1):
            result = self._line(number, line)
            if result is None:
                continue
            if isinstance(result, int):  # an offset-only line: the true total length
                if held is not None:
                    excess = self._count - result
                    if 0 < excess <= len(held):
                        held = held[: len(held) - excess]
                        self._count = result
                continue
            if held:
                yield held
            held = result
        if held:
            yield held
        if self._offsets is None:
            raise CaptureError("hex dump holds no bytes")

    def _line(self, number: int, line: str) -> bytes | int | None:
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            return None
        if stripped == "*":
            self._star = True
            return None
        tokens = list(_TOKEN.finditer(line))
        offset = self._offset(tokens)
        if offset is not None:
            tokens = tokens[1:]
            expected = self._base + self._count
            if not tokens and self._repeat and expected - len(self._repeat) < offset < expected:
                return offset - self._base  # od -x pads an odd last byte; the final offset says so
            if offset != expected:
                if (
                    self._star
                    and self._repeat
                    and offset > expected
                    and (offset - expected) % len(self._repeat) == 0
                ):
                    filler = self._repeat * ((offset - expected) // len(self._repeat))
                    self._count += len(filler)
                    self._star = False
                    if not tokens:
                        return filler
                    return filler + self._hex(number, line, tokens)
                raise CaptureError(
                    f"hex dump line {number}: offset {offset:#x} does not follow the "
                    f"{self._count} bytes before it (expected {expected:#x})"
                )
            if not tokens:
                return offset - self._base
        elif self._offsets:
            raise CaptureError(f"hex dump line {number}: the offset column is missing")
        self._star = False
        data = self._hex(number, line, tokens)
        if offset is not None:
            self._repeat = data
        return data

    def _offset(self, tokens: list[re.Match[str]]) -> int | None:
        """The line's offset, or None; decides on the first line whether the dump has offsets."""
        first = tokens[0].group()
        if self._offsets is False:
            return None
        colon = first.endswith(":")
        text = first[:-1] if colon else first
        if not _HEX.fullmatch(text):
            if self._offsets:
                raise CaptureError(f"hex dump: {first!r} is not an offset")
            self._offsets = False
            return None
        if self._offsets is None:
            second = tokens[1].group() if len(tokens) > 1 else ""
            looks = colon or (len(text) >= 4 and int(text, 16) == 0 and len(second) != len(text))
            if not looks or len(tokens) < 2:
                self._offsets = False
                return None
            self._offsets = True
            self._base = int(text, 16)
            self._radix = 16 if colon else None
            body = [t.group() for t in tokens[1:]]
            self._swap = not colon and all(
                len(t) == 4 for t in body[: min(len(body), 8)] if _HEX.fullmatch(t)
            )
            return self._base
        if self._radix is None and self._count:
            # od counts in octal by default, hexdump in hex: the second offset tells which.
            expected = self._base + self._count
            self._radix = 8 if re.fullmatch(r"[0-7]+", text) and int(text, 8) == expected else 16
        return int(text, self._radix or 16)

    def _hex(self, number: int, line: str, tokens: list[re.Match[str]]) -> bytes:
        out = bytearray()
        previous_end = tokens[0].start() if tokens else 0
        for match in tokens:
            if (
                self._offsets
                and match.start() - previous_end >= 2
                and _is_ascii_column(line[match.start() :], out)
            ):
                break
            previous_end = match.end()
            parts = match.group().rstrip(",;").split(":") if not self._offsets else [match.group()]
            try:
                for part in parts:
                    out += self._token_bytes(part)
            except ValueError:
                if self._offsets:
                    break  # the ASCII column of a dump we could not recognise any other way
                token = match.group()
                shown = token if len(token) <= 24 else token[:24] + "…"
                raise CaptureError(f"hex dump line {number}: {shown!r} is not hexadecimal") from None
        self._count += len(out)
        return bytes(out)

    def _token_bytes(self, token: str) -> bytes:
        if token[:2] in ("0x", "0X"):
            token = token[2:]
        if not token or len(token) % 2 or not _HEX.fullmatch(token):
            raise ValueError(token)
        raw = bytes.fromhex(token)
        if self._swap and len(raw) == 2:
            raw = raw[::-1]
        return raw


def parse_hex(lines: Iterable[str]) -> Iterator[bytes]:
    """Bytes of a hex dump, line by line; :class:`CaptureError` names the first bad line."""
    return HexDumpParser().lines(lines)
