"""Typed session values → Foxglove messages and JSON records, for the writer thread.

Pure apart from remembering what it last wrote: the robot's pose and status are written when
they change and, for a recording, again while they do not (:meth:`Converter.repeat`: a parked
robot is in every second of the file, so any window of it shows the robot), the map once per
loaded map. Nothing is written
of the robot before the server first described it (no placeholder pose at 0, 0; no empty status).
Runs on the writer thread only (a big map's lines take a while to build).
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, is_dataclass, replace
from enum import Enum
from typing import Any

import numpy as np
from foxglove.messages import (
    Color,
    CompressedImage,
    FrameTransform,
    LinePrimitive,
    LinePrimitiveLineType,
    PackedElementField,
    PackedElementFieldNumericType,
    Point3,
    PointCloud,
    Pose,
    PoseInFrame,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    Timestamp,
    Vector3,
)

from ..base.notices import Notice
from ..values.state import (
    CameraChanged,
    ConnectionChanged,
    DrawingsChanged,
    HealthChanged,
    MapChanged,
    MapModel,
    MapPhase,
    RobotChanged,
    RobotState,
    StateChange,
)
from . import topics

MAP_FRAME = "map"
ROBOT_FRAME = "base_link"
CAMERA_FRAME = "camera"
REPEAT_NS = 250_000_000
"""The pose (with its transform) and the status are written again after this long unchanged
(:meth:`Converter.repeat`, called every :data:`REPEAT_EVERY` s): never a second of the file without them."""
REPEAT_EVERY = 0.5
"""As long as the writer gathers (``recording.GATHER_SECONDS``): a parked robot's repeats come with
the writer's gathering wakes, not with wakes of their own."""
MAX_SCENE_LINES = 200_000
"""Map lines beyond this are left out of the SceneUpdate (the raw channel still has them all)."""
_XYZ = [
    PackedElementField(name="x", offset=0, type=PackedElementFieldNumericType.Float32),
    PackedElementField(name="y", offset=4, type=PackedElementFieldNumericType.Float32),
    PackedElementField(name="z", offset=8, type=PackedElementFieldNumericType.Float32),
]
_MAP_LINE_COLOR = Color(r=0.1, g=0.1, b=0.1, a=1.0)

Message = Any
"""A foxglove message, or a dict for a JSON topic."""
Out = list[tuple[str, Message]]


def stamp(at_ns: int) -> Timestamp:
    return Timestamp(at_ns // 1_000_000_000, at_ns % 1_000_000_000)


def yaw(degrees: float) -> Quaternion:
    half = math.radians(degrees) / 2.0
    return Quaternion(x=0.0, y=0.0, z=math.sin(half), w=math.cos(half))


def cloud(points_mm: np.ndarray | tuple[tuple[int, int], ...], at_ns: int) -> PointCloud:
    """(x, y) in mm, map frame → a PointCloud of float32 x, y, z in metres."""
    xy = np.asarray(points_mm, dtype=np.float64).reshape(-1, 2)
    xyz = np.zeros((len(xy), 3), dtype="<f4")
    xyz[:, :2] = xy / 1000.0
    return PointCloud(
        timestamp=stamp(at_ns), frame_id=MAP_FRAME, point_stride=12, fields=_XYZ, data=xyz.tobytes()
    )


def jsonable(value: Any) -> Any:
    """Dataclasses, enums, sets and tuples as plain JSON values (non-finite floats as strings)."""
    if isinstance(value, Enum):
        return value.value
    if is_dataclass(value) and not isinstance(value, type):
        return {k: jsonable(v) for k, v in asdict(value).items()}
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, (set, frozenset)):
        return sorted(jsonable(v) for v in value)
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, (bytes, bytearray)):
        return f"<{len(value)} bytes>"
    return value


def other_topic(change: object) -> str:
    """``/rtmu/navigation`` for ``NavChanged``; ``/rtmu/state/<part>`` for other parts without a topic."""
    name = type(change).__name__.removesuffix("Changed")
    if name == "Nav":
        return topics.NAVIGATION
    return topics.STATE_PREFIX + re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def notice_record(notice: Notice) -> dict[str, Any]:
    return {"kind": notice.kind.value, "level": notice.level.value, "text": notice.text}


def status_record(r: RobotState) -> dict[str, Any]:
    """What "why did the robot stop" needs besides the stops: modes, status words, battery, motion."""
    battery: dict[str, Any] = {"state": r.battery_state, "low": r.battery_low, "shutdown": r.battery_shutdown}
    if r.battery_v is not None:  # None until the robot said which it is (the session holds it back)
        battery["state_of_charge_pct" if r.battery_is_soc else "volts"] = r.battery_v
    return {
        "mode": r.mode,
        "mode_name": r.mode_name,
        "status": r.status,
        "extended_status": r.extended_status,
        "battery": battery,
        "vel_mm_s": r.vel,
        "rot_vel_deg_s": r.rot_vel,
        "lat_vel_mm_s": r.lat_vel,
        "moving": r.moving,
        "temperature_c": r.temperature,
        "safe_drive": r.safe_drive,
        "dock_state": r.dock_state,
        "wifi_quality": r.wifi_quality,
        "wifi_signal": r.wifi_signal,
        "closest_obstacle_mm": r.closest_obstacle_mm,
    }


class Converter:
    """One recording's conversions; remembers what it wrote so unchanged parts are not repeated."""

    def __init__(self) -> None:
        self._pose: tuple[float, float, float] | None = None
        self._pose_ns = 0
        self._status: dict[str, Any] | None = None
        self._status_ns = 0
        self._robot: RobotState | None = None
        self._described_ns: int | None = None
        """When the server first described the robot."""
        self._sonar: object = ()
        self._laser: object = ()
        self._map_state: tuple[Any, ...] | None = None
        self._map_written: int | None = None
        self._camera = -1
        self._drawings: object = None

    def change(self, change: StateChange, at_ns: int) -> Out:
        if isinstance(change, RobotChanged):
            return self.robot(change.value, at_ns)
        if isinstance(change, MapChanged):
            return self.map(change.value, at_ns)
        if isinstance(change, CameraChanged):
            image = change.value
            if image is None or image.sequence == self._camera:
                return []
            self._camera = image.sequence
            picture = CompressedImage(
                timestamp=stamp(at_ns), frame_id=CAMERA_FRAME, data=image.jpeg, format="jpeg"
            )
            return [(topics.CAMERA, picture)]
        if isinstance(change, ConnectionChanged):
            return [(topics.CONNECTION, jsonable(change.value))]
        if isinstance(change, HealthChanged):
            return [(topics.LINK_HEALTH, jsonable(change.value))]
        if isinstance(change, DrawingsChanged):
            # The list and what is shown, not every sample's points (those are in the raw bytes):
            # a 5 Hz laser would otherwise cost tens of MB an hour of JSON.
            layers: list[dict[str, Any]] = [
                {**jsonable(replace(d, points=())), "points": len(d.points)} for d in change.value.layers
            ]
            shape = [(d.name, d.shown, d.problem, bool(d.points)) for d in change.value.layers]
            if shape == self._drawings:
                return []
            self._drawings = shape
            summary = {"offered": change.value.offered, "note": change.value.note, "layers": layers}
            return [(other_topic(change), summary)]
        # Any other part (navigation, popups, parts added later) as JSON: nothing published is lost.
        return [(other_topic(change), jsonable(getattr(change, "value", change)))]

    def robot(self, r: RobotState, at_ns: int) -> Out:
        if r.numbers_at is None and r.strings_at is None:
            return []  # the session's starting value: the server has said nothing of the robot yet
        self._robot = r
        out = self._pose_and_status(r, at_ns, again=False)
        if r.sonar != self._sonar:
            self._sonar = r.sonar
            out.append((topics.SONAR, cloud(r.sonar, at_ns)))
        if r.laser != self._laser:
            self._laser = r.laser
            out.append((topics.LASER, cloud(r.laser, at_ns)))
        return out

    def repeat(self, at_ns: int) -> Out:
        """The pose (with its TF) and the status again where they went unwritten for :data:`REPEAT_NS`.

        The session publishes a robot only when it changes, so a parked robot's pose would be written
        once; a recording calls this a few times a second so every second of the file holds it.
        """
        return [] if self._robot is None else self._pose_and_status(self._robot, at_ns, again=True)

    def _pose_and_status(self, r: RobotState, at_ns: int, *, again: bool) -> Out:
        out: Out = []
        pose = (r.x, r.y, r.th)
        stale = at_ns - self._pose_ns >= REPEAT_NS
        if r.numbers_at is not None and (stale if again else pose != self._pose):
            self._pose, self._pose_ns = pose, at_ns
            when = stamp(at_ns)
            position = Vector3(x=r.x / 1000.0, y=r.y / 1000.0, z=0.0)
            pose_msg = Pose(position=position, orientation=yaw(r.th))
            out.append((topics.POSE, PoseInFrame(timestamp=when, frame_id=MAP_FRAME, pose=pose_msg)))
            tf = FrameTransform(
                timestamp=when,
                parent_frame_id=MAP_FRAME,
                child_frame_id=ROBOT_FRAME,
                translation=position,
                rotation=yaw(r.th),
            )
            out.append((topics.TF, tf))
        if self._described_ns is None:
            self._described_ns = at_ns
        if r.strings_at is None and at_ns - self._described_ns < REPEAT_NS:
            return (
                out  # its status words come with the next packet: no status without them (unless none come)
            )
        status = status_record(r) if not again or self._status is None else self._status
        if status != self._status or (again and at_ns - self._status_ns >= REPEAT_NS):
            self._status, self._status_ns = status, at_ns
            out.append((topics.STATUS, status))
        return out

    def map(self, m: MapModel, at_ns: int) -> Out:
        out: Out = []
        state = (m.state, m.name, m.generation, m.error)
        if state != self._map_state:
            self._map_state = state
            record = {"state": m.state.value, "name": m.name, "generation": m.generation, "error": m.error}
            out.append((topics.MAP_STATE, record))
        if m.state is MapPhase.READY and m.data is not None and self._map_written != m.generation:
            self._map_written = m.generation
            out.extend(map_messages(m, at_ns))
        return out


def map_messages(m: MapModel, at_ns: int) -> Out:
    """The map's lines as a SceneUpdate and its points as a PointCloud (metres, map frame)."""
    assert m.data is not None
    segments = np.asarray(m.data.scan.segments, dtype=np.float64).reshape(-1, 4)[:MAX_SCENE_LINES] / 1000.0
    ends = segments.reshape(-1, 2)
    points = [Point3(x=float(x), y=float(y), z=0.0) for x, y in ends.tolist()]
    lines = LinePrimitive(
        type=LinePrimitiveLineType.LineList,
        thickness=0.03,
        points=points,
        color=_MAP_LINE_COLOR,
        pose=Pose(position=Vector3(), orientation=yaw(0.0)),
    )
    entity = SceneEntity(
        timestamp=stamp(at_ns), frame_id=MAP_FRAME, id=f"map:{m.name}", lines=[lines] if points else []
    )
    return [(topics.MAP, SceneUpdate(entities=[entity])), (topics.MAP_POINTS, cloud(m.data.points, at_ns))]
