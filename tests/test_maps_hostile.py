"""Hostile maps are refused before memory is spent: lying counts, huge files, huge lines, endless headers."""

from __future__ import annotations

import contextlib
import tracemalloc
from collections.abc import Callable
from pathlib import Path

import pytest

from rtmu.mapfile import MapFormatError, from_stream, parse_map, parse_map_lines, read_map

MB = 1 << 20


def peak_bytes(action: Callable[[], object]) -> int:
    """Peak memory Python and numpy allocated while ``action`` ran (numpy reports its buffers too)."""
    tracemalloc.start()
    with contextlib.suppress(MapFormatError):
        action()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak


def test_claimed_counts_allocate_nothing() -> None:
    text = (
        "2D-Map\nNumPoints: 1000000000\nNumLines: 2000000000\nMinPos: -2147483648 -2147483648\n"
        "MaxPos: 2147483647 2147483647\nLINES\n0 0 1 1\nDATA\n1 2\n"
    )
    assert peak_bytes(lambda: parse_map(text)) < 1 * MB
    data = parse_map(text)
    assert data.claimed.num_points == 1_000_000_000 and data.num_points == 1
    assert data.claimed.num_lines == 2_000_000_000 and data.num_lines == 1


def test_file_over_the_size_limit_is_not_read(tmp_path: Path) -> None:
    huge = tmp_path / "huge.map"
    with open(huge, "wb") as file:
        file.write(b"2D-Map\nDATA\n")
        file.truncate(600 * MB)  # sparse: costs no disk, but says 600 MB
    peak = peak_bytes(lambda: read_map(huge))
    assert peak < 1 * MB
    with pytest.raises(MapFormatError, match="over the 536870912-byte limit") as info:
        read_map(huge)
    assert info.value.source == str(huge) and info.value.line is None


def test_size_limit_is_configurable(tmp_path: Path) -> None:
    path = tmp_path / "small.map"
    path.write_bytes(b"2D-Map\nDATA\n" + b"1 2\n" * 1000)
    assert read_map(path).num_points == 1000
    with pytest.raises(MapFormatError, match="1000-byte limit"):
        read_map(path, max_bytes=1000)
    with pytest.raises(MapFormatError, match="1000-byte limit"):
        parse_map(path.read_bytes(), max_bytes=1000)


def test_huge_line_stops_reading_early(tmp_path: Path) -> None:
    path = tmp_path / "oneline.map"
    with open(path, "wb") as file:
        file.write(b"2D-Map\nDATA\n1 2\n")
        file.truncate(200 * MB)  # 200 MB of NUL bytes without a line break
    peak = peak_bytes(lambda: read_map(path))
    assert peak < 40 * MB  # one read chunk (8 MB) and its scan, not the file
    with pytest.raises(MapFormatError, match="line longer than 65536 bytes") as info:
        read_map(path)
    assert info.value.line == 4


@pytest.mark.parametrize("where", ["header", "data"])
def test_line_limit_in_text(where: str) -> None:
    long = "x" * 70_000
    text = f"2D-Map\nMetaInfo: {long}\nDATA\n" if where == "header" else f"2D-Map\nDATA\n1 2\n{long}\n"
    with pytest.raises(MapFormatError, match="line longer") as info:
        parse_map(text, source="t")
    assert info.value.line == (2 if where == "header" else 4)
    assert parse_map(text, max_line=100_000).source == "<map>"


def test_line_limit_for_streamed_maps() -> None:
    with pytest.raises(MapFormatError, match="line longer") as info:
        parse_map_lines(["2D-Map", "DATA", "1 2", "9" * 70_000])
    assert info.value.line == 4
    with pytest.raises(MapFormatError, match="line longer") as info:
        from_stream(["2D-Map", "MapInfo: " + "y" * 70_000], None, None)
    assert info.value.line == 2


def test_endless_header_is_bounded() -> None:
    text = "2D-Map\n" + "Frobnicate: 1\n" * 1000 + "DATA\n"
    assert len(parse_map(text).unknown_lines) == 1000
    with pytest.raises(MapFormatError, match="header longer than 500 lines") as info:
        parse_map(text, max_header_lines=500)
    assert info.value.line == 501


def test_many_garbage_lines_cost_counts_not_objects() -> None:
    text = b"2D-Map\nDATA\n" + b"garbage here\n" * 200_000 + b"1 2\n"
    peak = peak_bytes(lambda: parse_map(text))
    assert peak < 40 * MB
    data = parse_map(text)
    assert data.skipped_lines == 200_000 and len(data.warnings) == 100
    assert data.points.tolist() == [[1, 2]]


def test_binary_junk_is_not_a_map() -> None:
    with pytest.raises(MapFormatError, match="not an ARIA map"):
        parse_map(bytes(range(256)) * 10)
    data = parse_map(b"2D-Map\nDATA\n" + bytes(range(256)) + b"\n1 2\n")
    assert data.points.tolist() == [[1, 2]] and data.skipped_lines >= 1
