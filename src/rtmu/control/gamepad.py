"""A gamepad's events → the controller's intents, with the pad's own safety rules. GTK-free.

The UI's libmanette adapter (``rtmu.ui.gamepad``) only translates device events
into the calls below; every decision lives here, on an injected clock, so it is
tested headlessly against the simulator.

Mapping (a standard pad; Xbox / PlayStation names):

* **Left shoulder (LB / L1) is the dead-man.** The left stick drives only while
  it is held — the index finger holds it, the thumb steers, the way ROS's
  ``teleop_twist_joy`` enables. Stick up/down is ``trans``, left/right is ``rot``,
  analog, through a radial dead zone and in 5 % steps.
* **East (B / Circle) is STOP**, always, dead-man or not.
* **D-pad up / down** change the speed step (the ``ratioDrive`` throttle).

Stops, each through the controller and so through the same drive lease as the keys:
releasing the dead-man; the pad unplugged; the pad silent for :data:`SILENCE`
seconds while the dead-man is held (a radio gone out of range sends no "removed");
the window losing focus; another robot selected (:meth:`Gamepad.retarget`). After an
unplug, a silence, a focus loss or a switch of robot the stick is latched off until the
dead-man is released and pressed again; after any other
stop (STOP, a lapsed lease, a stale link) the controller itself holds that rule.

A pad that floods events cannot flood the robot: stick changes reach the lease at
most every :data:`MIN_PUSH_INTERVAL` s (the rest wait for :meth:`Gamepad.tick`),
and a ratio equal to the last one pushed is not pushed again.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum
from typing import Protocol

DEADMAN = "left_shoulder"
STOP = "east"
FASTER = "dpad_up"
SLOWER = "dpad_down"
AXIS_TRANS = "left_y"
"""Up is negative on evdev and libmanette: forward = −value."""
AXIS_ROT = "left_x"
"""Left is negative: rot (positive = left) = −value."""

BUTTON_CODES = {
    0x130: "south",  # BTN_SOUTH (A / Cross)
    0x131: "east",  # BTN_EAST (B / Circle)
    0x133: "north",  # BTN_NORTH
    0x134: "west",  # BTN_WEST
    0x136: "left_shoulder",  # BTN_TL (LB / L1)
    0x137: "right_shoulder",  # BTN_TR
    0x220: "dpad_up",  # BTN_DPAD_UP
    0x221: "dpad_down",
    0x222: "dpad_left",
    0x223: "dpad_right",
}
"""Linux input button codes (what libmanette reports for a mapped pad) → the names used here."""
AXIS_CODES = {0x00: "left_x", 0x01: "left_y", 0x03: "right_x", 0x04: "right_y"}
"""ABS_X, ABS_Y, ABS_RX, ABS_RY."""
HAT_Y = 0x11
"""ABS_HAT0Y: an unmapped pad's D-pad, −1 up, +1 down."""

DEAD_ZONE = 0.2
"""Stick deflection (of 1.0) read as centred: worn sticks rest up to ~0.15 off-centre."""
STEP = 5.0
"""Ratios are rounded to 5 % steps: stick noise must not become a stream of new ratios."""
SILENCE = 1.5
"""Seconds without any event from the pad, while the dead-man is held, before it is taken as gone."""
MIN_PUSH_INTERVAL = 0.05
"""At most 20 stick updates a second reach the lease, however fast the pad sends."""


class Drive(Protocol):
    """What the mapping needs of :class:`rtmu.control.controller.Controller`."""

    def analog(self, trans: float, rot: float) -> None: ...

    def analog_release(self) -> None: ...

    def stop(self) -> None: ...

    def speed_up(self) -> None: ...

    def speed_down(self) -> None: ...

    @property
    def analog_blocked(self) -> bool: ...


class DeadMan(Enum):
    """What the status widget shows about the dead-man."""

    NO_PAD = "no pad"
    RELEASED = "released"
    HELD = "held"
    """Held: the stick drives."""
    LATCHED = "release to re-arm"
    """Held, but a stop happened: it must be released and pressed again."""


@dataclass(frozen=True, slots=True)
class PadState:
    name: str = ""
    """The connected pad's name (untrusted device text: shown as plain text only); empty = none."""
    deadman: DeadMan = DeadMan.NO_PAD


def stick_ratios(x: float, y: float) -> tuple[float, float]:
    """(trans, rot) in % for a stick at (x, y) ∈ [−1, 1]²: radial dead zone, rescaled, 5 % steps.

    Anything not a finite number reads as centred; values outside the range are clamped."""
    x = x if math.isfinite(x) else 0.0
    y = y if math.isfinite(y) else 0.0
    x, y = max(-1.0, min(1.0, x)), max(-1.0, min(1.0, y))
    magnitude = math.hypot(x, y)
    if magnitude <= DEAD_ZONE:
        return 0.0, 0.0
    scale = min(1.0, (magnitude - DEAD_ZONE) / (1.0 - DEAD_ZONE)) / magnitude
    trans = _step(-y * scale * 100.0)
    rot = _step(-x * scale * 100.0)
    return trans, rot


def _step(value: float) -> float:
    return float(max(-100.0, min(100.0, round(value / STEP) * STEP))) + 0.0  # + 0.0: no −0.0


class Gamepad:
    """One operator's pad (the first one connected; others are ignored until it goes).

    Call everything from the UI thread; ``now`` is the clock's time of the event.
    """

    def __init__(self, drive: Drive, clock: Callable[[], float]) -> None:
        self.drive = drive
        self.clock = clock
        self.on_change: Callable[[PadState], None] | None = None
        self._device: object | None = None
        self._name = ""
        self._deadman = False
        """The dead-man button is physically down (as far as the pad has told us)."""
        self._latched = False
        """Unplug, silence or focus loss stopped the stick: ignore it until the dead-man is re-pressed."""
        self._focused = True
        self._x = 0.0
        self._y = 0.0
        self._last_event = -math.inf
        self._last_push = -math.inf
        self._pushed: tuple[float, float] | None = None
        self._pending = False
        self._state = PadState()

    # -- devices ---------------------------------------------------------------------------------
    @property
    def state(self) -> PadState:
        return self._state

    def connected(self, device: object, name: str) -> bool:
        """A pad appeared; True if it is now the one we listen to."""
        if self._device is not None:
            return False
        self._device, self._name = device, name
        self._deadman, self._latched, self._x, self._y = False, False, 0.0, 0.0
        self._last_event = self.clock()
        self._publish()
        return True

    def disconnected(self, device: object) -> None:
        """A pad went away: if it is ours and it drove, stop (its release will never come)."""
        if device is not self._device:
            return
        self._stop_stick()
        self._device, self._name, self._deadman, self._latched = None, "", False, False
        self._publish()

    # -- events ----------------------------------------------------------------------------------
    def button(self, device: object, name: str, down: bool) -> None:
        if device is not self._device:
            return
        self._last_event = self.clock()
        if name == STOP and down:
            self.drive.stop()
        elif name == DEADMAN:
            self._deadman_changed(down)
        elif name == FASTER and down and self._focused:
            self.drive.speed_up()
        elif name == SLOWER and down and self._focused:
            self.drive.speed_down()
        self._publish()

    def axis(self, device: object, name: str, value: float) -> None:
        if device is not self._device:
            return
        now = self.clock()
        self._last_event = now
        if name == AXIS_ROT:
            self._x = value
        elif name == AXIS_TRANS:
            self._y = value
        else:
            return
        if not self._driving():
            return
        if now - self._last_push >= MIN_PUSH_INTERVAL:
            self._push(now)
        else:
            self._pending = True

    def focus(self, active: bool) -> None:
        """The window gained or lost focus; losing it stops the stick (the window stops the rest)."""
        if self._focused == active:
            return
        self._focused = active
        if not active and self._deadman:
            self._stop_stick()
            self._latched = True
        self._publish()

    def retarget(self, drive: Drive) -> None:
        """Drive another robot from now on (the window shows another robot of the fleet).

        A stick that was driving is released on the robot before (the fleet has already
        stopped it), and a dead-man still held is latched: the new robot moves only after
        the dead-man is released and pressed again, as a held key does not carry over.
        """
        if drive is self.drive:
            return
        if self._driving():
            self._stop_stick()
        self.drive = drive
        self._pushed = None
        self._pending = False
        if self._deadman:
            self._latched = True
        self._publish()

    def tick(self) -> None:
        """From the UI timer: push a stick change held back by the rate limit; notice a silent pad."""
        if not self._driving():
            self._publish()
            return
        now = self.clock()
        if now - self._last_event > SILENCE:
            self._stop_stick()
            self._latched = True
        elif self._pending and now - self._last_push >= MIN_PUSH_INTERVAL:
            self._push(now)
        self._publish()

    def hat(self, device: object, axis: int, value: int) -> None:
        """An unmapped pad's D-pad as a hat axis: up/down become the speed buttons."""
        if axis != HAT_Y:
            if device is self._device:
                self._last_event = self.clock()
            return
        if value < 0:
            self.button(device, FASTER, True)
        elif value > 0:
            self.button(device, SLOWER, True)
        elif device is self._device:
            self._last_event = self.clock()

    # -- inside ----------------------------------------------------------------------------------
    def _deadman_changed(self, down: bool) -> None:
        if down == self._deadman:
            return  # a repeated event: nothing new
        self._deadman = down
        if not down:
            self._latched = False
            self._stop_stick()
            return
        if not self._focused:
            self._latched = True  # pressed while another window has the keyboard: never drives
            return
        self._push(self.clock())

    def _driving(self) -> bool:
        return self._deadman and not self._latched and self._focused

    def _push(self, now: float) -> None:
        self._pending = False
        self._last_push = now
        ratios = stick_ratios(self._x, self._y)
        if ratios == self._pushed:
            return
        self._pushed = ratios
        self.drive.analog(*ratios)

    def _stop_stick(self) -> None:
        self._pending = False
        self._pushed = None
        self.drive.analog_release()

    def _publish(self) -> None:
        if self._device is None:
            state = PadState()
        elif not self._deadman:
            state = PadState(self._name, DeadMan.RELEASED)
        elif self._latched or self.drive.analog_blocked or not self._focused:
            state = PadState(self._name, DeadMan.LATCHED)
        else:
            state = PadState(self._name, DeadMan.HELD)
        if state != self._state:
            self._state = state
            if self.on_change is not None:
                self.on_change(state)
