"""The battery figure is published only with its unit: a late ``batteryInfo`` is asked again.

A real loopback server (tests/client/servers.py) that leaves the first ``batteryInfo`` unanswered, as a
busy robot or laptop may, and answers the second with "state of charge". The window's reading must
never show the LD robot's 87 % as 87 V: the number waits for its unit, which the second ask brings.
"""

from __future__ import annotations

from rtmu.client.runner import ClientRunner
from rtmu.client.session_config import SessionConfig
from rtmu.model.observables import RobotModel
from rtmu.protocol.payloads.robot import BatteryInfo
from rtmu.values.target import Target

from .servers import ServerThread, TestServer
from .uiqueue import UiQueue


def test_a_batteryinfo_that_times_out_once_is_asked_again_and_the_number_waits_for_its_unit() -> None:
    server = TestServer()
    server.state["battery"] = 87.0
    asked: list[int] = []

    def late_battery_info(_side, _args):  # type: ignore[no-untyped-def]
        asked.append(1)
        return [] if len(asked) == 1 else [BatteryInfo(20.0, 5.0, True).encode()]

    server.handlers["batteryInfo"] = late_battery_info
    model, ui = RobotModel(), UiQueue()
    shown: list[tuple[float | None, bool]] = []
    model.robot.observe(lambda _old, new: shown.append((new.battery_v, new.battery_is_soc)))
    with (
        ServerThread(server) as running,
        ClientRunner(model, post=ui.post, config=SessionConfig(reply_timeout=0.5)) as runner,
    ):
        runner.connect(Target("127.0.0.1", running.port)).result(10)
        ui.wait_for(lambda: model.robot.value.battery_v is not None, 10)
    assert len(asked) == 2  # the unanswered ask was followed by a second one
    assert model.robot.value.battery_is_soc and model.robot.value.battery_v == 87.0
    assert all(soc for value, soc in shown if value is not None), "the number was shown without its unit"
