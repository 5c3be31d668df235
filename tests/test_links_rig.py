"""The links lab's simulator stands for the robot, whose CPUs are not the laptop's: its process leads a
session of its own whose scheduling group is raised where allowed, so a busy session beside it (other
engineers' test runs) cannot keep its status 300–400 ms late, as a traced soak once found."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the lab's rig lives in bench/
from bench.links_rig import RigProcess
from bench.links_rig_proc import ROBOT_PRIORITY


def _autogroup_nice(pid: int) -> int:
    with open(f"/proc/{pid}/autogroup") as f:
        return int(f.read().split()[-1])


def test_the_rig_runs_in_a_raised_group_of_its_own() -> None:
    if not os.path.exists("/proc/self/autogroup"):
        pytest.skip("no autogroup on this kernel: nice values alone order the threads")
    rig = RigProcess(seed=1)
    try:
        assert os.getsid(rig.proc.pid) == rig.proc.pid  # a session (and a scheduling group) of its own
        assert os.getsid(rig.proc.pid) != os.getsid(0)
        if os.geteuid() == 0:
            assert _autogroup_nice(rig.proc.pid) == ROBOT_PRIORITY
        rig.play("good", 1)  # and it still answers
        assert rig.drives() == 0
    finally:
        rig.close()
