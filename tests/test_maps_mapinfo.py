"""``rtmu mapinfo``: the summary, the JSON form, one clear line for a missing (exit 2) or bad (16) file."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from rtmu.base.exit_codes import EXIT_BAD_FILE, EXIT_USAGE
from rtmu.cli import main
from rtmu.package_data import MAPS_DIR
from testdata import ARIA_MAPS

MAPS_DIR = MAPS_DIR


def test_text_summary(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mapinfo", str(ARIA_MAPS / "columbia.map")]) == 0
    out = capsys.readouterr().out
    assert "category:" in out and "2D-Map" in out
    assert "63311 (header: 63311)" in out
    assert "470 (header: 470)" in out
    assert "(-4780, -27000) .. (19560, 24680)" in out
    assert "20 mm" in out
    assert "ForbiddenLine 12" in out and "Goal 5" in out and "GoalWithHeading 3" in out
    assert '"Hallway 1"' in out
    assert "OriginLatLonAlt:" in out


def test_stale_header_is_pointed_out(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "stale.map"
    path.write_text("2D-Map\nNumLines: 9\nLINES\n" + "0 0 1 1\n" * 10 + "DATA\nnot a point\n")
    assert main(["mapinfo", str(path)]) == 0
    out = capsys.readouterr().out
    assert "10 (header: 9)  <- header is stale" in out
    assert "(1 data line skipped)" in out


def test_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mapinfo", str(MAPS_DIR / "office.map"), "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1
    info = json.loads(out)
    assert info["category"] == "2D-Map"
    assert info["points"] == info["claimed_points"] > 10_000
    assert info["lines"] == info["claimed_lines"] == 70
    assert info["bounds"][2:] == [info["scans"][0]["point_bounds"][2], info["scans"][0]["point_bounds"][3]]
    assert info["resolution"] == 20
    assert info["objects_by_type"]["ForbiddenArea"] == 1 and info["objects_by_type"]["Goal"] == 5
    assert "Meeting Room" in info["goals"]
    assert info["home"] == {"x": 2000.0, "y": 6000.0, "th": 0.0}
    assert info["unknown_keywords"] == [] and info["skipped_lines"] == 0


@pytest.mark.parametrize(
    ("content", "message", "code"),
    [
        (None, "cannot read", EXIT_USAGE),
        (b"hello\nDATA\n", ":1: not an ARIA map", EXIT_BAD_FILE),
        (b"2D-Map\nCairn: Goal 1 2\nDATA\n", ":2: Cairn: needs at least 7 fields", EXIT_BAD_FILE),
        (b"2D-Map\nMinPos: 0 0\n", ":2: ends before any DATA or LINES section", EXIT_BAD_FILE),
    ],
)
def test_a_missing_or_bad_file_exits_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes | None, message: str, code: int
) -> None:
    path = tmp_path / "bad.map"
    if content is not None:
        path.write_bytes(content)
    assert main(["mapinfo", str(path), "--json"]) == code
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1
    assert captured.err.startswith(f"rtmu mapinfo: {path}")
    assert message in captured.err


def test_real_command_line() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "rtmu", "mapinfo", str(MAPS_DIR / "arena.map"), "--json"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["goals"] == ["Goal", "Far corner"]
