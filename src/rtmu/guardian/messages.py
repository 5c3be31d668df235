"""The pipe between the parent and its guardian: records, some carrying a login.

Parent → guardian (the guardian's stdin): records of :data:`RECORD` (a kind byte, the sender's
``time.monotonic()``). A :data:`LOGIN` record is followed by a 4-byte big-endian length and a JSON
:class:`Hello` (host, port, user, password — never in argv or the environment — and the login's
serial number): log out of the robot watched so far and log in to this one. :data:`WARM` and
:data:`COLD` records carry a hello the same way. The parent writes every record under one lock, so
records from the UI and the network threads never interleave.

Guardian → parent (its stdout): one line per event, ``<word> <serial> <text>``; the serial names
the login the event is about, so a late word about a robot the guardian left is never taken for
the robot it watches now.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass

from ..values.target import Target

RECORD = struct.Struct(">cd")
LENGTH = struct.Struct(">I")
BEAT_UI = b"u"
"""The parent's UI thread is alive."""
BEAT_NET = b"n"
"""The parent's network thread is alive."""
ARM = b"a"
"""Motion may be commanded from now on: watch the heartbeats."""
DISARM = b"d"
"""The parent has sent its own stop: nothing to watch."""
HALT = b"h"
"""Stop the robot now through the guardian's own connection (the parent's link to it died while driving)."""
LOGIN = b"l"
"""A :class:`Hello` follows: watch this robot from now on (the one watched before is left, stopped
first if a drive was armed on it). A hello with an empty host only leaves: nothing is watched."""
BYE = b"b"
"""A clean exit: end without a stop."""
WARM = b"w"
"""A :class:`Hello` follows: keep a login to this robot ready beside the watched one (nothing is
watched or sent there), so a LOGIN for it later is ready at once. A bounded few are kept."""
COLD = b"c"
"""A :class:`Hello` follows: let go of the ready login to this robot, if one is kept (its session
disconnected)."""
WITH_HELLO = frozenset({LOGIN, WARM, COLD})
"""The kinds of record a :class:`Hello` follows."""
KINDS = frozenset({BEAT_UI, BEAT_NET, ARM, DISARM, HALT, BYE}) | WITH_HELLO
MAX_HELLO = 64 * 1024

# guardian → parent words
READY = "ready"
"""Logged in to the robot of that serial: it can stop it."""
UNAVAILABLE = "unavailable"
"""Could not log in (the text says why): that robot is not watched."""
STOPPED = "stopped"
LOST = "lost"
"""Its connection to that robot closed."""


@dataclass(frozen=True)
class Hello:
    """Log in to this robot, as the parent did (its own :class:`Target`, password and all)."""

    target: Target
    timeout: float = 10.0
    serial: int = 0
    """Which login this is (the parent counts them); every word about it carries this number."""

    def encode(self) -> bytes:
        t = self.target
        login = {"host": t.host, "port": t.port, "user": t.user, "password": t.password}
        keys = {"protocol": t.protocol, "server_key": t.server_key}
        body = json.dumps({**login, **keys, "timeout": self.timeout, "serial": self.serial}).encode()
        return LENGTH.pack(len(body)) + body

    @classmethod
    def decode(cls, body: bytes) -> Hello:
        d = json.loads(body.decode())
        protocol = d.get("protocol")
        target = Target(
            str(d["host"]),
            int(d["port"]),
            str(d["user"]),
            str(d["password"]),
            protocol=None if protocol is None else str(protocol),
            server_key=str(d.get("server_key", "")),
        )
        return cls(target, float(d["timeout"]), int(d.get("serial", 0)))

    def same_robot(self, other: Hello | None) -> bool:
        """The same login (address, user, password, protocol strings): logged in to one is logged in to
        both — whichever profile or reconnect rule the parent's session has."""
        if other is None:
            return False
        mine, theirs = self.target, other.target
        return (mine.host, mine.port, mine.user, mine.password, mine.protocol, mine.server_key) == (
            theirs.host, theirs.port, theirs.user, theirs.password, theirs.protocol, theirs.server_key
        )  # fmt: skip


def record(kind: bytes, at: float) -> bytes:
    return RECORD.pack(kind, at)


def login_record(hello: Hello, at: float, kind: bytes = LOGIN) -> bytes:
    """A record a hello follows (``kind``: :data:`LOGIN`, :data:`WARM` or :data:`COLD`)."""
    assert kind in WITH_HELLO
    return RECORD.pack(kind, at) + hello.encode()


Record = tuple[bytes, float, Hello | None]
"""(kind, the sender's time, the hello of a LOGIN, WARM or COLD record)."""


class RecordReader:
    """Splits bytes from the pipe into records; keeps a partial record for later.

    A login whose hello is too long or does not decode raises ``ValueError``: the pipe is then out
    of step, and the guardian ends rather than guess where the next record starts."""

    def __init__(self) -> None:
        self._buf = b""

    def feed(self, data: bytes) -> list[Record]:
        self._buf += data
        out: list[Record] = []
        at = 0
        buf = self._buf
        while len(buf) - at >= RECORD.size:
            kind, when = RECORD.unpack_from(buf, at)
            if kind not in WITH_HELLO:
                at += RECORD.size
                if kind in KINDS:
                    out.append((kind, when, None))
                continue
            head = at + RECORD.size
            if len(buf) - head < LENGTH.size:
                break
            (size,) = LENGTH.unpack_from(buf, head)
            if size > MAX_HELLO:
                raise ValueError("hello too large")
            if len(buf) - head - LENGTH.size < size:
                break
            body = buf[head + LENGTH.size : head + LENGTH.size + size]
            try:
                hello = Hello.decode(body)
            except (ValueError, KeyError, TypeError) as exc:
                raise ValueError(f"bad hello: {exc}") from None
            out.append((kind, when, hello))
            at = head + LENGTH.size + size
        self._buf = buf[at:]
        return out


def report(word: str, serial: int, text: str = "") -> str:
    """One line to the parent: ``<word> <serial> <text>``, on one line whatever the text holds."""
    return f"{word} {serial} {text}".rstrip().replace("\n", " ").replace("\r", " ")


def parse_report(line: str) -> tuple[str, int, str]:
    """(word, serial, text) of one line the guardian said; serial -1 when the line has none."""
    word, _, rest = line.partition(" ")
    number, _, text = rest.partition(" ")
    try:
        return word, int(number), text
    except ValueError:
        return word, -1, rest
