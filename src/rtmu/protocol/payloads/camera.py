"""Camera and video (protocol §4.6–4.7).

Camera data names carry the camera's name as a suffix (``getPictureCam1``,
``setCameraRelCam1``); those types match by prefix (see
:func:`~.base.payload_type_for`). Pan/tilt/zoom "doubles" of the camera
commands travel as ``byte2`` hundredths, not as text; they are held here in
degrees (zoom in % of range) and encode back by rounding to the hundredth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final, Self

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, NameMatch, Payload, Side, checked_count, register

JPEG_END: Final = b"\xff\xd9"
MAX_ARG_DEPTH: Final = 16
"""How deeply ``L`` (list) parameter blocks may nest before we call the packet hostile."""
DOUBLE_FACTOR: Final = 100
_LIMIT_FIELDS: Final = ("min pan", "max pan", "min tilt", "max tilt", "min zoom", "max zoom")


def _hundredths(value: float) -> int:
    scaled = value * DOUBLE_FACTOR
    return int(math.copysign(math.floor(abs(scaled) + 0.5), scaled))


# -- pictures ---------------------------------------------------------------------


@register
@dataclass(frozen=True, slots=True)
class VideoFrame(Payload):
    """``sendVideo`` reply: ``ubyte2`` width, ``ubyte2`` height, then a JPEG file filling the payload.

    Video forwarded by ``ArHybridForwarderVideo`` carries 2 junk bytes after
    the JPEG's end marker; they are kept in ``trailing`` so the payload
    re-encodes exactly. ``jpeg`` ends at the last ``FF D9`` (or takes
    everything when there is none).
    """

    DATA_NAME = "sendVideo"
    SIDE = Side.REPLY

    width: int
    height: int
    jpeg: bytes
    trailing: bytes = b""

    def encode(self) -> bytes:
        return FieldWriter().ubyte2(self.width).ubyte2(self.height).raw(self.jpeg).raw(self.trailing).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        width = r.ubyte2("width")
        height = r.ubyte2("height")
        rest = r.rest()
        end = rest.rfind(JPEG_END)
        if end < 0:
            return cls(width, height, rest)
        return cls(width, height, rest[: end + 2], rest[end + 2 :])


@register
@dataclass(frozen=True, slots=True)
class Picture(VideoFrame):
    """``getPicture<Name>`` reply (e.g. ``getPictureCam1``): laid out as ``sendVideo``."""

    DATA_NAME = "getPicture"
    NAME_MATCH = NameMatch.PREFIX


@register
@dataclass(frozen=True, slots=True)
class VideoRequest(Payload):
    """``sendVideo`` args: optional JPEG quality 0–100 (None = leave it out, as ARIA's example does)."""

    DATA_NAME = "sendVideo"
    SIDE = Side.ARGS

    quality: int | None = None

    def encode(self) -> bytes:
        return b"" if self.quality is None else FieldWriter().ubyte(self.quality).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(None if r.at_end() else r.ubyte("quality"))


@register
@dataclass(frozen=True, slots=True)
class PictureRequest(VideoRequest):
    """``getPicture<Name>`` args: optional quality, as ``sendVideo``."""

    DATA_NAME = "getPicture"
    NAME_MATCH = NameMatch.PREFIX


@register
@dataclass(frozen=True, slots=True)
class VideoSize(Payload):
    """``videoSize`` reply: ``ubyte2`` width, ``ubyte2`` height (+2 junk bytes when forwarded)."""

    DATA_NAME = "videoSize"
    SIDE = Side.REPLY

    width: int
    height: int
    trailing: bytes = b""

    def encode(self) -> bytes:
        return FieldWriter().ubyte2(self.width).ubyte2(self.height).raw(self.trailing).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.ubyte2("width"), r.ubyte2("height"), r.rest())


# -- camera list and its parameter blocks ---------------------------------------------


@dataclass(frozen=True, slots=True)
class ClientArg:
    """One parameter block in ``ArClientArg`` form (``ArClientArgUtils.cpp``, default settings).

    ``kind`` is the type character: ``B`` byte (bool), ``I`` byte4 with min/max,
    ``D`` double with min/max, ``S`` string, ``L`` list of child blocks, ``.``
    separator. Lower-case kinds are the same followed by a display-hint string.
    """

    name: str
    description: str
    priority: int
    kind: str
    value: int | float | str | None = None
    minimum: int | float | None = None
    maximum: int | float | None = None
    children: tuple[ClientArg, ...] = ()
    display_hint: str | None = None
    """Only with lower-case kinds."""

    def write(self, w: FieldWriter) -> None:
        if len(self.kind) != 1:
            raise ValueError(f"parameter kind must be one character, got {self.kind!r}")
        w.string(self.name).string(self.description).byte(self.priority).byte(ord(self.kind))
        base = self.kind.upper()
        if base == "B":
            w.byte(int(self.value or 0))
        elif base == "I":
            w.byte4(int(self.value or 0)).byte4(int(self.minimum or 0)).byte4(int(self.maximum or 0))
        elif base == "D":
            w.double(float(self.value or 0)).double(float(self.minimum or 0)).double(float(self.maximum or 0))
        elif base == "S":
            w.string(str(self.value or ""))
        elif base == "L":
            w.byte4(len(self.children))
            for child in self.children:
                child.write(w)
        elif base != ".":
            raise ValueError(f"unknown parameter kind {self.kind!r}")
        if self.kind.islower():
            w.string(self.display_hint or "")

    @classmethod
    def read(cls, r: FieldReader, depth: int = 0) -> ClientArg:
        if depth > MAX_ARG_DEPTH:
            raise PayloadError(f"parameter lists nested deeper than {MAX_ARG_DEPTH}")
        name = r.string("parameter name")
        description = r.string("parameter description")
        priority = r.byte("parameter priority")
        kind = chr(r.ubyte("parameter type"))
        base = kind.upper()
        value: int | float | str | None = None
        minimum: int | float | None = None
        maximum: int | float | None = None
        children: tuple[ClientArg, ...] = ()
        if base == "B":
            value = r.byte("bool parameter value")
        elif base == "I":
            value, minimum, maximum = r.byte4("int value"), r.byte4("int minimum"), r.byte4("int maximum")
        elif base == "D":
            value, minimum, maximum = (
                r.double("double value"),
                r.double("double minimum"),
                r.double("double max"),
            )
        elif base == "S":
            value = r.string("string parameter value")
        elif base == "L":
            count = checked_count(r.byte4("list child count"), 4, r, "list child count")
            children = tuple(cls.read(r, depth + 1) for _ in range(count))
        elif base != ".":
            raise PayloadError(f"unknown parameter type {kind!r} for {name!r}")
        hint = r.string("display hint") if kind.islower() and kind != "." else None
        return cls(name, description, priority, kind, value, minimum, maximum, children, hint)


@dataclass(frozen=True, slots=True)
class CameraCommand:
    """A generic camera command and the data name that implements it on this server."""

    command: str
    """e.g. ``getCameraData``."""
    data_name: str
    """e.g. ``getCameraDataCam1``."""
    interval_ms: int = -1
    """Suggested request interval; −1 = none."""


@dataclass(frozen=True, slots=True)
class Camera:
    name: str
    camera_type: str
    display_name: str
    display_type: str
    commands: tuple[CameraCommand, ...] = ()
    params: tuple[ClientArg, ...] = ()

    def data_name(self, command: str) -> str | None:
        """This camera's data name for a generic command (``getPicture`` → ``getPictureCam1``)."""
        for c in self.commands:
            if c.command == command:
                return c.data_name
        return None


@register
@dataclass(frozen=True, slots=True)
class CameraList(Payload):
    """``getCameraList`` reply: each camera with its command → data-name table and parameters."""

    DATA_NAME = "getCameraList"
    SIDE = Side.REPLY

    cameras: tuple[Camera, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte2(len(self.cameras))
        for cam in self.cameras:
            w.string(cam.name).string(cam.camera_type).string(cam.display_name).string(cam.display_type)
            w.byte2(len(cam.commands))
            for c in cam.commands:
                w.string(c.command).string(c.data_name).byte4(c.interval_ms)
            w.byte2(len(cam.params))
            for p in cam.params:
                p.write(w)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        cameras = []
        for _ in range(checked_count(r.byte2("camera count"), 6, r, "camera count")):
            name = r.string("camera name")
            camera_type = r.string("camera type")
            display_name = r.string("display name")
            display_type = r.string("display type")
            commands = tuple(
                CameraCommand(r.string("command"), r.string("command data name"), r.byte4("request interval"))
                for _ in range(checked_count(r.byte2("command count"), 6, r, "command count"))
            )
            params = tuple(
                ClientArg.read(r)
                for _ in range(checked_count(r.byte2("parameter count"), 4, r, "parameter count"))
            )
            cameras.append(Camera(name, camera_type, display_name, display_type, commands, params))
        return cls(tuple(cameras))


@register
@dataclass(frozen=True, slots=True)
class CameraListUpdated(EmptyPayload):
    """``cameraListUpdated`` broadcast (empty): ask ``getCameraList`` again."""

    DATA_NAME = "cameraListUpdated"
    SIDE = Side.REPLY


# -- pan / tilt / zoom (byte2 hundredths) ---------------------------------------------


@register
@dataclass(frozen=True, slots=True)
class CameraData(Payload):
    """``getCameraData<N>`` reply: pan and tilt in degrees, zoom in % of its range."""

    DATA_NAME = "getCameraData"
    SIDE = Side.REPLY
    NAME_MATCH = NameMatch.PREFIX

    pan: float
    tilt: float
    zoom: float

    def encode(self) -> bytes:
        w = FieldWriter()
        for v in (self.pan, self.tilt, self.zoom):
            w.byte2(_hundredths(v))
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte2("pan") / 100, r.byte2("tilt") / 100, r.byte2("zoom") / 100)


@register
@dataclass(frozen=True, slots=True)
class CameraInfo(Payload):
    """``getCameraInfo<N>`` reply: the pan/tilt/zoom limits and whether the camera zooms."""

    DATA_NAME = "getCameraInfo"
    SIDE = Side.REPLY
    NAME_MATCH = NameMatch.PREFIX

    min_pan: float
    max_pan: float
    min_tilt: float
    max_tilt: float
    min_zoom: float = 0.0
    max_zoom: float = 100.0
    zoom_available: bool = True

    def encode(self) -> bytes:
        w = FieldWriter()
        for v in (self.min_pan, self.max_pan, self.min_tilt, self.max_tilt, self.min_zoom, self.max_zoom):
            w.byte2(_hundredths(v))
        return w.byte(1 if self.zoom_available else 0).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        pan0, pan1, tilt0, tilt1, zoom0, zoom1 = (
            r.byte2(f) / 100 for f in ("min pan", "max pan", "min tilt", "max tilt", "min zoom", "max zoom")
        )
        return cls(pan0, pan1, tilt0, tilt1, zoom0, zoom1, r.byte("zoom available") != 0)


@register
@dataclass(frozen=True, slots=True)
class SetCameraAbs(Payload):
    """``setCameraAbs<N>`` args: pan/tilt (deg) and zoom (%); a missing zoom means 0 (zoomed all out)."""

    DATA_NAME = "setCameraAbs"
    SIDE = Side.ARGS
    NAME_MATCH = NameMatch.PREFIX

    pan: float
    tilt: float
    zoom: float | None = None

    def encode(self) -> bytes:
        w = FieldWriter().byte2(_hundredths(self.pan)).byte2(_hundredths(self.tilt))
        if self.zoom is not None:
            w.byte2(_hundredths(self.zoom))
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        pan, tilt = r.byte2("pan") / 100, r.byte2("tilt") / 100
        return cls(pan, tilt, None if r.remaining < 2 else r.byte2("zoom") / 100)


@register
@dataclass(frozen=True, slots=True)
class SetCameraRel(SetCameraAbs):
    """``setCameraRel<N>`` args: pan/tilt steps (deg) and an optional zoom step (None = no zoom change)."""

    DATA_NAME = "setCameraRel"


@register
@dataclass(frozen=True, slots=True)
class SetCameraPct(Payload):
    """``setCameraPct<N>`` args: a point as −100…100 % of half the field of view from the image centre."""

    DATA_NAME = "setCameraPct"
    SIDE = Side.ARGS
    NAME_MATCH = NameMatch.PREFIX

    pan: float
    tilt: float

    def encode(self) -> bytes:
        return FieldWriter().byte2(_hundredths(self.pan)).byte2(_hundredths(self.tilt)).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte2("pan percent") / 100, r.byte2("tilt percent") / 100)


@register
@dataclass(frozen=True, slots=True)
class CameraModeList(Payload):
    """``getCameraModeList<N>`` reply: ``ubyte2`` count, then mode names."""

    DATA_NAME = "getCameraModeList"
    SIDE = Side.REPLY
    NAME_MATCH = NameMatch.PREFIX

    modes: tuple[str, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().ubyte2(len(self.modes))
        for m in self.modes:
            w.string(m)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.ubyte2("mode count"), 1, r, "mode count")
        return cls(tuple(r.string("camera mode") for _ in range(count)))


@register
@dataclass(frozen=True, slots=True)
class SetCameraMode(Payload):
    """``setCameraMode<N>`` args: a mode name; ``LookAtPoint`` also takes a point (mm)."""

    DATA_NAME = "setCameraMode"
    SIDE = Side.ARGS
    NAME_MATCH = NameMatch.PREFIX

    mode: str
    point: tuple[int, int] | None = None

    def encode(self) -> bytes:
        w = FieldWriter().string(self.mode)
        if self.point is not None:
            w.byte4(self.point[0]).byte4(self.point[1])
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        mode = r.string("camera mode")
        if r.at_end():
            return cls(mode)
        return cls(mode, (r.byte4("look-at x"), r.byte4("look-at y")))


@register
@dataclass(frozen=True, slots=True)
class CameraModeUpdated(Payload):
    """``cameraModeUpdated<N>`` reply/broadcast; empty (mode None) before the first mode change."""

    DATA_NAME = "cameraModeUpdated"
    SIDE = Side.REPLY
    NAME_MATCH = NameMatch.PREFIX

    mode: str | None
    point: tuple[int, int] | None = None

    def encode(self) -> bytes:
        if self.mode is None:
            return b""
        return SetCameraMode(self.mode, self.point).encode()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(None)
        m = SetCameraMode.decode(data)
        return cls(m.mode, m.point)


# -- legacy integer commands (one camera, no suffix) -----------------------------------


@register
@dataclass(frozen=True, slots=True)
class CameraUpdate(Payload):
    """``cameraUpdate`` reply (legacy): pan, tilt in whole degrees, zoom in % of its maximum."""

    DATA_NAME = "cameraUpdate"
    SIDE = Side.REPLY

    pan: int
    tilt: int
    zoom: int

    def encode(self) -> bytes:
        return FieldWriter().byte2(self.pan).byte2(self.tilt).byte2(self.zoom).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte2("pan"), r.byte2("tilt"), r.byte2("zoom"))


@register
@dataclass(frozen=True, slots=True)
class LegacyCameraInfo(Payload):
    """``cameraInfo`` reply (legacy): limits in whole degrees, zoom 0–100, zoom flag."""

    DATA_NAME = "cameraInfo"
    SIDE = Side.REPLY

    min_pan: int
    max_pan: int
    min_tilt: int
    max_tilt: int
    min_zoom: int = 0
    max_zoom: int = 100
    zoom_available: bool = True

    def encode(self) -> bytes:
        w = FieldWriter()
        for v in (self.min_pan, self.max_pan, self.min_tilt, self.max_tilt, self.min_zoom, self.max_zoom):
            w.byte2(v)
        return w.byte(1 if self.zoom_available else 0).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        pan0, pan1, tilt0, tilt1, zoom0, zoom1 = (r.byte2(f) for f in _LIMIT_FIELDS)
        return cls(pan0, pan1, tilt0, tilt1, zoom0, zoom1, r.byte("zoom available") != 0)
