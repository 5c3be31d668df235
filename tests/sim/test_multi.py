"""``rtmu sim --robots N``: N servers on consecutive ports, names robot1…N, distinct start poses."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.sim import SimConfig
from rtmu.sim.multi import fleet_configs
from rtmu.sim.start_spots import SPACING_MM

from .wire import WireClient, run

REPO = Path(__file__).resolve().parents[2]


def free_run(count: int) -> int:
    """A first port whose ``count`` consecutive ports are all free on 127.0.0.1 now."""
    for _attempt in range(50):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            first = probe.getsockname()[1]
        if first + count > 65535:
            continue
        socks = []
        try:
            for port in range(first, first + count):
                s = socket.socket()
                s.bind(("127.0.0.1", port))
                socks.append(s)
            return first
        except OSError:
            continue
        finally:
            for s in socks:
                s.close()
    raise AssertionError("no run of free ports")


def test_rtmu_sim_robots_serves_three_robots_apart_and_stops_them_all(arena_map: Path) -> None:
    first = free_run(3)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    cmd = [
        sys.executable,
        "-m",
        "rtmu",
        "sim",
        "--robots",
        "3",
        "--port",
        str(first),
        "--map",
        str(arena_map),
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=REPO)
    try:
        lines = [proc.stdout.readline() for _ in range(3)]  # type: ignore[union-attr]
        found = [re.search(r"(robot\d) listening on 127\.0\.0\.1:(\d+)", line) for line in lines]
        assert all(found), lines
        assert [(m.group(1), int(m.group(2))) for m in found if m] == [
            ("robot1", first), ("robot2", first + 1), ("robot3", first + 2)]  # fmt: skip

        async def poses() -> list[tuple[int, int]]:
            out = []
            for port in range(first, first + 3):
                c = await WireClient().open(port)
                numbers = UpdateNumbers.decode((await c.ask("updateNumbers"))[0])
                out.append((numbers.x, numbers.y))
                await c.close()
            return out

        assert len(set(run(poses()))) == 3, "two robots start at the same place"
        proc.send_signal(signal.SIGINT)
        assert proc.wait(10) == 128 + signal.SIGINT  # ended by Ctrl-C, as every command
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)


def test_fleet_configs_give_consecutive_ports_own_seeds_and_poses() -> None:
    robots = fleet_configs(SimConfig(port=7300, seed=5, start_pose=(1000.0, 0.0, 90.0)), 4)
    assert [r.name for r in robots] == ["robot1", "robot2", "robot3", "robot4"]
    assert [r.config.port for r in robots] == [7300, 7301, 7302, 7303]
    assert [r.config.seed for r in robots] == [5, 6, 7, 8]
    assert len({r.config.start_pose for r in robots}) == 4
    # In a row ahead of home (90°: +y), robot1 in front, none on home itself.
    wanted = [(1000.0, SPACING_MM * k, 90.0) for k in (4, 3, 2, 1)]
    assert [r.config.start_pose for r in robots] == [pytest.approx(p) for p in wanted]
    assert {r.config.port for r in fleet_configs(SimConfig(port=0), 3)} == {0}


@pytest.mark.parametrize(("port", "count"), [(7272, 0), (7272, 51), (65535, 2)])
def test_fleet_configs_refuse_impossible_fleets(port: int, count: int) -> None:
    with pytest.raises(ValueError):
        fleet_configs(SimConfig(port=port), count)


def test_rtmu_sim_robots_refuses_a_bad_count(arena_map: Path) -> None:
    cmd = [sys.executable, "-m", "rtmu", "sim", "--robots", "0", "--port", "0", "--map", str(arena_map)]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, timeout=60)
    assert out.returncode == 2 and "--robots must be 1…50" in out.stderr
