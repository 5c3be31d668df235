"""The gamepad's mapping and its stops: rules on a fake clock, then the same pad events against the simulator.

No GTK here: ``rtmu.control.gamepad`` gets the events the libmanette adapter would give it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from patience import PATIENCE
from rtmu.client.lease import EndReason
from rtmu.client.session import SessionConfig
from rtmu.control.gamepad import (
    AXIS_CODES,
    AXIS_ROT,
    AXIS_TRANS,
    BUTTON_CODES,
    DEADMAN,
    FASTER,
    HAT_Y,
    SILENCE,
    SLOWER,
    STOP,
    DeadMan,
    Gamepad,
    stick_ratios,
)
from rtmu.fleet.sessions import Fleet, RobotSession
from rtmu.model.observables import LinkHealth, LinkLevel, Phase
from rtmu.package_data import project_map
from rtmu.settings.store import Profile
from rtmu.sim import SimConfig, SimThread

from .test_controller import Rig
from .uiqueue import UiQueue

ARENA = project_map("arena.map")
PAD = object()


# -- the mapping ------------------------------------------------------------------------------------
def test_stick_ratios_dead_zone_scaling_and_steps() -> None:
    assert stick_ratios(0.0, 0.0) == (0.0, 0.0)
    assert stick_ratios(0.15, -0.1) == (0.0, 0.0), "inside the dead zone"
    assert stick_ratios(0.0, -1.0) == (100.0, 0.0), "stick up = forward"
    assert stick_ratios(0.0, 1.0) == (-100.0, 0.0)
    assert stick_ratios(-1.0, 0.0) == (0.0, 100.0), "stick left = rot positive (left)"
    trans, rot = stick_ratios(0.0, -0.6)
    assert trans == 50.0 and rot == 0.0, "rescaled past the dead zone, 5 % steps"
    assert stick_ratios(0.0, -0.61)[0] % 5 == 0


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, 1e300, -7.0])
def test_hostile_axis_values_read_as_centred_or_clamped(bad: float) -> None:
    trans, rot = stick_ratios(bad, bad)
    assert -100 <= trans <= 100 and -100 <= rot <= 100
    if not math.isfinite(bad):
        assert (trans, rot) == (0.0, 0.0)


class PadRig(Rig):
    def __init__(self) -> None:
        super().__init__()
        self.pad = Gamepad(self.ctl, self.clock)
        self.states: list[DeadMan] = []
        self.pad.on_change = lambda s: self.states.append(s.deadman)
        assert self.pad.connected(PAD, "Test pad")

    def tick(self, seconds: float) -> None:
        """The window's 10 Hz timer: the controller renews, the pad checks for silence."""
        for _ in range(round(seconds / 0.1)):
            self.clock.advance(0.1)
            self.ctl.tick()
            self.pad.tick()


def test_stick_drives_only_while_the_deadman_is_held() -> None:
    rig = PadRig()
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.tick(0.5)
    assert not rig.lease.live and rig.link.lease.view().generation == 0, "a stick without dead-man drove"
    rig.pad.button(PAD, DEADMAN, True)
    assert rig.lease.live and (rig.lease.ratios.trans, rig.lease.ratios.rot) == (100.0, 0.0)
    assert rig.pad.state.deadman is DeadMan.HELD
    rig.tick(1.0)
    assert rig.lease.live, "held: the controller keeps renewing"
    rig.pad.axis(PAD, AXIS_ROT, 1.0)  # the lease carries the analog ratio as it changes
    rig.clock.advance(0.06)
    rig.pad.axis(PAD, AXIS_ROT, 1.0)
    assert rig.lease.ratios.rot < 0 and rig.lease.ratios.trans > 0
    rig.pad.button(PAD, DEADMAN, False)
    assert not rig.lease.live and rig.lease.ended is EndReason.RELEASED


def test_unplugging_the_pad_stops() -> None:
    rig = PadRig()
    rig.pad.button(PAD, DEADMAN, True)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.tick(0.3)
    assert rig.lease.live
    rig.pad.disconnected(PAD)
    assert not rig.lease.live and rig.pad.state.deadman is DeadMan.NO_PAD


def test_a_silent_pad_stops_and_needs_a_fresh_deadman_press() -> None:
    rig = PadRig()
    rig.pad.button(PAD, DEADMAN, True)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.tick(SILENCE - 0.2)
    assert rig.lease.live, "stopped before the pad was silent for long"
    rig.tick(0.4)
    assert not rig.lease.live
    assert rig.pad.state.deadman is DeadMan.LATCHED
    rig.pad.axis(PAD, AXIS_TRANS, -0.9)  # the pad talks again: still latched
    rig.tick(0.2)
    assert not rig.lease.live
    rig.pad.button(PAD, DEADMAN, False)
    rig.pad.button(PAD, DEADMAN, True)
    assert rig.lease.live


def test_stop_button_and_a_lapse_block_the_stick_until_the_deadman_is_repressed() -> None:
    rig = PadRig()
    rig.pad.button(PAD, DEADMAN, True)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.link.calls.clear()
    rig.pad.button(PAD, STOP, True)
    assert "stop" in rig.link.names() and not rig.lease.live
    rig.clock.advance(0.1)
    rig.pad.axis(PAD, AXIS_TRANS, -0.8)
    assert not rig.lease.live and rig.pad.state.deadman is DeadMan.LATCHED
    rig.pad.button(PAD, DEADMAN, False)
    rig.pad.button(PAD, DEADMAN, True)
    assert rig.lease.live
    rig.clock.advance(0.5)  # the UI froze: the lease lapses
    rig.ctl.tick()
    assert not rig.lease.live
    rig.clock.advance(0.1)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    assert not rig.lease.live, "a lapsed lease came back without a fresh dead-man press"


def test_focus_loss_stops_and_a_press_while_unfocused_never_drives() -> None:
    rig = PadRig()
    rig.pad.button(PAD, DEADMAN, True)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.ctl.focus_lost()  # what the window does first
    rig.pad.focus(False)
    assert not rig.lease.live
    rig.pad.button(PAD, DEADMAN, False)
    rig.pad.button(PAD, DEADMAN, True)
    assert not rig.lease.live, "drove for a window that does not have focus"
    rig.pad.focus(True)
    rig.clock.advance(0.1)
    rig.pad.axis(PAD, AXIS_TRANS, -0.9)
    assert not rig.lease.live
    rig.pad.button(PAD, DEADMAN, False)
    rig.pad.button(PAD, DEADMAN, True)
    assert rig.lease.live


def test_a_stale_link_stops_the_stick() -> None:
    rig = PadRig()
    rig.pad.button(PAD, DEADMAN, True)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.model.health.set(LinkHealth(LinkLevel.STALE))
    assert not rig.lease.live and rig.ctl.analog_blocked


def test_speed_steps_on_the_dpad_apply_to_the_drive() -> None:
    rig = PadRig()
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.pad.button(PAD, DEADMAN, True)
    before = rig.lease.ratios.throttle
    assert rig.lease.live
    rig.pad.button(PAD, FASTER, True)
    assert rig.lease.ratios.throttle == before + 10
    rig.pad.button(PAD, SLOWER, True)
    rig.pad.button(PAD, SLOWER, True)
    assert rig.lease.ratios.throttle == before - 10


def test_a_second_pad_is_ignored_while_the_first_is_there() -> None:
    rig = PadRig()
    other = object()
    assert not rig.pad.connected(other, "Another pad")
    rig.pad.button(other, DEADMAN, True)
    rig.pad.axis(other, AXIS_TRANS, -1.0)
    assert not rig.lease.live


def test_a_flooding_pad_reaches_the_lease_at_a_bounded_rate() -> None:
    rig = PadRig()
    changes: list[object] = []
    rig.link.lease.on_event = changes.append
    rig.pad.button(PAD, DEADMAN, True)
    for i in range(20_000):  # 20 000 events in one simulated second
        rig.pad.axis(PAD, AXIS_TRANS, -0.3 - 0.7 * ((i * 7919) % 100) / 100)
        rig.clock.advance(0.00005)
        if i % 2000 == 1999:
            rig.ctl.tick()
            rig.pad.tick()
    assert rig.lease.live
    assert len(changes) <= 1 + 1 / 0.05 + 10, f"{len(changes)} lease changes for one second of flood"


def test_a_stuck_stick_without_deadman_never_moves_even_with_buttons_mashed() -> None:
    rig = PadRig()
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.pad.axis(PAD, AXIS_ROT, 0.7)
    for name in (STOP, FASTER, SLOWER, "south", "west", "north", "right_shoulder"):
        rig.pad.button(PAD, name, True)
        rig.pad.button(PAD, name, False)
    rig.tick(2.0)
    assert rig.link.lease.view().generation == 0


# -- against the simulator -------------------------------------------------------------------------
@contextmanager
def robot() -> Iterator[tuple[RobotSession, Gamepad, UiQueue, SimThread]]:
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        ui = UiQueue()
        fleet = Fleet()
        session = fleet.open(
            post=ui.post,
            config=SessionConfig(fetch_map=False),
            profile=Profile("pad", host="127.0.0.1", port=sim.port),
        )
        try:
            session.controller.connect()
            ui.wait_for(lambda: session.state.connection.value.phase is Phase.CONNECTED, timeout=10)
            pad = Gamepad(session.controller, time.monotonic)
            pad.connected(PAD, "Test pad")
            yield session, pad, ui, sim
        finally:
            fleet.close()


def run_ui(
    ui: UiQueue, session: RobotSession, pad: Gamepad, seconds: float, stick: float | None = None
) -> None:
    """The window's 10 Hz timer for ``seconds``; ``stick`` keeps the pad talking (a real stick's noise)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if stick is not None:
            pad.axis(PAD, AXIS_TRANS, stick)
        session.controller.tick()
        pad.tick()
        ui.drain()
        time.sleep(0.1)


def mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))


def wait_mode(sim: SimThread, name: str, within: float = 1.0) -> None:
    deadline = time.monotonic() + within * PATIENCE
    while (now := mode(sim)) != name:
        assert time.monotonic() < deadline, f"the robot is in {now!r}, not {name!r}"
        time.sleep(0.02)


def test_sim_stick_with_deadman_drives_and_release_stops() -> None:
    with robot() as (session, pad, ui, sim):
        start = sim.snapshot()
        pad.axis(PAD, AXIS_TRANS, -0.6)
        pad.button(PAD, DEADMAN, True)
        run_ui(ui, session, pad, 1.0, stick=-0.6)
        assert sim.call(lambda: sim.server.robot.received_ratios)[:2] == (50.0, 0.0), (
            "analog ratio on the wire"
        )
        moved = sim.snapshot()
        assert moved.vel > 0 and math.hypot(moved.x - start.x, moved.y - start.y) > 20
        pad.button(PAD, DEADMAN, False)
        wait_mode(sim, "stop")
        watchdog = sim.call(lambda: sim.server.robot.watchdog_stops)
        assert watchdog == 0, "stopped by the server's watchdog, not by us"


def test_sim_unplugged_pad_stops() -> None:
    with robot() as (session, pad, ui, sim):
        pad.button(PAD, DEADMAN, True)
        pad.axis(PAD, AXIS_TRANS, -1.0)
        run_ui(ui, session, pad, 0.5, stick=-1.0)
        assert mode(sim) == "ratioDrive"
        pad.disconnected(PAD)
        wait_mode(sim, "stop")


def test_sim_silent_pad_stops_within_its_timeout() -> None:
    with robot() as (session, pad, ui, sim):
        pad.button(PAD, DEADMAN, True)
        pad.axis(PAD, AXIS_TRANS, -1.0)
        run_ui(ui, session, pad, 0.5)  # from here on the pad says nothing
        assert mode(sim) == "ratioDrive"
        run_ui(ui, session, pad, SILENCE + 0.3)
        wait_mode(sim, "stop")
        drives = sim.call(lambda: sim.server.robot.ratio_drives_received)
        run_ui(ui, session, pad, 0.5, stick=-1.0)  # it talks again, the dead-man still down
        assert sim.call(lambda: sim.server.robot.ratio_drives_received) == drives
        assert mode(sim) == "stop"


def test_sim_stuck_stick_without_deadman_sends_no_drive() -> None:
    with robot() as (session, pad, ui, sim):
        pad.axis(PAD, AXIS_TRANS, -1.0)
        pad.axis(PAD, AXIS_ROT, -1.0)
        run_ui(ui, session, pad, 1.0, stick=-1.0)
        assert sim.call(lambda: sim.server.robot.ratio_drives_received) == 0
        assert sim.snapshot().vel == 0


def test_sim_flooding_pad_sends_a_bounded_stream() -> None:
    with robot() as (session, pad, ui, sim):
        pad.button(PAD, DEADMAN, True)
        end = time.monotonic() + 1.0
        events = 0
        while time.monotonic() < end:
            for i in range(500):
                pad.axis(PAD, AXIS_TRANS, -0.3 - 0.7 * ((events + i) % 97) / 97)
            events += 500
            session.controller.tick()
            pad.tick()
            ui.drain()
        pad.button(PAD, DEADMAN, False)
        wait_mode(sim, "stop")
        sent = sim.call(lambda: sim.server.robot.ratio_drives_received)
        assert events > 5000
        assert 0 < sent <= 45, f"{sent} ratioDrives for {events} pad events in 1 s"


def test_an_unmapped_pads_hat_dpad_steps_the_speed_and_any_event_is_a_sign_of_life() -> None:
    rig = PadRig()
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)
    rig.pad.button(PAD, DEADMAN, True)
    before = rig.lease.ratios.throttle
    rig.pad.hat(PAD, HAT_Y, -1)
    rig.pad.hat(PAD, HAT_Y, 0)
    assert rig.lease.ratios.throttle == before + 10
    for _ in range(round(2 * SILENCE / 0.5)):  # an unknown button now and then keeps the pad alive
        rig.tick(0.5)
        rig.pad.button(PAD, "code_999", True)
    assert rig.lease.live


def test_linux_codes_map_to_the_documented_buttons() -> None:
    assert BUTTON_CODES[0x136] == DEADMAN and BUTTON_CODES[0x131] == STOP
    assert BUTTON_CODES[0x220] == FASTER and BUTTON_CODES[0x221] == SLOWER
    assert AXIS_CODES[0x01] == AXIS_TRANS and AXIS_CODES[0x00] == AXIS_ROT


def test_the_libmanette_adapter_starts_on_this_machine_and_finds_no_pad() -> None:
    from rtmu.ui.gamepad import ManettePads

    rig = PadRig()
    pad = Gamepad(rig.ctl, rig.clock)
    pads = ManettePads(pad)
    try:
        assert pads.available, "libmanette (gir1.2-manette-0.2, from scripts/setup.sh) is missing"
        assert pad.state.deadman is DeadMan.NO_PAD  # no /dev/input here: nothing plugged in
    finally:
        pads.close()


def test_the_stick_during_a_navigation_only_stops_it_and_the_next_deadman_press_drives() -> None:
    from rtmu.model.observables import NavState

    rig = PadRig()
    rig.model.navigation.set(NavState(navigating=True, target="Lab B", goals=("Lab A", "Lab B")))
    rig.pad.button(PAD, DEADMAN, True)  # the dead-man alone, stick centred: the navigation goes on
    assert "stop" not in rig.link.names()
    rig.clock.advance(0.1)
    rig.pad.axis(PAD, AXIS_TRANS, -1.0)  # the operator wins: this only stops
    assert rig.link.names().count("stop") == 1 and not rig.lease.live
    rig.model.navigation.set(NavState(navigating=False, goals=("Lab A", "Lab B")))
    rig.clock.advance(0.1)
    rig.pad.axis(PAD, AXIS_TRANS, -0.9)
    assert not rig.lease.live, "the stick that stopped the navigation drove on without a fresh press"
    rig.pad.button(PAD, DEADMAN, False)
    rig.pad.button(PAD, DEADMAN, True)
    assert rig.lease.live
