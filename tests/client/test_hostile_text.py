"""Control characters in every string a server sends never reach the operator's terminal raw.

A hostile loopback server puts ESC sequences (clear screen, set the terminal title), BEL, CR, BS,
DEL and the C1 CSI (0x9b) into its data names and descriptions, status and mode strings, map name
and route names. Every subcommand that prints them runs as a real process; its human output may hold
no control character but newline, and its JSON output must parse back to the exact strings (with
the dangerous characters spelled as JSON escapes, so the raw output is inert too).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.ld import Routes

from .servers import SPECS, ServerThread, TestServer

EVIL = "\x1b[2J\x1b]0;pwned\x07\rX\bY\x7fZ\x9b31m!"
"""Latin-1 only: ARIA strings are single bytes, so no character above U+00FF can arrive."""
STATUS, MODE = f"Stopped{EVIL}", f"Stop{EVIL}"


def _hostile_server() -> TestServer:
    specs = [
        *SPECS,
        (
            f"custom{EVIL}",
            f"does things{EVIL}",
            f"args{EVIL}",
            f"returns{EVIL}",
            f"Group{EVIL}",
            "RETURN_NONE",
        ),
        ("getRoutes", "routes", "none", "repeat string", "Navigation", "RETURN_SINGLE"),
        ("patrol", "patrol", "string", "none", "Navigation", "RETURN_NONE"),
    ]
    server = TestServer(specs)
    server.strings = (STATUS, MODE, STATUS)
    server.handlers["getMapName"] = lambda s, a: [FieldWriter().string(f"site{EVIL}.map").bytes()]
    server.handlers["getRoutes"] = lambda s, a: [Routes((f"Loop{EVIL}", "Plain")).encode()]
    return server


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rtmu", *args], capture_output=True, text=True, timeout=60, encoding="utf-8"
    )


def _raw_controls(text: str) -> list[str]:
    return sorted({hex(ord(c)) for c in text if (ord(c) < 0x20 and c != "\n") or 0x7F <= ord(c) <= 0x9F})


HUMAN = [
    ("probe", []),
    ("status", ["--once"]),
    ("map", ["--out", "{tmp}/m.map"]),
    ("routes", []),
    ("patrol", ["Nowhere"]),
    ("doctor", []),
    ("drive", ["--trans", "0", "--rot", "0", "--seconds", "0.2"]),
    ("why", []),
    ("drive", ["--trans", "50", "--seconds", "0.3"]),  # it never moves: the answer is printed
]


@pytest.mark.parametrize(("command", "extra"), HUMAN, ids=[f"{c}{i}" for i, (c, _) in enumerate(HUMAN)])
def test_human_output_escapes_every_control_character(tmp_path: Path, command: str, extra: list[str]) -> None:
    with ServerThread(_hostile_server()) as server:
        argv = [a.format(tmp=tmp_path) for a in extra]
        result = _run(command, f"127.0.0.1:{server.port}", *argv)
    out = result.stdout + result.stderr
    assert "Traceback" not in out, out
    assert not _raw_controls(out), f"{command} printed raw {_raw_controls(out)}: {out!r}"
    if command in ("probe", "status", "routes", "patrol", "map"):
        assert "\\x1b[2J" in out, f"{command} should show the hostile text escaped: {out!r}"


@pytest.mark.parametrize(
    ("command", "extra", "pick"),
    [
        ("status", ["--once", "--json"], lambda obj: [obj["status"], obj["mode"]]),
        ("routes", ["--json"], lambda obj: obj[:1]),
    ],
    ids=["status", "routes"],
)
def test_json_output_keeps_the_exact_strings_and_stays_inert(command: str, extra: list[str], pick) -> None:  # type: ignore[no-untyped-def]
    with ServerThread(_hostile_server()) as server:
        result = _run(command, f"127.0.0.1:{server.port}", *extra)
    assert result.returncode == 0, result.stderr
    assert not _raw_controls(result.stdout), repr(result.stdout)
    got = pick(json.loads(result.stdout))
    assert all(EVIL in value for value in got), got
