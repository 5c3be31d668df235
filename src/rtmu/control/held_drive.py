"""Held motion: drive keys and a gamepad's stick (under its dead-man) → one drive lease.

* ``press(direction)`` / ``release(direction)``: move only **while held**. The
  first press grants a drive lease (``rtmu.client.lease``); :meth:`HeldDrive.renew`, called
  by the UI's own timer every :data:`TICK` seconds, renews it while keys are
  held; the network side resends ``ratioDrive`` at 10 Hz while the lease is
  fresh. Two held directions combine into a curve (forward+left = forward with
  half rotation); opposite directions cancel. Releasing the last key sends zero
  ratios and ``stop``.
* Keys still held when motion is stopped (focus loss, disconnect, a stale or lost
  link, a lapsed lease) are *blocked* until released: the robot stays still until a
  fresh key press — also after a reconnect, and also after focus comes back: a key
  held through the focus loss auto-repeats as presses, which must not restart
  motion. While the window is unfocused no real key release can arrive, so
  releases then (a window "releasing everything" on focus loss) do not unblock;
  the first press after focus returns marks the window focused again (a key
  released while unfocused therefore needs one press to clear it, then a fresh press).
* ``analog(trans, rot)`` / ``analog_release()``: a gamepad's stick while its
  dead-man button is held (``rtmu.control.gamepad`` turns pad events into these). It rides
  the SAME lease as the keys (held keys win over the stick while both are held);
  every stop blocks the stick too, until the dead-man is released and pressed again.
* A key pressed while the server navigates does not steer: it stops the navigation
  (the controller's ``stop``) and stays blocked until released.
* Speed is the ``ratioDrive`` throttle and applies at once to a drive in progress, capped
  for the near-people setting from the robot's limits (``motion_limits``).

The rules of when motion may start at all (replay, connection, navigation, the drive gate)
are the controller's, read through :class:`DriveHost`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from ..base.i18n import _, words
from ..base.notices import Kind, Notice
from ..client.lease import DriveRatios, EndReason
from ..model.observables import OperatorState, RobotModel
from ..values.state import LinkLevel
from .motion_limits import capped_throttle
from .motion_watch import MotionWatch
from .ports import ClientLink, View

TICK = 0.1
"""Seconds between :meth:`~rtmu.control.controller.Controller.tick` calls the UI timer should make
(10 Hz renewal)."""
CURVE_ROT = 50.0
"""Rotation ratio (%) used when a turn key is held together with forward or backward."""

DIRECTIONS = ("forward", "backward", "left", "right")


def ratios_for(held: set[str] | frozenset[str], throttle: float) -> DriveRatios:
    """The ``ratioDrive`` for a set of held directions (empty or cancelling → zero motion)."""
    trans = 100.0 * (("forward" in held) - ("backward" in held))
    rot = 100.0 * (("left" in held) - ("right" in held))
    if trans and rot:
        rot = CURVE_ROT if rot > 0 else -CURVE_ROT
    return DriveRatios(trans, rot, float(throttle))


class DriveHost(Protocol):
    """What a held drive reads of its controller at each step (the window may swap its view)."""

    view: View
    link: ClientLink
    robot: RobotModel
    operator: OperatorState
    motion: MotionWatch
    replay: str | None
    drive_gate: Callable[[], str | None] | None

    @property
    def connected(self) -> bool: ...

    @property
    def navigating(self) -> bool: ...

    def supports(self, name: str) -> bool: ...

    def stop(self) -> None: ...

    def say_replay(self) -> None: ...


class HeldDrive:
    """The keys held, the keys blocked, the stick, and the lease they share. UI thread only."""

    def __init__(self, host: DriveHost) -> None:
        self._host = host
        self._held: set[str] = set()
        self._blocked: set[str] = set()
        """Keys that were held when motion was stopped for them; ignored until released."""
        self._analog: tuple[float, float] | None = None
        """The gamepad stick (trans, rot in %) while its dead-man is held; None when let go."""
        self._analog_blocked = False
        """The stick drove (or was held) when motion was stopped: ignored until the dead-man is released."""
        self._generation: int | None = None
        self._unfocused = False
        """Between focus loss and the next key press: releases seen then are not real key-ups."""
        self.keys_reach = True
        """The window has the keyboard, so the stop key reaches it (False from focus loss to focus gain)."""

    # -- what is held --------------------------------------------------------------------------
    @property
    def held(self) -> frozenset[str]:
        return frozenset(self._held)

    @property
    def granted(self) -> bool:
        """A lease was granted for the keys or the stick and not yet ended."""
        return self._generation is not None

    @property
    def driving(self) -> bool:
        """Keys are held, or a lease is granted."""
        return bool(self._held) or self._generation is not None

    @property
    def holding(self) -> bool:
        """Keys are held, or the stick drives."""
        return bool(self._held) or (self._analog is not None and self._generation is not None)

    @property
    def analog_active(self) -> bool:
        """The stick is being listened to (dead-man held, not blocked by a stop)."""
        return self._analog is not None

    @property
    def analog_ratios(self) -> tuple[float, float] | None:
        """The stick's (trans, rot) in % while its dead-man is held; None when let go."""
        return self._analog

    @property
    def analog_blocked(self) -> bool:
        """A stop ended the stick's drive: the dead-man must be released before it drives again."""
        return self._analog_blocked

    @property
    def needs_renewal(self) -> bool:
        """Keys, the stick or a live lease drive: :meth:`renew` is needed."""
        return bool(self._held or self._analog is not None or self._host.link.lease.view().live)

    # -- keys ----------------------------------------------------------------------------------
    def press(self, direction: str) -> None:
        if direction not in DIRECTIONS:
            raise ValueError(f"unknown direction {direction!r}")
        host = self._host
        self._unfocused = False  # key presses reach a focused window only
        self.keys_reach = True
        if direction in self._held or direction in self._blocked:
            return  # key auto-repeat, or a key held through a stop: wait for its release
        if host.replay:
            self._blocked.add(direction)
            host.say_replay()
            return
        if not host.connected or not host.supports("ratioDrive"):
            self._blocked.add(direction)
            return
        if host.navigating:  # the operator wins: this press only stops the navigation
            host.stop()
            self._blocked.add(direction)
            host.view.notify(Notice.info(Kind.NAVIGATION, _("Navigation cancelled. Press again to drive.")))
            return
        if self._gate_refuses():
            self._blocked.add(direction)
            return
        self._held.add(direction)
        self._apply()

    def _gate_refuses(self) -> bool:
        """The drive gate says no: tell the operator why (the key must be pressed again)."""
        gate = self._host.drive_gate
        why = gate() if gate is not None else None
        if why is not None:
            said = _("Not driving: {why} Press again once it is armed.").format(why=why)
            self._host.view.notify(Notice.warning(Kind.SAFETY, said))
        return why is not None

    def release(self, direction: str) -> None:
        if not self._unfocused:  # a real key-up: the key may drive again on its next press
            self._blocked.discard(direction)
        if direction not in self._held:
            return
        self._held.discard(direction)
        self._apply()

    # -- the stick (a gamepad's, under its dead-man) -------------------------------------------
    def analog(self, trans: float, rot: float) -> None:
        """The stick while the dead-man is held: trans/rot in −100…100 % (rot positive = left).

        The first call grants the lease like a key press; later ones change its ratios. Ignored
        while blocked (after any stop) until :meth:`analog_release`."""
        host = self._host
        if self._analog_blocked:
            return
        if not host.connected or not host.supports("ratioDrive"):
            self._analog_blocked = True
            return
        if host.navigating and (trans or rot):  # the operator wins: this only stops the navigation
            host.stop()
            self._analog_blocked = True
            host.view.notify(Notice.info(Kind.NAVIGATION, _("Navigation cancelled. Press again to drive.")))
            return
        if self._analog is None and (trans or rot) and self._gate_refuses():
            self._analog_blocked = True
            return
        self._analog = (max(-100.0, min(100.0, trans)), max(-100.0, min(100.0, rot)))
        self._apply()

    def analog_release(self) -> None:
        """The dead-man was let go (or the pad is gone): stop the stick's drive; it may drive again."""
        self._analog_blocked = False
        if self._analog is None:
            return
        self._analog = None
        self._apply()

    # -- focus ---------------------------------------------------------------------------------
    def keys_lost(self) -> None:
        """The window lost the keyboard: what is held now stays blocked until a real release."""
        if self._analog is not None:
            self._analog = None
            self._analog_blocked = True
        self._blocked |= self._held
        self._held.clear()
        self._unfocused = True
        self.keys_reach = False

    def keys_back(self) -> None:
        """The window has the keyboard again: releases from now on are real."""
        self._unfocused = False
        self.keys_reach = True

    def keys_left(self) -> None:
        """The keyboard went to another surface of the window: key-ups until the next press are not real."""
        self._unfocused = True

    # -- the lease -----------------------------------------------------------------------------
    def renew(self) -> None:
        """Renew the lease while keys (or the stick) drive; a lease that cannot be renewed halts them."""
        if not self._held and (self._analog is None or self._generation is None):
            return
        lease = self._host.link.lease
        if not lease.renew():
            self.halt(lease.ended or EndReason.LAPSED)

    def _apply(self) -> None:
        host = self._host
        speed = capped_throttle(
            host.operator.speed.value.percent, host.operator.near_people.value.cap, host.motion.limits
        )
        if self._held or self._analog is None:
            ratios = ratios_for(self._held, speed)
        else:
            ratios = DriveRatios(self._analog[0], self._analog[1], float(speed))
        lease = host.link.lease
        if not ratios.moving:
            if self._generation is not None:
                lease.release()
                self._generation = None
            return
        if self._generation is None or not lease.change(ratios):
            if self._generation is not None:
                # The lease died under us (lapsed/stale); the keys pressed before are stale too.
                self.halt(lease.ended or EndReason.LAPSED)
                return
            host.motion.end_jog(_("a drive"), host.robot.robot.value)
            self._generation = lease.grant(ratios)
            host.view.driving()

    def reapply(self) -> None:
        """The cap or the robot's limits changed: a drive in progress takes the new throttle at once."""
        if (self._held or self._analog is not None) and self._generation is not None:
            self._apply()

    def halt(self, reason: EndReason, *, quiet: bool = False) -> None:
        """Motion was stopped for ``reason`` while keys were held: block them until released.

        A lease the network side ended for the link (its drive loop sees a stale link before the
        model's health reaches this thread) is said here, so the operator hears it whichever
        side noticed first; ``quiet`` where the caller says it itself."""
        had = self.holding
        self._blocked |= self._held
        self._held.clear()
        if self._analog is not None:
            self._analog = None
            self._analog_blocked = True
        lease = self._host.link.lease
        if self._generation is not None:
            lease.end(reason, self._generation)
            self._generation = None
        if had and reason is EndReason.LAPSED:
            why = lease.why or _("a busy computer?")
            text = _("Stopped: the window did not respond in time ({why})").format(why=why)
            self._host.view.notify(
                Notice.stopped(Kind.SAFETY, _("{text}. Press again to drive.").format(text=text))
            )
        elif had and reason is EndReason.LINK and not quiet:
            level = self._host.robot.health.value.level
            self.say_link_stop(level if level in (LinkLevel.STALE, LinkLevel.LOST) else LinkLevel.STALE)

    def say_link_stop(self, level: LinkLevel) -> None:
        """Said once per stop, with the network side's measured cause where it gave one."""
        host = self._host
        why = host.link.lease.why or host.robot.health.value.cause
        said = f" — {words(why)}" if why else _(". Press again once it is back.")
        host.view.notify(
            Notice.stopped(
                Kind.LINK, _("Stopped: the link is {value}{said}").format(value=_(level.value), said=said)
            )
        )
