"""The window's session records by default: one MCAP file with the raw bytes and Foxglove channels.

A robot session built through the fleet (as the window builds it) connects to the
simulator, loads the map, takes pictures, drives and stops; the file is then read
with the ``mcap`` package and held against what the session really published.
"""

from __future__ import annotations

import time
from pathlib import Path

from rtmu.capture.recorded import CONNECTION_TOPIC, RAW_TOPICS
from rtmu.recorder import topics
from rtmu.values.intents import RequestPicture
from rtmu.values.state import CameraChanged, MapPhase, RobotChanged, StateChange

from .mcapread import read, summary_counts
from .poses import _position
from .simsession import hold, recorded_session

SCHEMAS = {
    topics.POSE: ("foxglove.PoseInFrame", "protobuf"),
    topics.TF: ("foxglove.FrameTransform", "protobuf"),
    topics.SONAR: ("foxglove.PointCloud", "protobuf"),
    topics.MAP: ("foxglove.SceneUpdate", "protobuf"),
    topics.MAP_POINTS: ("foxglove.PointCloud", "protobuf"),
    topics.CAMERA: ("foxglove.CompressedImage", "protobuf"),
    RAW_TOPICS["s2c"]: ("rtmu.ArNetworkingBytes", "arnetworking"),
    RAW_TOPICS["c2s"]: ("rtmu.ArNetworkingBytes", "arnetworking"),
}
JSON_TOPICS = (
    topics.STATUS,
    topics.MAP_STATE,
    topics.CONNECTION,
    topics.LINK_HEALTH,
    topics.INTENTS,
    topics.LEASE,
    topics.STOPS,
    CONNECTION_TOPIC,
)


def run_session(tmp_path: Path, spy: list[StateChange]) -> Path:
    with recorded_session(tmp_path, spy=spy) as (session, ui, _view, _sim):
        ui.wait_for(lambda: session.state.map.value.state is MapPhase.READY, timeout=15)
        for _ in range(3):
            before = session.state.camera.value
            session.controller.ask(RequestPicture())
            ui.wait_for(lambda b=before: session.state.camera.value is not b, timeout=5)
        hold(ui, session, "forward", 1.0)
        time.sleep(0.3)  # the release's stop goes out, the robot comes to rest
        ui.drain()
        session.controller.stop()
        ui.drain()
        ui.wait_for(lambda: not session.state.robot.value.moving, timeout=3)
        recorder = session.recorder
        assert recorder is not None
    files = list(tmp_path.glob("*.mcap"))
    assert len(files) == 1, files
    assert recorder.recordings[0].dropped == 0
    return files[0]


def poses(changes: list[StateChange]) -> int:
    """How many times the published robot changed position (the session's placeholder before the first
    status not counted): what the recorded poses must count, repeats of a resting robot aside."""
    count, last = 0, None
    for change in changes:
        if isinstance(change, RobotChanged) and change.value.numbers_at is not None:
            pose = (change.value.x, change.value.y, change.value.th)
            if pose != last:
                count, last = count + 1, pose
    return count


def changes_of_position(messages: list[bytes]) -> int:
    count, last = 0, None
    for data in messages:
        position = _position(data)
        if position != last:
            count, last = count + 1, position
    return count


def test_a_session_is_one_mcap_file_with_every_channel_and_schema(tmp_path: Path) -> None:
    spy: list[StateChange] = []
    path = run_session(tmp_path, spy)
    assert path.name.endswith("_127.0.0.1_" + path.name.split("_")[-1])  # <UTC>_<host>_<port>.mcap
    got = read(path)
    assert got.cut_short is None
    schemas = got.schemas()
    for topic, expected in SCHEMAS.items():
        assert schemas.get(topic) == expected, topic
    for topic in JSON_TOPICS:
        assert schemas.get(topic, ("", ""))[1] == "json", topic
    assert summary_counts(path) == dict(got.counts()), "the file was finished with its summary"

    # Counts match what the session published.
    recorded = [m.data for m in got.topic(topics.POSE)]
    assert changes_of_position(recorded) == poses(spy) and len(recorded) == len(got.topic(topics.TF))
    assert poses(spy) > 3, "the robot drove"
    pictures = [c.value for c in spy if isinstance(c, CameraChanged) and c.value is not None]
    images = got.topic(topics.CAMERA)
    assert len(images) == len(pictures) == 3
    assert all(p.jpeg in m.data for p, m in zip(pictures, images, strict=True)), "the JPEG bytes as sent"
    assert len(got.topic(topics.MAP)) == 1 and len(got.topic(topics.MAP_POINTS)) == 1, "once per map"
    sonar = {c.value.sonar for c in spy if isinstance(c, RobotChanged) and c.value.sonar}
    assert len(got.topic(topics.SONAR)) >= len(sonar) > 0

    status = [s for s in got.records(topics.STATUS) if s["mode"]]  # the last one is the reset at disconnect
    assert status[-1]["battery"]["volts"] > 0 and status[-1]["battery"]["state"] == "ok"
    assert {"low", "shutdown"} <= set(status[-1]["battery"])
    assert any(s["moving"] for s in status) and not status[-1]["moving"]
    phases = [r["phase"] for r in got.records(topics.CONNECTION)]
    assert phases[-1] == "disconnected" and "connected" in phases


def test_why_did_the_robot_stop_is_answered_by_the_file(tmp_path: Path) -> None:
    path = run_session(tmp_path, [])
    got = read(path)
    lease = got.records(topics.LEASE)
    assert lease[0]["event"] == "grant" and lease[0]["ratios"]["trans"] > 0
    assert {"event": "end", "reason": "released"}.items() <= lease[-1].items()
    stops = got.records(topics.STOPS)
    reasons = [s["reason"] for s in stops]
    assert "lease released" in reasons, reasons
    assert "stop key" in reasons and reasons[-1] == "disconnect", reasons
    assert all(s["by"] == "client" and s["sent"] for s in stops)
    # …and the stop really left: the raw channel holds a stop request after the release.
    release_at = next(m.log_time for m in got.topic(topics.STOPS) if m.json()["reason"] == "lease released")
    assert any(m.log_time >= release_at for m in got.topic(RAW_TOPICS["c2s"]))


def test_operator_intents_are_recorded_without_the_password(tmp_path: Path) -> None:
    path = run_session(tmp_path, [])
    got = read(path)
    intents = got.records(topics.INTENTS)
    names = [i["intent"] for i in intents]
    assert names.count("RequestPicture") == 3, names
    assert "Stop" in names
    connect = intents[names.index("connect")]
    assert connect["host"] == "127.0.0.1" and "port" in connect and "password" not in connect
