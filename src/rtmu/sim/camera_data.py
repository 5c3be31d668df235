"""The simulated camera's requests: the VC-C4 head (absolute, relative, percent, the legacy integer
forms), its mode list, and the shared live frame for ``getVideo`` / ``getPicture``.

A data module of the simulator as the others are (``HANDLERS``, merged by :mod:`.profiles`), split from
:mod:`.handlers` so that the robot's own requests and the camera's each fit in a module.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads.camera import Camera as CameraPayload
from rtmu.protocol.payloads.camera import (
    CameraCommand,
    CameraData,
    CameraInfo,
    CameraList,
    CameraModeList,
    CameraModeUpdated,
    CameraUpdate,
    LegacyCameraInfo,
    Picture,
    SetCameraAbs,
    SetCameraPct,
    SetCameraRel,
    VideoFrame,
    VideoRequest,
    VideoSize,
)

from .camera import PAN_RANGE, TILT_RANGE, ZOOM_RANGE, PanTiltZoom
from .handlers import Call, Handler, Reply, decode_lenient, handles_into

HANDLERS: dict[str, Handler] = {}
handles = handles_into(HANDLERS)


# -- camera and video ----------------------------------------------------------------------
CAMERA_NAME = "Cam1"
CAMERA_COMMANDS = (
    ("cameraModeUpdated", "cameraModeUpdatedCam1", -1),
    ("getCameraData", "getCameraDataCam1", 100),
    ("getCameraDataInt", "cameraUpdate", -1),
    ("getCameraInfo", "getCameraInfoCam1", -1),
    ("getCameraInfoInt", "cameraInfo", -1),
    ("getCameraModeList", "getCameraModeListCam1", -1),
    ("getPicture", "getPictureCam1", -1),
    ("getVideo", "sendVideo", -1),
    ("resetCamera", "resetCameraCam1", -1),
    ("setCameraAbs", "setCameraAbsCam1", -1),
    ("setCameraAbsInt", "cameraAbs", -1),
    ("setCameraMode", "setCameraModeCam1", -1),
    ("setCameraPct", "setCameraPctCam1", -1),
    ("setCameraPctInt", "cameraPct", -1),
    ("setCameraRel", "setCameraRelCam1", -1),
    ("setCameraRelInt", "camera", -1),
)
CAMERA_MODES = ("Position",)


def _frame(call: Call, cls: type[VideoFrame]) -> Iterable[Reply]:
    """The shared latest frame (see :mod:`.video`); when it is being rendered the reply follows later."""
    try:
        quality = VideoRequest.decode(call.args).quality
    except (FieldUnderrun, PayloadError, ValueError):
        quality = None
    server, session, number = call.server, call.session, call.number
    size = server.video_size
    trailer = server.video_trailer()

    def payload(jpeg: bytes) -> bytes:
        return cls(size[0], size[1], jpeg, trailer).encode()

    def deliver(jpeg: bytes) -> None:
        session.send(number, payload(jpeg))

    view = call.world.camera_view(size)
    jpeg = server.video.picture(view, call.world.time, quality, (session.ident, number), deliver)
    return () if jpeg is None else (payload(jpeg),)


@handles("sendVideo")
def _send_video(call: Call) -> Iterable[Reply]:
    return _frame(call, VideoFrame)


@handles("getPictureCam1")
def _get_picture(call: Call) -> Iterable[Reply]:
    return _frame(call, Picture)


@handles("videoSize")
def _video_size(call: Call) -> Iterable[Reply]:
    w, h = call.server.video_size
    return (VideoSize(w, h, call.server.video_trailer()).encode(),)


@handles("getCameraList")
def _camera_list(call: Call) -> Iterable[Reply]:
    commands = tuple(CameraCommand(c, d, i) for c, d, i in CAMERA_COMMANDS)
    camera = CameraPayload(CAMERA_NAME, "VCC4", "Camera", "", commands)
    return (CameraList((camera,)).encode(),)


@handles("getCameraDataCam1")
def _camera_data(call: Call) -> Iterable[Reply]:
    p = call.world.camera.ptz
    return (CameraData(p.pan, p.tilt, p.zoom).encode(),)


@handles("cameraUpdate")
def _camera_update(call: Call) -> Iterable[Reply]:
    p = call.world.camera.ptz
    return (CameraUpdate(round(p.pan), round(p.tilt), round(p.zoom)).encode(),)


@handles("getCameraInfoCam1")
def _camera_info(call: Call) -> Iterable[Reply]:
    return (CameraInfo(*PAN_RANGE, *TILT_RANGE, *ZOOM_RANGE, True).encode(),)


@handles("cameraInfo")
def _legacy_camera_info(call: Call) -> Iterable[Reply]:
    (pan0, pan1), (tilt0, tilt1) = PAN_RANGE, TILT_RANGE
    return (LegacyCameraInfo(round(pan0), round(pan1), round(tilt0), round(tilt1), 0, 100, True).encode(),)


@handles("setCameraAbsCam1")
def _set_camera_abs(call: Call) -> Iterable[Reply]:
    a = decode_lenient(SetCameraAbs, call.args)
    call.world.camera.ptz.aim(a.pan, a.tilt, a.zoom or 0.0)
    return ()


@handles("setCameraRelCam1")
def _set_camera_rel(call: Call) -> Iterable[Reply]:
    a = decode_lenient(SetCameraRel, call.args)
    p = call.world.camera.ptz
    pan, tilt, zoom = p.target()
    factor = max(1.0 - zoom / 100.0, 0.01)
    pan += _away_from_zero(a.pan * factor)
    tilt += _away_from_zero(a.tilt * factor)
    p.aim(pan, tilt, zoom + (a.zoom or 0.0))
    return ()


@handles("setCameraPctCam1")
def _set_camera_pct(call: Call) -> Iterable[Reply]:
    a = decode_lenient(SetCameraPct, call.args)
    p = call.world.camera.ptz
    pan, tilt, zoom = p.target()
    half = PanTiltZoom(zoom=zoom).fov_deg / 2
    p.aim(pan + a.pan / 100.0 * half, tilt - a.tilt / 100.0 * half * 0.75, zoom)
    return ()


@handles("camera", "cameraAbs", "cameraPct")
def _legacy_camera_move(call: Call) -> Iterable[Reply]:
    data = call.args + b"\x00\x00\x00"
    d_pan, d_tilt, d_zoom = (int.from_bytes(data[i : i + 1], "little", signed=True) for i in range(3))
    p = call.world.camera.ptz
    pan, tilt, zoom = p.target()
    fov = PanTiltZoom(zoom=zoom).fov_deg
    if call.name == "camera":
        p.aim(pan + d_pan, tilt + d_tilt, zoom + d_zoom)
    elif call.name == "cameraAbs":
        p.aim(d_pan, d_tilt, d_zoom)
    else:
        p.aim(pan + d_pan / 100.0 * fov / 2, tilt - d_tilt / 100.0 * fov * 0.375, zoom)
    return ()


@handles("resetCameraCam1")
def _reset_camera(call: Call) -> Iterable[Reply]:
    call.world.camera.ptz.aim(0.0, 0.0, 0.0)
    return ()


@handles("getCameraModeListCam1")
def _camera_modes(call: Call) -> Iterable[Reply]:
    return (CameraModeList(CAMERA_MODES).encode(),)


@handles("cameraModeUpdatedCam1")
def _camera_mode_updated(call: Call) -> Iterable[Reply]:
    return (CameraModeUpdated(None).encode(),)  # ARIA: empty until the mode first changes


@handles("setCameraModeCam1", "setCameraParams")
def _camera_ignored(call: Call) -> Iterable[Reply]:
    return ()


def _away_from_zero(value: float) -> float:
    return float(math.copysign(math.ceil(abs(value)), value)) if value else 0.0
