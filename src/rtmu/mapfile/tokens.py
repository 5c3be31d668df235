"""Splitting a header line into tokens the way ARIA's argument builder does, and strict number parsing.

ARIA splits on whitespace, then glues a token that starts with a double quote to
the following ones until a token ends with a quote, so ``"Kitchen door"`` is one
argument. There is no escape character and no comment syntax: ``;`` and ``#``
are ordinary text in map files.
"""

from __future__ import annotations

import math
import re

SPACE = " \t\n\v\f\r"
"""Whitespace as C's isspace() sees it; str.split() would also split on latin-1's NBSP and NEL."""
_TOKEN = re.compile(r"[^ \t\n\v\f\r]+")
_FLOAT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


class TokenError(ValueError):
    """A line's tokens cannot be split (an opening quote never closes)."""


def split_words(text: str) -> list[str]:
    """Whitespace-separated words, no quote handling (numbers, flags)."""
    return _TOKEN.findall(text)


def split_keyword(line: str) -> tuple[str, str]:
    """A header line as (first word, the rest without surrounding whitespace); ("", "") when blank."""
    match = _TOKEN.search(line)
    if match is None:
        return "", ""
    return match.group(), line[match.end() :].strip(SPACE)


def split_tokens(text: str) -> list[str]:
    """Whitespace-separated tokens of ``text``; a quoted run (quotes and spacing kept) is one token."""
    tokens: list[str] = []
    quote_start: int | None = None
    for match in _TOKEN.finditer(text):
        token = match.group()
        if quote_start is None:
            if token.startswith('"') and (len(token) == 1 or not token.endswith('"')):
                quote_start = match.start()
            else:
                tokens.append(token)
        elif token.endswith('"'):
            tokens.append(text[quote_start : match.end()])
            quote_start = None
    if quote_start is not None:
        raise TokenError(f"unterminated quote: {text[quote_start:][:40]!r}")
    return tokens


def unquote(token: str) -> str:
    """The text inside a quoted token; an unquoted token is returned as it is (ARIA accepts both)."""
    if len(token) >= 2 and token[0] == '"' and token[-1] == '"':
        return token[1:-1]
    return token


def parse_float(token: str) -> float | None:
    """A finite decimal number, or None; unlike ``float()`` no ``nan``, ``inf`` or ``1_000``."""
    if not _FLOAT.fullmatch(token):
        return None
    value = float(token)
    return value if math.isfinite(value) else None


def format_number(value: float) -> str:
    """Millimetres as ARIA writes them (an integer) when whole; otherwise the shortest exact text."""
    value = float(value)
    if value.is_integer():
        return str(int(value))
    return repr(value)


def format_heading(th: float) -> str:
    """Degrees with six decimals like ARIA's ``%f``, unless that would lose precision we were given."""
    th = float(th)
    text = f"{th:f}"
    return text if float(text) == th else repr(th)


def info_fields(args: str) -> tuple[str, dict[str, str]]:
    """A ``MapInfo:``-style argument string as (class, {key: value}), e.g. ``("GoalType", {"Name": "Goal"})``.

    Tokens without ``=`` are kept with an empty value. Raises TokenError for an unterminated quote.
    """
    tokens = [unquote(t) for t in split_tokens(args)]
    if not tokens:
        return "", {}
    fields: dict[str, str] = {}
    for token in tokens[1:]:
        key, _, value = token.partition("=")
        fields[key] = value
    return tokens[0], fields
