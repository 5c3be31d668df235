"""Server text printed on the terminal cannot act on it: control and format characters show escaped."""

from __future__ import annotations

import json

from rtmu.base.textsafe import visible
from rtmu.subcommands._status import status_line

HOSTILE = "ok\x1b[2J\r\x07\x08\x7f\x9b31m\u202eevil\u200b\u2028end"


def test_plain_text_is_unchanged() -> None:
    assert visible("Stopped (Idle) · 12 °") == "Stopped (Idle) · 12 °"


def test_every_control_and_format_character_is_escaped_visibly() -> None:
    out = visible(HOSTILE)
    assert out == "ok\\x1b[2J\\r\\x07\\x08\\x7f\\x9b31m\\u202eevil\\u200b\\u2028end"
    assert all(ch.isprintable() for ch in out)


def test_escaping_is_unambiguous_for_a_literal_backslash() -> None:
    assert visible("a\\x1b") == "a\\\\x1b"
    assert visible("a\\x1b") != visible("a\x1b")


def test_status_line_escapes_status_and_mode() -> None:
    obj = {
        "x": 0,
        "y": 0,
        "th": 0,
        "vel": 0,
        "rot_vel": 0,
        "battery_v": 12.5,
        "status": HOSTILE,
        "mode": "\x1b]0;t\x07",
    }
    line = status_line(obj)
    assert all(ch.isprintable() for ch in line)
    assert "\\x1b[2J" in line and "\\x1b]0;t\\x07" in line


def test_json_keeps_the_exact_strings() -> None:
    assert json.loads(json.dumps({"s": HOSTILE}, ensure_ascii=False))["s"] == HOSTILE


def test_mapinfo_escapes_map_file_text(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    from rtmu.cli import main

    path = tmp_path / "evil.map"
    path.write_text(
        "2D-Map\nMinPos: 0 0\nMaxPos: 10 10\n"
        'Ev\x1b[2J\x07\u202eil: 1\nCairn: GoalWithHeading 5 5 0 "" ICON "g\x1b[2J\x07\u202eoal"\nDATA\n1 1\n'
    )
    main(["mapinfo", str(path)])
    out = capsys.readouterr()
    assert "Ev\\x1b[2J\\x07" in out.out  # the reader reads latin-1: U+202E arrives as C1 bytes
    for text in (out.out, out.err):
        assert not any(ch in text for ch in "\x1b\x07\u202e"), text
