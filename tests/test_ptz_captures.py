"""The camera head and the server strings against real ARIA sessions (``tests/data/captures``).

serverDemo's data list (clientCommandLister) names a VC-C4 head ``Cam1``: ``client.ptz`` finds it
movable from the names ARIA's camera handler registers, and the simulator registers the same
names. ARIA's clientStringInfoExample session (strings.pcap) goes through the strings feed as the
details table would show it.
"""

from __future__ import annotations

from rtmu.client.call_values import Packet
from rtmu.client.detached import DetachedContext
from rtmu.client.ptz import pick_camera
from rtmu.client.server_strings import StringsFeed
from rtmu.protocol.payloads.camera import Camera, CameraCommand, CameraInfo
from rtmu.protocol.payloads.strings import StringsInfo
from rtmu.sim.camera_data import CAMERA_COMMANDS
from test_golden_captures import decoded

# getCameraList's command table for Cam1 as serverDemo sends it (protocol §4.6), without video.
CAPTURED_COMMANDS = {
    "cameraModeUpdated": "cameraModeUpdatedCam1",
    "getCameraData": "getCameraDataCam1",
    "getCameraDataInt": "cameraUpdate",
    "getCameraInfo": "getCameraInfoCam1",
    "getCameraInfoInt": "cameraInfo",
    "getCameraModeList": "getCameraModeListCam1",
    "resetCamera": "resetCameraCam1",
    "setCameraAbs": "setCameraAbsCam1",
    "setCameraAbsInt": "cameraAbs",
    "setCameraMode": "setCameraModeCam1",
    "setCameraPct": "setCameraPctCam1",
    "setCameraPctInt": "cameraPct",
    "setCameraRel": "setCameraRelCam1",
    "setCameraRelInt": "camera",
}


def test_serverdemo_lists_every_data_name_of_its_camera_head_and_ptz_finds_it_movable():
    d = decoded("clientCommandLister-serverDemoMap.pcap")
    (session,) = d.decoder.sessions
    offered = session.datalist
    assert "getCameraList" in offered
    for name in CAPTURED_COMMANDS.values():
        assert name in offered, name
    cam = Camera(
        "Cam1", "VCC4", "Camera", "", tuple(CameraCommand(c, n) for c, n in CAPTURED_COMMANDS.items())
    )
    assert pick_camera((cam,), offered.__contains__) is cam
    data = offered.entry("getCameraDataCam1")
    assert data is not None and data.command_group == "CameraInfo"
    rel = offered.entry("setCameraRelCam1")
    assert rel is not None and rel.command_group == "CameraControl"
    # A camera whose set commands the server does not list is not a head we can move.
    ghost = Camera("Cam2", "VCC4", "", "", (CameraCommand("setCameraRel", "setCameraRelCam2"),))
    assert pick_camera((ghost,), offered.__contains__) is None


def test_the_simulator_registers_serverdemos_camera_names():
    sim = {c: n for c, n, _ in CAMERA_COMMANDS if c not in ("getPicture", "getVideo")}
    assert sim == CAPTURED_COMMANDS
    intervals = {c: i for c, _, i in CAMERA_COMMANDS}
    assert intervals["getCameraData"] == 100 and {
        i for c, i in intervals.items() if c != "getCameraData"
    } == {-1}


def test_captured_vcc4_limits_decode_to_the_simulators_limits():
    info = CameraInfo.decode(bytes.fromhex("B8D9 4826 48F4 6022 0000 1027 01"))
    assert (info.min_pan, info.max_pan, info.min_tilt, info.max_tilt) == (-98, 98, -30, 88)
    from rtmu.sim.camera import PAN_RANGE, TILT_RANGE, ZOOM_RANGE

    assert (info.min_pan, info.max_pan) == PAN_RANGE and (info.min_tilt, info.max_tilt) == TILT_RANGE
    assert ZOOM_RANGE == (info.min_zoom, info.max_zoom) == (0, 100)


def test_captured_strings_go_through_the_feed_as_the_table_shows_them():
    d = decoded("strings.pcap")
    (info_packet,) = d.data("getStringsInfo")
    values = d.data("getStrings")
    ctx = DetachedContext()
    feed = StringsFeed(ctx)
    feed._set_info(StringsInfo.decode(info_packet.payload))
    feed.watch(True)
    for packet in values:
        feed._on_values(Packet("getStrings", packet.payload, 0.0))
        ((label, value),) = ctx.robot.server_strings
        assert label == "Motor Packet Count" and value.isdigit()
        assert ctx.robot.server_strings_more == 0
    assert ctx.robot.wifi_quality is None  # serverDemo publishes no wireless item
