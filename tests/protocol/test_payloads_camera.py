"""Camera and video payloads (protocol §4.6–4.7): frames with trailing bytes, camera list, PTZ."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.fields import FieldWriter, format_double, parse_double
from rtmu.protocol.payloads import Side, decode_payload, payload_type_for
from rtmu.protocol.payloads.camera import (
    Camera,
    CameraCommand,
    CameraData,
    CameraInfo,
    CameraList,
    CameraModeList,
    CameraModeUpdated,
    CameraUpdate,
    ClientArg,
    LegacyCameraInfo,
    Picture,
    PictureRequest,
    SetCameraAbs,
    SetCameraMode,
    SetCameraPct,
    SetCameraRel,
    VideoFrame,
    VideoRequest,
    VideoSize,
)

JPEG = b"\xff\xd8\xff\xe0\x00\x10JFIF\x00" + bytes(range(40)) + b"\xff\xd9"
text = st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=12)


def test_forwarded_frame_keeps_its_two_trailing_bytes() -> None:
    raw = b"\x40\x01\xf0\x00" + JPEG + b"\x05\xaa"  # as captured: 320x240, checksum junk after FF D9
    f = VideoFrame.decode(raw)
    assert (f.width, f.height) == (320, 240)
    assert f.jpeg == JPEG and f.trailing == b"\x05\xaa"
    assert f.encode() == raw
    assert f.to_fields()["trailing"] == "05aa"


def test_direct_frame_and_no_end_marker() -> None:
    f = VideoFrame.decode(b"\x02\x00\x01\x00" + JPEG)
    assert f.trailing == b"" and f.jpeg == JPEG
    odd = VideoFrame.decode(b"\x02\x00\x01\x00abc")
    assert odd.jpeg == b"abc" and odd.trailing == b""
    assert VideoFrame.decode(b"\x02\x00\x01\x00") == VideoFrame(2, 1, b"")


def test_frame_too_short_names_the_field() -> None:
    with pytest.raises(FieldUnderrun, match="height"):
        VideoFrame.decode(b"\x40\x01\xf0")
    with pytest.raises(FieldUnderrun, match="width"):
        VideoFrame.decode(b"")


@given(st.integers(0, 65535), st.integers(0, 65535), st.binary(max_size=100), st.binary(max_size=4))
def test_frame_round_trip(w: int, h: int, body: bytes, trailing: bytes) -> None:
    jpeg = b"\xff\xd8" + body + b"\xff\xd9"
    trailing = trailing.replace(b"\xff", b"\x00")  # junk after the marker cannot hold another marker
    f = VideoFrame(w, h, jpeg, trailing)
    assert VideoFrame.decode(f.encode()) == f


@given(st.binary(max_size=80))
def test_any_frame_bytes_re_encode_exactly(raw: bytes) -> None:
    raw = b"\x10\x00\x10\x00" + raw
    assert VideoFrame.decode(raw).encode() == raw


def test_picture_names_carry_the_camera() -> None:
    assert payload_type_for("getPictureCam1", Side.REPLY) is Picture
    assert payload_type_for("getPicture", Side.REPLY) is Picture
    assert payload_type_for("sendVideo", Side.REPLY) is VideoFrame
    p = decode_payload("getPictureCam1", Side.REPLY, b"\x02\x00\x01\x00" + JPEG)
    assert isinstance(p, Picture) and p.jpeg == JPEG
    assert payload_type_for("getPictureCam2", Side.ARGS) is PictureRequest


def test_video_request_optional_quality() -> None:
    assert VideoRequest().encode() == b""
    assert VideoRequest.decode(b"") == VideoRequest(None)
    assert VideoRequest(90).encode() == b"\x5a"
    assert PictureRequest.decode(b"\x32") == PictureRequest(50)


def test_video_size_with_forwarded_junk() -> None:
    assert VideoSize.decode(b"\x40\x01\xf0\x00") == VideoSize(320, 240)
    raw = b"\x40\x01\xf0\x00\x12\x34"
    assert VideoSize.decode(raw) == VideoSize(320, 240, b"\x12\x34")
    assert VideoSize.decode(raw).encode() == raw
    with pytest.raises(FieldUnderrun, match="height"):
        VideoSize.decode(b"\x40\x01")


CAM1_COMMANDS = (
    ("cameraModeUpdated", "cameraModeUpdatedCam1", -1),
    ("getCameraData", "getCameraDataCam1", 100),
    ("getCameraDataInt", "cameraUpdate", -1),
    ("getCameraInfo", "getCameraInfoCam1", -1),
    ("setCameraRel", "setCameraRelCam1", -1),
    ("getPicture", "getPictureCam1", -1),
)


def cam1() -> Camera:
    params = (
        ClientArg("Param group", "", 0, "L", children=(ClientArg("Pan speed", "deg/s", 1, "I", 50, 0, 100),)),
        ClientArg("Inverted", "mounted upside down", 2, "B", 0),
        ClientArg("Gain", "", 1, "D", 1.5, 0.0, 10.0),
        ClientArg("Label", "", 3, "S", "front"),
        ClientArg("", "", 0, "."),
    )
    commands = tuple(CameraCommand(*c) for c in CAM1_COMMANDS)
    return Camera("Cam1", "VCC4", "Camera", "", commands, params)


def test_camera_list_layout() -> None:
    cl = CameraList((cam1(),))
    raw = cl.encode()
    assert raw[:2] == b"\x01\x00"
    assert raw[2:].startswith(
        b"Cam1\0VCC4\0Camera\0\0\x06\x00cameraModeUpdated\0cameraModeUpdatedCam1\0\xff\xff\xff\xff"
    )
    assert b"getCameraData\0getCameraDataCam1\0\x64\x00\x00\x00" in raw
    # parameter block: name, description, priority, type, value(s)
    assert (
        b"Pan speed\0deg/s\0\x01I" + (50).to_bytes(4, "little") + bytes(4) + (100).to_bytes(4, "little")
        in raw
    )
    assert b"Gain\0\0\x01D1.5\x000\x0010\x00" in raw
    decoded = CameraList.decode(raw)
    assert decoded == cl
    assert decoded.cameras[0].data_name("getPicture") == "getPictureCam1"
    assert decoded.cameras[0].data_name("nope") is None


def test_camera_list_display_hint_variant() -> None:
    w = FieldWriter().byte2(1).string("C").string("T").string("D").string("").byte2(0).byte2(1)
    w.string("speed").string("").byte(1).byte(ord("i")).byte4(5).byte4(0).byte4(9).string("SpinBox")
    cl = CameraList.decode(w.bytes())
    arg = cl.cameras[0].params[0]
    assert arg.kind == "i" and arg.value == 5 and arg.display_hint == "SpinBox"
    assert cl.encode() == w.bytes()


def test_camera_list_hostile() -> None:
    with pytest.raises(PayloadError, match="camera count"):
        CameraList.decode(b"\xff\x7f")
    w = FieldWriter().byte2(1).string("C").string("T").string("D").string("").byte2(0).byte2(1)
    unknown = w.bytes() + b"p\0\0\x00Z"
    with pytest.raises(PayloadError, match="unknown parameter type"):
        CameraList.decode(unknown)
    # a list nested deeper than anyone needs
    nested = FieldWriter()
    for _ in range(40):
        nested.string("l").string("").byte(0).byte(ord("L")).byte4(1)
    with pytest.raises(PayloadError, match="nested"):
        CameraList.decode(w.bytes() + nested.bytes())
    with pytest.raises(PayloadError, match="list child count"):
        CameraList.decode(w.bytes() + b"l\0\0\x00L\xff\xff\xff\x7f")


wire_double = st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: parse_double(format_double(v)))
int4 = st.integers(-(2**31), 2**31 - 1)
leaf_args = st.one_of(
    st.builds(ClientArg, text, text, st.integers(-128, 127), st.just("B"), st.integers(-128, 127)),
    st.builds(ClientArg, text, text, st.integers(-128, 127), st.just("I"), int4, int4, int4),
    st.builds(
        ClientArg, text, text, st.integers(-128, 127), st.just("D"), wire_double, wire_double, wire_double
    ),
    st.builds(ClientArg, text, text, st.integers(-128, 127), st.just("S"), text),
    st.builds(ClientArg, text, text, st.integers(-128, 127), st.just(".")),
)
client_args = st.recursive(
    leaf_args,
    lambda kids: st.builds(
        ClientArg,
        text,
        text,
        st.integers(-128, 127),
        st.just("L"),
        children=st.lists(kids, max_size=3).map(tuple),
    ),
    max_leaves=8,
)
cameras = st.builds(
    Camera,
    text,
    text,
    text,
    text,
    st.lists(st.builds(CameraCommand, text, text, int4), max_size=4).map(tuple),
    st.lists(client_args, max_size=4).map(tuple),
)


@given(st.lists(cameras, max_size=3))
def test_camera_list_round_trip(cams: list[Camera]) -> None:
    cl = CameraList(tuple(cams))
    raw = cl.encode()
    assert CameraList.decode(raw) == cl
    assert CameraList.decode(raw).encode() == raw


def test_camera_info_captured() -> None:
    raw = bytes.fromhex("B8D9 4826 48F4 6022 0000 1027 01")
    info = CameraInfo.decode(raw)
    assert info == CameraInfo(-98.0, 98.0, -30.0, 88.0, 0.0, 100.0, True)
    assert info.encode() == raw
    assert payload_type_for("getCameraInfoCam1", Side.REPLY) is CameraInfo


def test_legacy_camera_info_captured() -> None:
    raw = bytes.fromhex("9EFF 6200 E2FF 5800 0000 6400 01")
    info = LegacyCameraInfo.decode(raw)
    assert info == LegacyCameraInfo(-98, 98, -30, 88, 0, 100, True)
    assert info.encode() == raw
    assert payload_type_for("cameraInfo", Side.REPLY) is LegacyCameraInfo
    assert CameraUpdate.decode(CameraUpdate(10, -5, 50).encode()) == CameraUpdate(10, -5, 50)


@given(st.lists(st.integers(-(2**15), 2**15 - 1), min_size=3, max_size=3))
def test_camera_data_hundredths_round_trip(values: list[int]) -> None:
    raw = b"".join(v.to_bytes(2, "little", signed=True) for v in values)
    d = CameraData.decode(raw)
    assert d.pan == values[0] / 100
    assert d.encode() == raw


def test_set_camera_optional_zoom() -> None:
    assert SetCameraAbs(10.5, -3.25, 50).encode() == bytes.fromhex("1A04 BBFE 8813")
    assert SetCameraAbs.decode(bytes.fromhex("1A04 BBFE")) == SetCameraAbs(10.5, -3.25, None)
    assert SetCameraRel(1, 2).encode() == bytes.fromhex("6400 C800")
    assert payload_type_for("setCameraRelCam1", Side.ARGS) is SetCameraRel
    assert SetCameraPct.decode(SetCameraPct(-100, 50).encode()) == SetCameraPct(-100, 50)
    with pytest.raises(FieldUnderrun, match="tilt"):
        SetCameraAbs.decode(b"\x01\x00")


def test_camera_modes() -> None:
    raw = b"\x03\x00Position\0LookAtGoal\0LookAtPoint\0"
    assert CameraModeList.decode(raw) == CameraModeList(("Position", "LookAtGoal", "LookAtPoint"))
    assert CameraModeList.decode(raw).encode() == raw
    with pytest.raises(PayloadError, match="mode count"):
        CameraModeList.decode(b"\x09\x00a\0")
    look = SetCameraMode("LookAtPoint", (1000, -2000))
    assert SetCameraMode.decode(look.encode()) == look
    assert SetCameraMode.decode(b"Position\0") == SetCameraMode("Position")
    assert CameraModeUpdated.decode(b"") == CameraModeUpdated(None)  # before any change
    assert CameraModeUpdated(None).encode() == b""
    assert CameraModeUpdated.decode(look.encode()) == CameraModeUpdated("LookAtPoint", (1000, -2000))
    assert payload_type_for("cameraModeUpdatedCam1", Side.REPLY) is CameraModeUpdated


def test_registered() -> None:
    assert payload_type_for("getCameraList", Side.REPLY) is CameraList
    assert payload_type_for("videoSize", Side.REPLY) is VideoSize
    assert payload_type_for("sendVideo", Side.ARGS) is VideoRequest
