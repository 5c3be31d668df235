"""Make server-controlled text safe to print on an operator's terminal.

A hostile server can put ESC sequences, carriage returns, backspaces or bidi
overrides in names, descriptions, status strings and refusal reasons; printed
raw they would let it rewrite what the operator reads.  ``visible`` escapes
every such character as a readable ``\\x1b`` / ``\\r`` / ``\\u202e`` so the text
stays legible and cannot act on the terminal.  JSON output must carry the exact
strings: ``json_safe`` escapes the same characters as JSON ``\\uXXXX`` escapes,
which parse back to the very same string.
"""

from __future__ import annotations

import unicodedata

_NAMED = {"\t": "\\t", "\n": "\\n", "\r": "\\r", "\\": "\\\\"}


def _escape(ch: str) -> str:
    named = _NAMED.get(ch)
    if named is not None:
        return named
    code = ord(ch)
    if code <= 0xFF:
        return f"\\x{code:02x}"
    if code <= 0xFFFF:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def _unsafe(ch: str) -> bool:
    # Cc: C0, DEL, C1. Cf: bidi overrides/isolates, zero-width joiners and other
    # format characters that reorder or hide text. Zl/Zp: line/paragraph separators.
    return unicodedata.category(ch) in ("Cc", "Cf", "Zl", "Zp", "Cs")


def visible(text: object) -> str:
    """Return ``text`` with control and format characters escaped visibly."""
    s = text if isinstance(text, str) else str(text)
    if s.isprintable() and "\\" not in s:
        return s
    return "".join(_escape(ch) if ch == "\\" or _unsafe(ch) else ch for ch in s)


def json_safe(encoded: str) -> str:
    """``json.dumps(..., ensure_ascii=False)`` output with DEL, C1, format and separator characters
    written as ``\\uXXXX``: still the exact strings for a JSON reader, inert on a terminal. (JSON
    already escapes C0; such characters can only stand inside strings, so the result stays valid.)"""
    if encoded.isprintable():
        return encoded
    return "".join(_json_escape(ch) if _unsafe(ch) else ch for ch in encoded)


def _json_escape(ch: str) -> str:
    code = ord(ch)
    if code <= 0xFFFF:
        return f"\\u{code:04x}"
    code -= 0x10000  # outside the BMP: a UTF-16 surrogate pair, as JSON spells it
    return f"\\u{0xD800 + (code >> 10):04x}\\u{0xDC00 + (code & 0x3FF):04x}"
