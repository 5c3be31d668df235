"""Map format figures: parse, write and generate a 1 M-point map (temporary files, never in the repo).

Baselines are the simple ways measured in the same run: a line-by-line Python
parser (split each line, ``int()`` each token) and a line-by-line writer.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from bench.common import Result, best_time
from rtmu.mapfile import map_header_lines, read_map, write_map
from rtmu.sim.mapgen import generate_map

POINTS = 1_000_000
LINES = 10_000
SEED = 2024


def naive_parse(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The obvious reader: every line through Python, section by section."""
    points: list[tuple[int, int]] = []
    segments: list[tuple[int, ...]] = []
    target: list | None = None
    with open(path, encoding="latin-1") as file:
        for line in file:
            words = line.split()
            if not words:
                continue
            if words[0] == "DATA":
                target, width = points, 2
                continue
            if words[0] == "LINES":
                target, width = segments, 4
                continue
            if target is None:
                continue
            try:
                row = tuple(int(w) for w in words)
            except ValueError:
                continue
            if len(row) == width:
                target.append(row)
    return np.array(points, dtype=np.int32), np.array(segments, dtype=np.int32)


def naive_write(data, path: Path) -> None:  # type: ignore[no-untyped-def]
    """The obvious writer: the header lines, then one formatted string per point."""
    with open(path, "w", encoding="latin-1") as file:
        for line in map_header_lines(data):
            file.write(line + "\n")
        file.write("LINES\n")
        for x1, y1, x2, y2 in data.segments.tolist():
            file.write(f"{x1} {y1} {x2} {y2}\n")
        file.write("DATA\n")
        for x, y in data.points.tolist():
            file.write(f"{x} {y}\n")


def run() -> list[Result]:
    generate_seconds = best_time(lambda: generate_map(POINTS, LINES, SEED), repeat=3, min_seconds=0.0)
    data = generate_map(POINTS, LINES, SEED)
    with tempfile.TemporaryDirectory(prefix="rtmu-bench-maps-") as folder:
        path = Path(folder) / "big.map"
        naive_path = Path(folder) / "naive.map"
        write_seconds = best_time(lambda: write_map(data, path), repeat=3, min_seconds=0.0)
        naive_write_seconds = best_time(lambda: naive_write(data, naive_path), repeat=2, min_seconds=0.0)
        parse_seconds = best_time(lambda: read_map(path), repeat=3, min_seconds=0.0)
        naive_parse_seconds = best_time(lambda: naive_parse(path), repeat=2, min_seconds=0.0)
        # The figures only count if both readers agree with what was written.
        again = read_map(path)
        naive_points, naive_segments = naive_parse(path)
        assert again == data
        assert np.array_equal(naive_points, data.points) and np.array_equal(naive_segments, data.segments)
    return [
        Result("maps.parse_1m_points", parse_seconds, "s", baseline=naive_parse_seconds),
        Result("maps.write_1m_points", write_seconds, "s", baseline=naive_write_seconds),
        Result("maps.generate_1m_points", generate_seconds, "s"),
    ]
