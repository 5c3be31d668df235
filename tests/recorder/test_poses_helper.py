"""The test helper that says where a recording had the robot holds on a loaded machine too.

A replay that has delivered all the server's bytes ends where the recording's last pose put the robot,
however long after those bytes a busy machine logged it (a 25 ms lag failed test_replay once).
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

from mcap.writer import Writer

from rtmu.capture.recorded import RAW_TOPICS
from rtmu.recorder import topics

from .poses import recorded_pose_at

MS = 1_000_000


def pose_bytes(x_mm: float, y_mm: float) -> bytes:
    """A PoseInFrame with only its position (fields 3 → 1 → x, y), as poses.py reads it."""
    position = b"\x09" + struct.pack("<d", x_mm / 1000) + b"\x11" + struct.pack("<d", y_mm / 1000)
    pose = b"\x0a" + bytes([len(position)]) + position
    return b"\x1a" + bytes([len(pose)]) + pose


def write(path: Path, chunks_ms: list[int], poses_ms: list[tuple[int, float]], disconnect_ms: int) -> Path:
    with path.open("wb") as f:
        writer = Writer(f)
        writer.start()
        raw = writer.register_channel(RAW_TOPICS["s2c"], "application/octet-stream", 0)
        pose = writer.register_channel(topics.POSE, "protobuf", 0)
        stops = writer.register_channel(topics.STOPS, "json", 0)
        for n, at in enumerate(chunks_ms):
            writer.add_message(raw, at * MS, b"\xfa\xfb", at * MS, n)
        for n, (at, x) in enumerate(poses_ms):
            writer.add_message(pose, at * MS, pose_bytes(x, 27), at * MS, n)
        stop = json.dumps({"reason": "disconnect"}).encode()
        writer.add_message(stops, disconnect_ms * MS, stop, disconnect_ms * MS, 0)
        writer.finish()
    return path


def test_after_the_last_bytes_the_last_pose_counts_however_late_it_was_logged(tmp_path: Path) -> None:
    path = write(tmp_path / "late.mcap", [1000, 1100], [(1005, 435), (1125, 436)], disconnect_ms=1500)
    assert recorded_pose_at(path, 1100 * MS) == (436, 27), "the last bytes' pose, logged 25 ms after them"


def test_before_the_last_bytes_a_pose_belongs_to_the_bytes_it_followed(tmp_path: Path) -> None:
    path = write(tmp_path / "mid.mcap", [1000, 1100, 1200], [(1005, 435), (1105, 436)], disconnect_ms=1500)
    assert recorded_pose_at(path, 1000 * MS) == (435, 27)
    assert recorded_pose_at(path, 1100 * MS) == (436, 27)
