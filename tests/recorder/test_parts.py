"""The recorder's parts one by one: names and age, settings, intents, the writer's queue, conversions."""

from __future__ import annotations

import os
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from rtmu.base.notices import Kind
from rtmu.capture import CaptureError, open_capture
from rtmu.client.lease import DriveLease, DriveRatios, EndReason, LeaseEvent
from rtmu.fleet.sessions import recorder_for
from rtmu.recorder import Limits, Recorder, RecorderConfig, Recording, topics
from rtmu.recorder.convert import REPEAT_EVERY, REPEAT_NS, Converter, other_topic, status_record
from rtmu.recorder.files import file_name, prune, recordings_dir
from rtmu.recorder.items import Event
from rtmu.recorder.mcapfile import McapFile
from rtmu.settings.store import RecordingSettings, SettingsError, format_settings, parse_settings
from rtmu.values.state import ConnectionChanged, ConnectionState, Phase, RobotChanged, RobotState
from rtmu.values.target import Target

from .mcapread import read


def test_recordings_live_under_xdg_data_home_named_by_utc_time_and_robot() -> None:
    assert recordings_dir({"XDG_DATA_HOME": "/data"}) == Path("/data/rtmu/recordings")
    assert recordings_dir({"XDG_DATA_HOME": "relative"}) == Path.home() / ".local/share/rtmu/recordings"
    when = 1_764_044_100.0  # 2025-11-25 04:15:00 UTC
    assert file_name("lab-robot:7272", when) == "20251125T041500Z_lab-robot-7272.mcap"
    assert file_name("../../etc/passwd\x1b[2J", when) == "20251125T041500Z_etc-passwd-2J.mcap"


def test_old_recordings_are_pruned_by_age_and_nothing_else(tmp_path: Path) -> None:
    now = time.time()
    old, new, other = tmp_path / "old.mcap", tmp_path / "new.mcap", tmp_path / "notes.txt"
    for path in (old, new, other):
        path.write_bytes(b"x")
    os.utime(old, (now - 40 * 86400, now - 40 * 86400))
    os.utime(other, (now - 40 * 86400, now - 40 * 86400))
    assert prune(tmp_path, 0) == []
    assert prune(tmp_path, 30, now) == [old]
    assert not old.exists() and new.exists() and other.exists()


def test_recording_settings_have_defaults_an_off_switch_and_bounds() -> None:
    default = parse_settings("version = 1\n").recording
    assert (
        default == RecordingSettings()
        and default.enabled
        and default.max_file_mb > 0
        and default.keep_days > 0
    )
    text = (
        'version = 1\n[recording]\nenabled = false\nmax_file_mb = 50\nkeep_days = 7\ndirectory = "/srv/rec"\n'
    )
    parsed = parse_settings(text)
    assert parsed.recording == RecordingSettings(
        enabled=False, directory="/srv/rec", max_file_mb=50, keep_days=7
    )
    assert parse_settings(format_settings(parsed)).recording == parsed.recording
    assert "[recording]" not in format_settings(parse_settings("version = 1\n"))
    for bad in ("max_file_mb = 0", "keep_days = -1", 'directory = "rel"', "enabled = 1", "colour = 1"):
        with pytest.raises(SettingsError):
            parse_settings(f"version = 1\n[recording]\n{bad}\n")


class Runner:
    def __init__(self) -> None:
        self.calls: list[tuple[object, ...]] = []
        self.on_notice = None

    def connect(self, target: Target) -> str:
        self.calls.append(("connect", target.host, target.port, target.user, target.password, target.profile))
        return "future"

    def command(self, name: str, *args: object) -> None:
        self.calls.append(("command", name, *args))

    def ui_heartbeat(self) -> None:
        self.calls.append(("beat",))


def test_the_lease_reports_grants_changes_and_ends_with_their_reason() -> None:
    lease = DriveLease()
    events: list[LeaseEvent] = []
    lease.on_event = events.append
    forward = DriveRatios(50.0, 0.0, 60.0)
    generation = lease.grant(forward)
    lease.change(DriveRatios(50.0, 20.0, 60.0))
    lease.renew()
    lease.end(EndReason.LAPSED)
    lease.end(EndReason.STOPPED)  # already ended: nothing new happened
    assert [(e.event, e.generation, e.reason) for e in events] == [
        ("grant", generation, None),
        ("change", generation, None),
        ("end", generation, EndReason.LAPSED),
    ]


def test_status_names_the_battery_unit_the_robot_reports() -> None:
    soc = status_record(RobotState(battery_v=41.0, battery_low=20.0, battery_is_soc=True, mode="Drive"))
    assert soc["battery"] == {"state": "ok", "low": 20.0, "shutdown": None, "state_of_charge_pct": 41.0}
    volts = status_record(RobotState(battery_v=11.0, battery_low=11.5))
    assert volts["battery"]["volts"] == 11.0 and volts["battery"]["state"] == "low"
    unknown = status_record(RobotState(battery_v=None, battery_is_soc=False))["battery"]
    assert "volts" not in unknown and "state_of_charge_pct" not in unknown and unknown["state"] == "unknown"


def test_unchanged_parts_are_not_written_again() -> None:
    convert = Converter()
    still = RobotState(x=1000.0, y=2000.0, th=90.0, status="Stopped", numbers_at=1.0, strings_at=1.0)
    first = [t for t, _ in convert.change(RobotChanged(still), 1)]
    assert first == [topics.POSE, topics.TF, topics.STATUS]
    assert convert.change(RobotChanged(still), 2) == []
    moved = replace(still, x=1001.0)
    assert [t for t, _ in convert.change(RobotChanged(moved), 3)] == [topics.POSE, topics.TF]


def test_nothing_of_the_robot_is_written_before_the_server_described_it() -> None:
    """The session's starting RobotState is a placeholder: no pose at (0, 0), no empty status."""
    convert = Converter()
    assert convert.change(RobotChanged(RobotState()), 1) == []
    assert convert.repeat(REPEAT_NS * 3) == []
    numbers = RobotState(x=5.0, numbers_at=2.0)
    assert [t for t, _ in convert.change(RobotChanged(numbers), 2)] == [topics.POSE, topics.TF]
    words = replace(numbers, status="Stopped", mode="Stop", strings_at=2.1)  # its words, 100 ms later
    status = convert.change(RobotChanged(words), 3)
    assert [t for t, _ in status] == [topics.STATUS] and status[0][1]["status"] == "Stopped"
    mute = Converter()  # a server that sends no status words: its numbers are recorded after a while
    mute.change(RobotChanged(numbers), 10)
    assert [t for t, _ in mute.repeat(10 + REPEAT_NS)] == [topics.POSE, topics.TF, topics.STATUS]


def test_a_parked_robots_pose_and_status_are_repeated_so_every_second_holds_them() -> None:
    convert = Converter()
    parked = RobotState(x=1000.0, y=2000.0, th=90.0, status="Stopped", numbers_at=1.0, strings_at=1.0)
    convert.change(RobotChanged(parked), 0)
    assert convert.repeat(REPEAT_NS - 1) == [], "not yet"
    again = convert.repeat(REPEAT_NS)
    assert [t for t, _ in again] == [topics.POSE, topics.TF, topics.STATUS]
    assert again[2][1]["status"] == "Stopped"
    assert convert.repeat(REPEAT_NS + 1) == [], "just written"
    assert REPEAT_NS / 1e9 + REPEAT_EVERY < 1.0, "called this often, no second of the file lacks them"


def test_producers_never_wait_for_a_stuck_writer(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A writer stuck on a dead disk: submit stays a non-blocking put, the surplus is dropped and counted.

    Not timed (a loaded machine is no failure): the writer stays stuck until every submit has
    returned, so one submit that waited for it would never return while it is stuck."""
    stuck = threading.Event()
    real_log = McapFile.log

    def slow_log(self: McapFile, topic: str, message: object, at_ns: int) -> None:
        if topic == topics.NOTICES:
            stuck.wait(120)
        real_log(self, topic, message, at_ns)

    monkeypatch.setattr(McapFile, "log", slow_log)
    recording = Recording(tmp_path / "stuck.mcap", limits=Limits(queue_items=100)).start()
    submitted = threading.Event()

    def produce() -> None:
        for n in range(1000):
            recording.submit(Event(topics.NOTICES, {"n": n}, time.time_ns()))
        submitted.set()

    producer = threading.Thread(target=produce, daemon=True)
    producer.start()
    try:
        assert submitted.wait(60), "a submit waited for the stuck writer"
        assert not stuck.is_set()
        assert recording.dropped >= 1000 - 100 - 1
    finally:
        stuck.set()
        producer.join(10)
        recording.close()
    got = read(recording.path)
    assert got.records(topics.RECORDER)[-1] == {"event": "dropped", "items": recording.dropped}


def test_a_recording_that_cannot_make_its_file_says_so_once(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("not a directory")
    problems = []
    recording = Recording(tmp_path / "file" / "x.mcap", on_problem=problems.append).start()
    recording.close()
    assert [p.kind for p in problems] == [Kind.RECORDING]
    assert "could not be created" in problems[0].text
    assert not recording.submit(Event(topics.NOTICES, {}, 0))


def test_a_stopped_recording_is_not_restarted_by_every_reconnect(tmp_path: Path) -> None:
    """A disk that refused once is not asked again on each reconnect; a new connect tries again."""
    (tmp_path / "file").write_text("not a directory")
    problems: list[object] = []
    recorder = Recorder(RecorderConfig(tmp_path / "file"), problems.append)
    assert recorder._link_opened("robot", 7272) is not None
    first = recorder.recordings[0]
    first.close()
    assert first.stopped is not None and len(problems) == 1
    assert recorder._link_opened("robot", 7272) is None, "a reconnect to the same robot"
    assert len(recorder.recordings) == 1 and len(problems) == 1
    recorder.published(ConnectionChanged(ConnectionState(phase=Phase.DISCONNECTED)))
    assert recorder._link_opened("robot", 7272) is not None, "the operator connects again"
    recorder.close()
    assert len(recorder.recordings) == 2 and len(problems) == 2


def test_decode_of_a_damaged_recording_names_the_damage(tmp_path: Path) -> None:
    good = tmp_path / "good.mcap"
    file = McapFile(good, {})
    file.log(topics.NOTICES, {"n": 1}, 1)
    file.close()
    data = good.read_bytes()
    for name, damaged in {
        "cut.mcap": data[: len(data) // 2],
        "noise.mcap": data[:8] + bytes(range(256)) * 8,
        "lying.mcap": data[:8] + b"\x06" + (2**62).to_bytes(8, "little") + b"\x00" * 64,
    }.items():
        path = tmp_path / name
        path.write_bytes(damaged)
        source = open_capture(path)
        with pytest.raises(CaptureError, match="not a readable MCAP recording"):
            list(source.events())


def test_the_window_records_by_default_and_the_off_switch_turns_it_off() -> None:
    recorder = recorder_for(RecordingSettings())
    assert recorder is not None and recorder.config.directory == recordings_dir()
    assert recorder.config.max_bytes == RecordingSettings().max_file_mb * 1_000_000
    assert recorder_for(RecordingSettings(enabled=False)) is None
    assert recorder_for(None) is None, "tests and scripts that build a session record nothing"
    custom = recorder_for(RecordingSettings(directory="/srv/rec", keep_days=3))
    assert custom is not None and custom.config.directory == Path("/srv/rec") and custom.config.keep_days == 3


def test_every_part_the_session_publishes_has_a_topic_of_its_own() -> None:
    """Parts without a Foxglove schema (navigation, popups, parts added later) each get a JSON topic."""
    import typing

    from rtmu.values import state

    own = {
        state.RobotChanged,
        state.MapChanged,
        state.CameraChanged,
        state.ConnectionChanged,
        state.HealthChanged,
    }
    others = [part for part in typing.get_args(state.StateChange) if part not in own]
    assert state.NavChanged in others
    named = {other_topic(part.__new__(part)) for part in others}
    assert topics.NAVIGATION in named and len(named) == len(others)
    fixed = {v for k, v in vars(topics).items() if k.isupper() and isinstance(v, str)}
    assert named - {topics.NAVIGATION} <= {t for t in named if t.startswith(topics.STATE_PREFIX)} - fixed


def test_a_stopped_recording_drains_quietly_until_closed(tmp_path: Path) -> None:
    """After its limit the writer only drains its queue: no busy loop eating a core until it is closed."""
    import resource

    recording = Recording(tmp_path / "capped.mcap", limits=Limits(max_bytes=1)).start()
    recording.submit(Event(topics.NOTICES, {"n": 1}, time.time_ns()))
    deadline = time.monotonic() + 5
    while recording.stopped is None:
        assert time.monotonic() < deadline
        time.sleep(0.01)

    def cpu() -> float:
        usage = resource.getrusage(resource.RUSAGE_SELF)
        return usage.ru_utime + usage.ru_stime

    before = cpu()
    time.sleep(0.6)
    assert cpu() - before < 0.2, "the stopped writer spins"
    started = time.monotonic()
    recording.close()
    assert time.monotonic() - started < 2.0
    assert "size limit" in (recording.stopped or "")
