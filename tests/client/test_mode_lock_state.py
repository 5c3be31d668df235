"""getModeInfo's lock flags reach the robot's state and read as words the operator is shown."""

from __future__ import annotations

from rtmu.client.runner import ClientRunner
from rtmu.model.observables import RobotModel
from rtmu.sim import SimConfig, SimThread
from rtmu.values.state import RobotState
from rtmu.values.target import Target

from .uiqueue import UiQueue


def test_the_lock_flags_reach_the_robot_state_and_clear_again() -> None:
    model, ui = RobotModel(), UiQueue()
    with SimThread(SimConfig(port=0)) as sim, ClientRunner(model, post=ui.post) as runner:
        runner.connect(Target("127.0.0.1", sim.port)).result(10)
        ui.wait_for(lambda: model.robot.value.mode_name == "stop", 10)
        assert model.robot.value.mode_lock == ""
        runner.call(lambda: runner.session.client.send("SimulatorLockStopMode"))  # type: ignore[union-attr]
        ui.wait_for(lambda: model.robot.value.mode_locked, 10)
        robot = model.robot.value
        assert (robot.mode_locked, robot.mode_will_unlock) == (True, False)
        assert robot.mode_lock == "locked in Stop mode; will not unlock if asked"
        runner.call(lambda: runner.session.client.send("SimulatorUnlockMode"))  # type: ignore[union-attr]
        ui.wait_for(lambda: not model.robot.value.mode_locked, 10)
        assert model.robot.value.mode_lock == ""


def test_the_lock_in_words() -> None:
    docking = RobotState(mode="Docking", mode_name="dock", mode_locked=True, mode_will_unlock=True)
    assert docking.mode_lock == "locked in Docking mode; will unlock if asked"
    nameless = RobotState(mode_locked=True)
    assert nameless.mode_lock == "locked in its current mode; will not unlock if asked"
    assert RobotState(mode="Stop", mode_will_unlock=True).mode_lock == ""
