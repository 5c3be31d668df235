"""A fresh scan of the office map while the robot is driven round a loop: the ``.2d`` parses, in order.

The simulator runs on its manual clock; the test drives it the way ``rtmu drive`` does (``ratioDrive``
every 100 ms) round a circle, tags the loop, stops the scan, downloads the log through ``getFile`` and
reads it with a reader written from the format's documentation (``scanlog_reader``).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

from rtmu.client.connection import AriaClient
from rtmu.client.download import download_file
from rtmu.client.scan import start_scan, stop_scan, tag_loop
from rtmu.package_data import project_map
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target

from .scanlog_reader import Reading, Tag, read_scan_log
from .servers import run

OFFICE = project_map("office.map")
TRANS_PCT, TURN_PCT = 30.0, 40.0
STEPS = 300
"""100 ms steps of driving: a little more than one full turn (about 20 °/s)."""


def test_a_scan_driven_round_a_loop_parses_with_poses_and_readings_in_order(tmp_path: Path) -> None:
    robot = tmp_path / "robot"
    robot.mkdir()
    with SimThread(SimConfig(port=0, realtime=False, map_path=OFFICE, files_dir=robot)) as sim:

        async def main() -> None:
            c = AriaClient()
            await c.connect(Target("127.0.0.1", sim.port))
            try:
                assert await start_scan(c, "Office Loop") == "office loop.2d"
                sim.advance(0.2)
                assert await tag_loop(c, start=True, tag="1")
                for _ in range(STEPS):
                    c.send(RatioDrive(TRANS_PCT, TURN_PCT, 100))
                    await c.flush()
                    sim.advance(0.1)
                assert await tag_loop(c, start=False, tag="1")
                c.send("stop")
                await c.flush()
                sim.advance(0.5)
                assert await stop_scan(c) == "office loop.2d"
                await download_file(c, "office loop.2d", tmp_path / "loop.2d")
            finally:
                await c.disconnect()

        run(main(), 120)
        home = sim.server.home if sim.server is not None else (0.0, 0.0, 0.0)

    log = read_scan_log((tmp_path / "loop.2d").read_text())
    assert log.ended
    assert log.header["version"] == "4" and log.header["sick1conf"] == "-90.00 90.00 181"
    assert log.header["locationTypes"] == "robot robotGlobal"
    readings = log.readings
    assert len(readings) >= 360 / 25  # a turn every 25° at least
    assert [r.scan_id for r in readings] == list(range(len(readings)))
    assert all(a.time <= b.time for a, b in itertools.pairwise(readings))
    assert all(len(r.points) == 181 for r in readings)
    assert readings[0].pose[:2] == (round(home[0]), round(home[1]))
    for a, b in itertools.pairwise(readings):
        moved = math.hypot(b.pose[0] - a.pose[0], b.pose[1] - a.pose[1])
        turned = abs((b.pose[2] - a.pose[2] + 180) % 360 - 180)
        assert moved > 300 or turned > 25 or b.time - a.time > 0, (a, b)
    headings = [r.pose[2] for r in readings]
    turned_total = sum(abs((b - a + 180) % 360 - 180) for a, b in itertools.pairwise(headings))
    assert turned_total >= 330  # round the loop
    assert all(any(p != (0, 0) for p in r.points) for r in readings)  # the office's walls are in range
    texts = [t.text for t in log.tags]
    assert texts == ["loop start 1", "loop stop 1"]
    kinds = ["tag" if isinstance(x, Tag) else "reading" for x in log.order]
    assert kinds[0] == "reading" and kinds.index("tag") < len(kinds) - 1 - kinds[::-1].index("reading")
    first_tag, last_tag = log.tags
    inside = [r for r in readings if first_tag.time <= r.time <= last_tag.time]
    assert len(inside) >= len(readings) - 3
    assert isinstance(readings[0], Reading)
