"""The window's model hears LD data from ``rtmu sim --kind aram`` and none of it from the default."""

from __future__ import annotations

import time

from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import Phase, RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.ld_data import ROUTES
from rtmu.values.intents import Dock
from rtmu.values.target import Target

from .uiqueue import UiQueue

OFFICE = project_map("office.map")


def connected(port: int) -> tuple[ClientRunner, RobotModel, UiQueue]:
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, clock=time.monotonic, config=SessionConfig(fetch_map=False))
    runner.start()
    runner.connect(Target("127.0.0.1", port, profile="sim")).result(10)
    ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
    return runner, model, ui


def test_model_gets_laser_dock_routes_and_data_store_from_aram() -> None:
    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE)) as sim:
        runner, model, ui = connected(sim.port)
        try:
            ui.wait_for(lambda: len(model.robot.value.laser) > 50, timeout=5)
            ui.wait_for(lambda: model.robot.value.dock_state == "Undocked", timeout=5)
            ui.wait_for(lambda: model.robot.value.routes == ROUTES, timeout=5)
            ui.wait_for(lambda: len(model.robot.value.data_store) >= 5, timeout=5)
            names = dict(model.robot.value.data_store)
            assert 0 <= int(names["DataStore_WirelessQuality"]) <= 70
            runner.send(Dock()).result(5)
            ui.wait_for(lambda: model.robot.value.dock_state == "Docking", timeout=5)
            ui.wait_for(lambda: model.robot.value.dock_state == "Docked", timeout=90)  # it drives there
        finally:
            runner.close()


def test_default_profile_publishes_none_of_it_but_its_laser() -> None:
    """A Pioneer server's laser (MobileSim's ``sim_lms2xx_1Current`` drawing) is every robot's laser."""
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        runner, model, ui = connected(sim.port)
        try:
            ui.wait_for(lambda: len(model.robot.value.sonar) > 0, timeout=5)
            ui.wait_for(lambda: model.robot.value.wifi_quality is not None, timeout=5)
            ui.wait_for(lambda: len(model.robot.value.laser) > 50, timeout=5)
            robot = model.robot.value
            assert robot.dock_state is None
            assert robot.routes == () and robot.data_store == ()
            offers = model.connection.value.offers
            assert "updateNumbers" in offers and "getRoutes" not in offers
        finally:
            runner.close()
