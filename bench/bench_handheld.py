"""What the handheld parts cost on the UI thread, each against the simple way in the same run.

* ``handheld.pad_axis_event_us``: one stick event through the gamepad mapping, the controller and the
  drive lease (stick moving, dead-man held, a fake clock advancing 1 ms per event so the rate limit
  lets one in twenty through). Baseline: one drive key press + release through the same controller
  and lease — the keyboard's cost per event.
* ``handheld.flood_lease_updates``: lease updates (what wakes the network side to send ``ratioDrive``)
  for 20 000 stick events in one second of a flooding pad. Baseline: the events themselves, what a
  mapping without the rate limit would have pushed.
* ``handheld.alarm_update_us``: one ``AlarmMonitor.update`` (battery, Wi-Fi, round trip with
  hysteresis). Baseline: ``RobotState.battery_state``, the plain threshold compare the toolbar makes.
"""

from __future__ import annotations

from types import SimpleNamespace

from bench.common import Result, best_time
from rtmu.client.lease import DriveLease
from rtmu.control.alarms import AlarmMonitor
from rtmu.control.controller import Controller
from rtmu.control.gamepad import AXIS_TRANS, DEADMAN, Gamepad
from rtmu.control.ports import NoView
from rtmu.model.observables import ConnectionState, LinkHealth, LinkLevel, OperatorState, Phase, RobotModel
from rtmu.values.state import RobotState


class _Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def _rig() -> tuple[Controller, Gamepad, _Clock, DriveLease]:
    clock = _Clock()
    model = RobotModel()
    model.connection.set(
        ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272, offers=frozenset({"ratioDrive"}))
    )
    model.health.set(LinkHealth(LinkLevel.OK))
    lease = DriveLease(clock=clock, ttl=1e9)  # the bench measures cost, not lapses
    link = SimpleNamespace(lease=lease, on_notice=None, stop=lambda: None)
    controller = Controller(model, OperatorState(), link, NoView(), clock=clock)  # type: ignore[arg-type]
    pad = Gamepad(controller, clock)
    pad.connected("pad", "bench pad")
    return controller, pad, clock, lease


def run() -> list[Result]:
    controller, pad, clock, _lease = _rig()
    pad.button("pad", DEADMAN, True)
    values = [-0.3 - 0.7 * (i % 97) / 97 for i in range(97)]
    state = {"i": 0}

    def axis_event() -> None:
        state["i"] += 1
        clock.now += 0.001
        pad.axis("pad", AXIS_TRANS, values[state["i"] % 97])

    def key_event() -> None:
        controller.press("forward")
        controller.release("forward")

    pad_s = best_time(axis_event)
    pad.button("pad", DEADMAN, False)
    key_s = best_time(key_event)

    _c, flood_pad, flood_clock, flood_lease = _rig()
    updates = [0]
    flood_lease.on_change = lambda: updates.__setitem__(0, updates[0] + 1)
    flood_pad.button("pad", DEADMAN, True)
    events = 20_000
    for i in range(events):
        flood_clock.now += 1.0 / events
        flood_pad.axis("pad", AXIS_TRANS, values[i % 97])
        if i % 2000 == 0:
            flood_pad.tick()

    monitor = AlarmMonitor()
    robots = [
        RobotState(battery_v=v / 10, battery_low=11.5, battery_shutdown=11.0, wifi_quality=q)
        for v, q in zip(range(100, 140), range(0, 70, 2), strict=False)
    ]
    health = LinkHealth(LinkLevel.OK, rtt_ms=12.0)
    k = {"i": 0}

    def alarm_update() -> None:
        k["i"] += 1
        monitor.update(robots[k["i"] % len(robots)], health)

    def plain_check() -> None:
        k["i"] += 1
        _ = robots[k["i"] % len(robots)].battery_state

    return [
        Result("handheld.pad_axis_event_us", pad_s * 1e6, "us", baseline=key_s * 1e6),
        Result("handheld.flood_lease_updates", float(updates[0]), "updates", baseline=float(events)),
        Result(
            "handheld.alarm_update_us",
            best_time(alarm_update) * 1e6,
            "us",
            baseline=best_time(plain_check) * 1e6,
        ),
    ]
