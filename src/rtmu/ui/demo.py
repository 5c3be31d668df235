"""``rtmu --demo [--robots N]``: the bundled simulator beside the window, and the options that reach it.

The window itself never knows it is a demo: it gets ordinary options — one robot at
``127.0.0.1:PORT``, or a fleet of ``robot1…N`` — pointing at simulators started here on free
loopback ports, which run for as long as the window lives. Kept apart from ``ui.app`` (the
command line's entry) so that starting simulators is one module's job.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Protocol

from ..package_data import project_map
from ..settings.store import DirectRobot
from .options import GuiOptions

DEMO_MAP = "office.map"


class RunningDemo(Protocol):
    """What the window's start-up needs of the simulators it started: a way to stop them."""

    def stop(self) -> None: ...


def demo_fleet_options(options: GuiOptions, endpoints: list[tuple[str, int]]) -> GuiOptions:
    """The window on every simulated robot of ``--demo --robots N``."""
    robots = tuple(DirectRobot(name, "127.0.0.1", port) for name, port in endpoints)
    return replace(options, fleet=robots, host=None, port=None, user=None, persist=False, connect=True)


def start_demo(options: GuiOptions, robots: int = 1) -> tuple[GuiOptions, RunningDemo]:
    """Start ``robots`` simulated robots on the office map; the options that connect the window to them.

    Raises whatever the simulator raised when it could not start (the caller says why and exits).
    """
    from ..sim import SimConfig, SimThread

    config = SimConfig(host="127.0.0.1", port=0, map_path=project_map(DEMO_MAP), camera=True)
    if robots == 1:
        sim = SimThread(config).start()
        one = replace(options, host="127.0.0.1", port=sim.port, user=None, persist=False, connect=True)
        return one, sim
    from ..sim.multi import SimFleetThreads, fleet_configs

    fleet = SimFleetThreads(fleet_configs(config, robots)).start()
    return demo_fleet_options(options, fleet.endpoints()), fleet
