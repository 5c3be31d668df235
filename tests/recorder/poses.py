"""Where a recording had the robot: its ``/robot/pose`` channel read with the ``mcap`` package."""

from __future__ import annotations

import struct
from pathlib import Path

from rtmu.capture.recorded import RAW_TOPICS
from rtmu.recorder import topics

from .mcapread import read


def poses(path: Path) -> list[tuple[int, tuple[float, float]]]:
    """(log time, (x, y) in mm) of every recorded pose, from the PoseInFrame protobuf's position doubles."""
    out = []
    for m in read(path).topic(topics.POSE):
        out.append((m.log_time, _position(m.data)))
    return out


def _position(pose_in_frame: bytes) -> tuple[float, float]:
    # PoseInFrame.pose (3) → Pose.position (1) → Vector3 x (1), y (2) as doubles: found by their tags.
    pose = _field(pose_in_frame, 3)
    position = _field(pose, 1)
    x = y = 0.0
    i = 0
    while i < len(position):
        tag = position[i]
        if tag in (0x09, 0x11, 0x19):
            value = struct.unpack("<d", position[i + 1 : i + 9])[0]
            if tag == 0x09:
                x = value
            elif tag == 0x11:
                y = value
            i += 9
        else:
            raise AssertionError(f"unexpected tag {tag}")
    return round(x * 1000), round(y * 1000)


def _field(message: bytes, number: int) -> bytes:
    i = 0
    while i < len(message):
        key = message[i]
        i += 1
        wire = key & 7
        if wire == 2:
            size, shift = 0, 0
            while True:
                b = message[i]
                i += 1
                size |= (b & 0x7F) << shift
                shift += 7
                if not b & 0x80:
                    break
            if key >> 3 == number:
                return message[i : i + size]
            i += size
        elif wire == 0:
            while message[i] & 0x80:
                i += 1
            i += 1
        elif wire == 1:
            i += 8
        elif wire == 5:
            i += 4
    return b""


def recorded_pose_at(path: Path, at_ns: int) -> tuple[float, float]:
    """The pose the recording had at ``at_ns`` (a pose is logged just after the bytes that carried it).

    Once the server's last bytes are delivered, that is the last pose before the session disconnected,
    however late a loaded machine logged it; before then, the pose logged within 20 ms of the bytes.
    """
    recording = read(path)
    ended = [m.log_time for m in recording.topic(topics.STOPS) if m.json()["reason"] == "disconnect"]
    more = any(m.log_time > at_ns for m in recording.topic(RAW_TOPICS["s2c"]))
    allowance = [at_ns + 20_000_000] if more or not ended else []
    cut = min([*allowance, *ended])  # the session's own reset as it disconnects is not the robot
    before = [p for t, p in poses(path) if t < cut]
    return before[-1]
