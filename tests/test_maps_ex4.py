"""Ex4 maps (ARAM's ``2D-Map-Ex4``, and later ``-ExN``) through every path: file, ``mapinfo``,
``getMap`` text and ``getMapBinary`` downloads from the simulator, and writing back.

The map is our own, made here with header lines invented in the Ex4 spirit (extra ``MapInfo:``
lines, keywords no reader knows, Cairn types nobody defined), so nothing is copied from a robot.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK
from rtmu.cli import main
from rtmu.mapfile import read_map, write_map
from rtmu.sim import SimConfig, SimThread
from testdata import ARIA_MAPS

UNKNOWN_LINES = (
    "MapScaleFactor: 1.000000",
    'LocalizationParams: MinScore=0.42 Grid="fine"',
    "FleetZoneVersion: 7",
)
EX4_MAP = "\n".join(
    (
        "2D-Map-Ex4",
        "MinPos: 0 0",
        "MaxPos: 4000 3000",
        "NumPoints: 3",
        "LineMinPos: 0 0",
        "LineMaxPos: 4000 3000",
        "NumLines: 2",
        "Resolution: 20",
        *UNKNOWN_LINES,
        'MapInfo: GoalType Name=Goal "Label=Goal" "Desc=Goal"',
        'MapInfo: SectorType Name=SpeedZone Shape=Polygon "Desc=A slow zone" MaxSpeed=float',
        'MapInfo: ArgDesc Name=SpeedZone Kind="Ex4 only"',
        'Cairn: Goal 1000 1000 90 "" ICON "Dock Front"',
        'Cairn: ChargingStation 2000 500 0 "" ICON "Charger 1"',
        'Cairn: SpeedZone 2500 1500 0 "slow" ICON "Zone A" 2000 1000 3000 2000',
        "DATA",
        "100 100",
        "2000 2500",
        "3900 2900",
        "LINES",
        "0 0 4000 0",
        "0 0 0 3000",
        "",
    )
)


@pytest.fixture()
def ex4_file(tmp_path: Path) -> Path:
    path = tmp_path / "ex4.map"
    path.write_text(EX4_MAP, encoding="latin-1")
    return path


def _check(data) -> None:  # type: ignore[no-untyped-def]
    assert data.category == "2D-Map-Ex4"
    assert data.num_points == 3 and data.num_lines == 2
    kinds = sorted(o.type for o in data.objects)
    assert kinds == ["ChargingStation", "Goal", "SpeedZone"]
    assert [line for line in data.unknown_lines] == list(UNKNOWN_LINES)


def test_an_ex4_file_reads_keeping_unknown_lines_and_cairn_types(ex4_file: Path) -> None:
    _check(read_map(ex4_file))


@pytest.mark.parametrize("first", ["2D-Map-Ex5", "2d-map-ex12"])
def test_later_ex_headers_are_accepted_too(tmp_path: Path, first: str) -> None:
    path = tmp_path / "later.map"
    path.write_text(EX4_MAP.replace("2D-Map-Ex4", first, 1), encoding="latin-1")
    assert read_map(path).category == first.replace("2d-map-ex", "2D-Map-Ex")


def test_a_non_map_is_still_refused(tmp_path: Path) -> None:
    path = tmp_path / "no.map"
    path.write_text(EX4_MAP.replace("2D-Map-Ex4", "2D-Map-Exotic", 1), encoding="latin-1")
    with pytest.raises(Exception, match="not an ARIA map"):
        read_map(path)


def test_writing_an_ex4_map_keeps_its_header_and_unknown_lines(ex4_file: Path, tmp_path: Path) -> None:
    out = tmp_path / "again.map"
    write_map(read_map(ex4_file), out)
    text = out.read_text(encoding="latin-1")
    assert text.startswith("2D-Map-Ex4\n")
    for line in UNKNOWN_LINES:
        assert line in text
    _check(read_map(out))


def test_mapinfo_describes_an_ex4_file(ex4_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mapinfo", str(ex4_file), "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["category"] == "2D-Map-Ex4"
    assert summary["unknown_lines"] == len(UNKNOWN_LINES)


@pytest.mark.parametrize(
    ("profile", "text"),
    [("default", True), ("default", False), ("aram", True), ("aram", False)],
    ids=["getMap", "getMapBinary", "aram-getMap", "aram-getMapBinary"],
)
def test_an_ex4_map_downloads_from_the_simulator(
    ex4_file: Path, tmp_path: Path, profile: str, text: bool
) -> None:
    out = tmp_path / "down.map"
    with SimThread(SimConfig(port=0, map_path=ex4_file, profile=profile)) as sim:
        args = ["map", f"127.0.0.1:{sim.port}", "--out", str(out), "--timeout", cli_timeout(10)]
        assert main([*args, "--text"] if text else args) == EXIT_OK
    data = read_map(out)
    if text or profile == "aram":
        _check(data)  # the text stream carries the file verbatim; ARAM's binary header says Ex4
    else:
        # serverDemo's binary stream names its first line 2D-Map; everything else is kept
        assert data.category == "2D-Map"
        _check(replace(data, category="2D-Map-Ex4"))


def test_real_aria_maps_still_read() -> None:
    for path in sorted(ARIA_MAPS.glob("*.map")):
        assert read_map(path).category.startswith("2D-Map"), path
