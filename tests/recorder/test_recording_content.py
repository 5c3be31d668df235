"""What a recording says from its first message on: the robot as it is, named schemas, honest units.

A window's session records the simulator; the file is read with the ``mcap`` package. A parked
robot is in every second of the file; nothing is written of the robot before the server described
it (no pose at 0, 0, no empty status); a state-of-charge robot's battery is never called volts;
MobileSim's "no temperature" (−127) is no temperature; every JSON channel has a schema of its own
name that Foxglove shows.
"""

from __future__ import annotations

import itertools
import time
from pathlib import Path

from rtmu.capture.recorded import RAW_TOPICS
from rtmu.recorder import topics
from rtmu.sim import SimConfig

from .mcapread import read
from .poses import _position
from .simsession import ARENA, recorded_session

START = (2500.0, 1500.0, 30.0)


def record_parked(tmp_path: Path, sim: SimConfig, seconds: float) -> Path:
    with recorded_session(tmp_path, sim=sim) as (session, ui, _view, _sim):
        ui.wait_for(lambda: session.state.robot.value.numbers_at is not None, timeout=10)
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            ui.drain()
            time.sleep(0.05)
    (path,) = tmp_path.glob("*.mcap")
    return path


def test_a_parked_robot_is_in_every_second_and_the_file_starts_with_the_real_robot(tmp_path: Path) -> None:
    path = record_parked(tmp_path, SimConfig(port=0, map_path=ARENA, seed=2, start_pose=START), 3.5)
    got = read(path)
    poses = got.topic(topics.POSE)
    assert len(poses) >= 4, "a parked robot's pose is written again, not once"
    first = _position(poses[0].data)
    assert first != (0, 0) and abs(first[0] - START[0]) < 300 and abs(first[1] - START[1]) < 300, first
    times = [m.log_time for m in poses]
    assert max(b - a for a, b in itertools.pairwise(times)) <= 1_000_000_000, "a second without a pose"
    tf = got.topic(topics.TF)
    assert len(tf) == len(poses)
    statuses = got.records(topics.STATUS)
    assert statuses and statuses[0]["mode"] and statuses[0]["status"], "no empty status at the start"
    assert all(s["temperature_c"] is None for s in statuses), "MobileSim's -127 is no temperature"
    assert all("volts" in s["battery"] for s in statuses if s["battery"]["state"] != "unknown")
    lasers = got.topic(topics.LASER)  # a Pioneer's laser: MobileSim's sim_lms2xx_1Current drawing
    assert lasers and got.schemas()[topics.LASER] == ("foxglove.PointCloud", "protobuf")
    assert max(m.data.count(b"map") for m in lasers) == 1 and max(len(m.data) for m in lasers) > 100 * 12


def test_every_json_channel_has_a_named_schema(tmp_path: Path) -> None:
    path = record_parked(tmp_path, SimConfig(port=0, map_path=ARENA, seed=2), 1.0)
    schemas = read(path).schemas()
    json_topics = {t: name for t, (name, encoding) in schemas.items() if encoding == "json"}
    assert json_topics[topics.STATUS] == "rtmu.Status"
    assert json_topics[topics.CONNECTION] == "rtmu.Connection"
    assert json_topics[topics.LINK_HEALTH] == "rtmu.LinkHealth"
    assert all(name.startswith("rtmu.") for name in json_topics.values()), json_topics
    assert len(set(json_topics.values())) == len(json_topics), "one schema per channel, not one for all"
    assert schemas[RAW_TOPICS["s2c"]][0] == "rtmu.ArNetworkingBytes"


def test_a_state_of_charge_is_never_recorded_as_volts(tmp_path: Path) -> None:
    """The LD profile reports a state of charge; the first status must already say so (or say nothing)."""
    path = record_parked(tmp_path, SimConfig(port=0, map_path=ARENA, seed=2, profile="aram"), 1.5)
    batteries = [s["battery"] for s in read(path).records(topics.STATUS)]
    assert batteries and any("state_of_charge_pct" in b for b in batteries)
    assert not any("volts" in b for b in batteries), batteries[:3]
