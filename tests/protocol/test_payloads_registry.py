"""Every registered payload type: lookup rules, hostile bytes, truncation, JSON output."""

from __future__ import annotations

import contextlib
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.payloads import (
    NameMatch,
    Payload,
    Side,
    central,
    commands,
    decode_payload,
    drawings,
    drive,
    ld,
    navigation,
    payload_type_for,
    popup,
    registered,
    robot,
    sensors,
    server,
    strings,
)
from rtmu.protocol.payloads import camera as cam
from rtmu.protocol.payloads import config as cfg
from rtmu.protocol.payloads import configcare as care
from rtmu.protocol.payloads import files as fs
from rtmu.protocol.payloads import map as mp
from rtmu.protocol.payloads import mapchange as mc
from rtmu.protocol.payloads import mapping as scan

SAMPLES: list[Payload] = [
    robot.UpdateNumbers(12.3, -1000, 2000, -45, 300, -20, 0, 31),
    robot.UpdateStrings("Driving", "Drive", "Driving"),
    robot.Update("Stopped", "Stop", robot.UpdateNumbers(13.0, 0, 0, 0, 0, 0, 0)),
    robot.BatteryInfo(11.5, 11.0, False),
    robot.PhysicalInfo("Pioneer", "p3dx", 381, 210, 255, False),
    robot.ActivityTimeInfo(-1),
    robot.ModeInfo("ratioDrive", False, False),
    robot.ModeDataList((robot.ModeData("stop", "stop"),)),
    robot.ModeBusyChanged(True),
    drive.RatioDrive(50, 0, 100, 0),
    drive.SetSafeDrive(True),
    drive.SafeDrive(True),
    drive.MoveDist(300),
    drive.TurnByAngle(90),
    drive.TurnToHeading(-90),
    mp.MapName("office.map"),
    mp.MapId("", "office.map", bytes(range(16)), 2291, 1795237141),
    mp.Goals(("Kitchen", "Door")),
    mp.MapUpdated(),
    mp.GoalsUpdated(),
    mp.MapTextPacket("2D-Map"),
    mp.MapBinaryPacket.point_block(np.array([[1, 2], [3, 4]])),
    mp.MapWithMaxCategoryPacket.segment_block(np.array([[1, 2, 3, 4]])),
    mp.MapMultiScansPacket.text_line("DATA"),
    mp.MapWithMaxCategoryRequest("2D-Map-Ex"),
    sensors.SensorList(("sonar", "sim_lms2xx_1")),
    sensors.SensorCurrentRequest(("sonar",)),
    sensors.SensorCumulativeRequest(("sonar",)),
    sensors.SensorReadings("sonar", ((1, 2), (3, 4))),
    sensors.SensorCumulativeReadings("sonar", ((1, 2),)),
    sensors.RangeDeviceReadings(((1, 2),)),
    sensors.RangeDeviceCumulative(((5, 6),)),
    drawings.DrawingListPacket(
        drawings.Drawing("sonarCurrent", "polyArrows", 0x33CCFF, 80, 75, 5000, 255, "On")
    ),
    drawings.DrawingList((drawings.Drawing("sonarCurrent", "polyArrows", 1, 2, 3, 4, 5),)),
    cam.VideoFrame(320, 240, b"\xff\xd8jpeg\xff\xd9", b"\x05\xaa"),
    cam.Picture(2, 1, b"\xff\xd8\xff\xd9"),
    cam.VideoRequest(90),
    cam.PictureRequest(50),
    cam.VideoSize(320, 240),
    cam.CameraList(
        (
            cam.Camera(
                "Cam1",
                "VCC4",
                "Camera",
                "",
                (cam.CameraCommand("getPicture", "getPictureCam1", -1),),
                (cam.ClientArg("Speed", "", 1, "D", 1.5, 0.0, 3.0),),
            ),
        )
    ),
    cam.CameraListUpdated(),
    cam.CameraData(10.5, -3.0, 50.0),
    cam.CameraInfo(-98, 98, -30, 88, 0, 100, True),
    cam.SetCameraAbs(10, 20, 30),
    cam.SetCameraRel(1, -1),
    cam.SetCameraPct(50, -50),
    cam.CameraModeList(("Position", "LookAtPoint")),
    cam.SetCameraMode("LookAtPoint", (100, 200)),
    cam.CameraModeUpdated("Position"),
    cam.CameraUpdate(10, -5, 50),
    cam.LegacyCameraInfo(-98, 98, -30, 88, 0, 100, True),
    strings.StringsInfo((strings.StringItem("Answer", 10),)),
    strings.Strings(("42",)),
    commands.CommandList((commands.CommandEntry("safeRatioDrivingEnable", "Enables"),)),
    commands.StringCommandList((commands.CommandEntry("MicroControllerCommand", "Sends"),)),
    popup.PopupCreate(7, "dock", "Docking", "Dock now?", popup.PopupType.QUESTION, ("Yes", "No", ""), 0, 1),
    popup.PopupClose(7, "Yes"),
    popup.PopupClicked(7, 0),
    popup.PopupListEnd(),
    server.IdleProcessingPending(False),
    server.RequestClientRestart(1, "config"),
    server.HeartbeatInterval(500),
    server.HeartbeatTcp(),
    server.HeartbeatUdp(),
    server.SelfIdentifier("rtmu"),
    ld.DockInfo(2, True, 300),
    ld.DockInfoChanged(1),
    ld.Routes(("Loop", "Night patrol")),
    ld.Patrol("Loop"),
    ld.GotoRouteGoal("Kitchen"),
    ld.Say("Hello"),
    ld.DataStoreValue("87"),
    navigation.GotoGoal("Kitchen"),
    navigation.GotoPose(1500, -2000, 90),
    navigation.Home(),
    navigation.TourGoals(),
    navigation.Dock(),
    navigation.LocalizeToPose(1000, 2000, -45, 200, 10),
    navigation.LocState(0, 870),
    navigation.PlannedPath(((0, 0), (1500, -200))),
    navigation.PathPlannerStatus("Moving to goal"),
    navigation.GoalName("Kitchen"),
    central.ClientList((central.CentralEntry("", 7273, "robot1", "", "10.0.0.5"),)),
    central.ClientAdded(central.CentralEntry("", 7274, "robot2", "", "10.0.0.6")),
    central.ClientRemoved(central.CentralEntry("central.lan", 7274, "robot2", "", "10.0.0.6")),
    central.SwitchRequest("robot1"),
    central.SwitchAccepted(),
    central.CentralServerHeartbeat(),
    central.CentralHeartbeat(),
    cfg.ConfigSectionPacket(
        "Teleop", "", (cfg.ConfigParam("Timeout", cfg.ParamType.DOUBLE, 2.0, "s", 1, 0.0, 60.0, 1),), "", 1
    ),
    cfg.ConfigSectionPacketV3("Teleop", "", (cfg.ConfigParam("On", cfg.ParamType.BOOL, True),)),
    cfg.ConfigSectionPacketV2("Teleop", "", (cfg.ConfigParam("N", cfg.ParamType.INT, 1, "", 0, 0, 2),)),
    cfg.ConfigSectionPacketV1("Teleop", "", (cfg.ConfigParam("S", cfg.ParamType.STRING, "x"),)),
    cfg.ConfigRequest(4, 3),
    cfg.SetConfig((("Section", "Teleop"), ("Timeout", "1"))),
    cfg.SetConfigReply("Teleop/Timeout: 99 is above the maximum of 60"),
    cfg.ConfigUpdated(),
    cfg.ConfigSectionFlags((("Teleop", ""),)),
    cfg.LastEditablePriority(3),
    cfg.ConfigCausingRestart(1),
    fs.DirListingRequest("maps"),
    fs.DirListingMultipleRequest(""),
    fs.DirListing(0, "", (fs.DirEntry(1, "maps", 1, 2, 4096), fs.DirEntry(2, "a.map", 3, 4, 120))),
    fs.DirListingPacket(0, "maps", (fs.DirEntry(2, "office.map", 5, 6, 2291),)),
    fs.GetFileRequest("maps/office.map"),
    fs.GetFileWithTimestampRequest("office.map"),
    fs.FileChunk(0, "office.map", b"2D-Map\n"),
    fs.TimestampedFileChunk(0, "office.map", b"", 1795237141),
    fs.PutFileRequest(1, "a.map", b"data"),
    fs.PutFileInterleavedRequest(0, "a.map"),
    fs.PutFileWithTimestampRequest(0, "a.map", mtime=1795237141),
    fs.PutFileWithTimestampInterleavedRequest(2, "a.map"),
    fs.PutFileReply(0, "a.map"),
    fs.PutFileInterleavedReply(10, "a.map"),
    fs.PutFileWithTimestampReply(7, "a.map"),
    fs.PutFileWithTimestampInterleavedReply(11, "a.map"),
    fs.DeleteFileRequest("a.map"),
    fs.DeleteFileReply(2, "a.map"),
    fs.DefaultUploadDownloadDir("maps"),
    scan.MappingStart("office"),
    scan.MappingStartReply(0),
    scan.MappingEndReply(1),
    scan.MappingStatus("office"),
    scan.MappingStatusBroadcast("office.2d"),
    scan.MappingLoopStart("1"),
    scan.MappingLoopEnd("1"),
    care.ConfigDefaultsRequest("Teleop"),
    care.ConfigDefaults((("Section", "Teleop"), ("Timeout", "2"))),
    care.ConfigDefaultsUpdated(),
    care.SetConfigParam((("Section", "Teleop"), ("Timeout", "1"))),
    care.SetConfigParamReply("Teleop", "Teleop/Timeout: 99 is above the maximum of 60"),
    care.ReloadConfig(),
    care.CheckMap(),
    mc.MapChangePacket(
        mc.ChangeCommand.CONTINUE,
        mp.MapId("", "office.map", bytes(range(16)), 2291, 1795237141),
        mp.MapId("", "office.map", b"", 0, -1),
        mc.ChangeData.OBJECTS,
        mc.LineChange.ADDITIONS,
        "",
        -1,
        1,
        (mc.FileLineGroup(mc.FileLine(12, 'Cairn: Goal 1000 2000 0.000000 "" ICON "Kitchen"')),),
    ),
    mc.MapChangeReply(10),
    mc.MapChangesInProgress(True),
]
TYPES = sorted(registered().values(), key=lambda c: (c.DATA_NAME, c.SIDE.value))


def test_every_registered_type_has_a_sample() -> None:
    assert {type(s) for s in SAMPLES} == set(TYPES)


@pytest.mark.parametrize("sample", SAMPLES, ids=lambda s: type(s).__name__)
def test_sample_round_trips_and_prints_as_json(sample: Payload) -> None:
    raw = sample.encode()
    assert type(sample).decode(raw) == sample
    assert type(sample).decode(raw).encode() == raw
    json.dumps(sample.to_fields())


@pytest.mark.parametrize("sample", SAMPLES, ids=lambda s: type(s).__name__)
def test_every_truncation_is_a_protocol_error_or_a_shorter_valid_payload(sample: Payload) -> None:
    raw = sample.encode()
    for cut in range(len(raw)):
        with contextlib.suppress(ProtocolError):
            type(sample).decode(raw[:cut])


@pytest.mark.parametrize("cls", TYPES, ids=lambda c: c.__name__)
@settings(max_examples=150, deadline=None)
@given(raw=st.binary(max_size=64))
def test_random_bytes_never_raise_anything_but_protocol_errors(cls: type[Payload], raw: bytes) -> None:
    try:
        decoded = cls.decode(raw)
    except ProtocolError:
        return
    json.dumps(decoded.to_fields())


def test_lookup_rules() -> None:
    assert payload_type_for("getPictureCam1", Side.REPLY) is cam.Picture
    assert payload_type_for("setCameraAbsPTZ_2", Side.ARGS) is cam.SetCameraAbs
    assert payload_type_for("getCameraModeListCam1", Side.REPLY) is cam.CameraModeList
    assert payload_type_for("urg_1Current", Side.REPLY) is sensors.RangeDeviceReadings
    assert payload_type_for("cameraInfo", Side.REPLY) is cam.LegacyCameraInfo  # exact beats families
    assert payload_type_for("getPictureCam1", Side.ARGS) is cam.PictureRequest
    assert payload_type_for("noSuchData", Side.REPLY) is None
    assert decode_payload("noSuchData", Side.REPLY, b"") is None
    assert cam.Picture.NAME_MATCH is NameMatch.PREFIX
    assert sensors.RangeDeviceReadings.NAME_MATCH is NameMatch.SUFFIX


def test_hostile_counts_are_refused_without_allocating() -> None:
    big = b"\xff\xff\xff\x7f"
    for cls, raw in [
        (robot.ModeDataList, big),
        (sensors.RangeDeviceReadings, big),
        (drawings.DrawingList, big),
        (mp.MapId, b"\0\0" + big),
        (sensors.SensorReadings, b"\xff\x7fsonar\0"),
        (strings.StringsInfo, b"\xff\xff"),
        (cam.CameraList, b"\xff\x7f"),
        (commands.CommandList, b"\xff\x7f"),
        (navigation.PlannedPath, b"\xff\x7f"),
    ]:
        with pytest.raises(ProtocolError):
            cls.decode(raw)
