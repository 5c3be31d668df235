"""The pipe between the parent and its guardian: one hello, then fixed-size records.

Parent → guardian (the guardian's stdin): a 4-byte big-endian length and a JSON
hello (host, port, user, password — never in argv or the environment), then
records of :data:`RECORD` (a kind byte, the sender's ``time.monotonic()``).
Every record is written with one ``os.write`` of fewer than ``PIPE_BUF`` bytes,
so records from the UI and the network threads never interleave.

Guardian → parent (its stdout): one line per event, ``<word> <text>``.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass

RECORD = struct.Struct(">cd")
BEAT_UI = b"u"
"""The parent's UI thread is alive."""
BEAT_NET = b"n"
"""The parent's network thread is alive."""
ARM = b"a"
"""Motion may be commanded from now on: watch the heartbeats."""
DISARM = b"d"
"""The parent has sent its own stop: nothing to watch."""
BYE = b"b"
"""A clean exit: end without a stop."""
KINDS = frozenset({BEAT_UI, BEAT_NET, ARM, DISARM, BYE})
MAX_HELLO = 64 * 1024

# guardian → parent words
READY = "ready"
UNAVAILABLE = "unavailable"
STOPPED = "stopped"
LOST = "lost"


@dataclass(frozen=True)
class Hello:
    host: str
    port: int
    user: str = ""
    password: str = ""
    timeout: float = 10.0

    def encode(self) -> bytes:
        body = json.dumps(
            {
                "host": self.host,
                "port": self.port,
                "user": self.user,
                "password": self.password,
                "timeout": self.timeout,
            }
        ).encode()
        return struct.pack(">I", len(body)) + body

    @classmethod
    def decode(cls, body: bytes) -> Hello:
        d = json.loads(body.decode())
        return cls(str(d["host"]), int(d["port"]), str(d["user"]), str(d["password"]), float(d["timeout"]))


def record(kind: bytes, at: float) -> bytes:
    return RECORD.pack(kind, at)


class RecordReader:
    """Splits bytes from the pipe into (kind, time) records; keeps a partial record for later."""

    def __init__(self) -> None:
        self._buf = b""

    def feed(self, data: bytes) -> list[tuple[bytes, float]]:
        self._buf += data
        n = len(self._buf) // RECORD.size * RECORD.size
        out = [RECORD.unpack_from(self._buf, i) for i in range(0, n, RECORD.size)]
        self._buf = self._buf[n:]
        return [(k, t) for k, t in out if k in KINDS]
