"""Operator intents → client calls, with the robot's safety rules in one place.

The controller runs on the UI thread. It is GTK-free: it talks to the window
through the small :class:`~rtmu.control.ports.View` protocol and to the network through
:class:`~rtmu.control.ports.ClientLink` (implemented by ``rtmu.client.ClientRunner``), and reads
time from an injected clock, so every rule below is tested without a display.

Driving rules
-------------
* Held keys and a gamepad's stick drive on one lease, only while held (``held_drive``: the
  press / release / stick rules, blocked keys, the curve, the throttle). :meth:`Controller.tick`,
  called by the UI's own timer every :data:`~rtmu.control.held_drive.TICK` seconds, renews it.
* :meth:`stop` always wins and is always sent, even when the link looks stale.
* Focus loss, disconnect, a stale or lost link, and a lapsed lease (the UI froze
  for more than 300 ms) stop the robot; keys (and the stick) held at that moment stay
  blocked until released (``held_drive``).
* Speed: 10…100 % in 10 % steps; it is the ``ratioDrive`` throttle and applies at
  once to a drive in progress. The operator's near-people cap (``OperatorState.near_people``)
  lowers that throttle so a full drive stays under it, from the robot's top speed
  (``motion_limits``: the server's own, else ARIA's P3-DX maximum, raised by any faster speed seen).
* Every jog (Turn, Go) ends with its outcome said (``jog_watch``): arrived, stopped short and why,
  or ended by a stop, a drive or a navigation.

Navigation rules (the server drives: ARNL's goals, points, home, dock, tours)
-----------------------------------------------------------------------------
* The operator always wins. :meth:`stop` cancels a navigation (its ``stop`` goes
  out at once, as always). A drive key pressed while the server navigates does
  not steer: it sends the stop and nothing else, and stays blocked until released;
  the next press drives as usual.
* Sending the robot somewhere ends a held drive first (the network side sends the
  stop before the goal), so the next ``ratioDrive`` cannot take it back.
* Navigation is autonomy on the server: focus loss, a stale link or a lapsed lease
  end *held drives* only, never a navigation (disconnecting still stops the robot).
* Looking never stops a mission: changing page (map ⇄ camera) or opening a dialog (Turn, Go, the
  server's commands) ends a held drive — its keys go elsewhere — but never a navigation, and
  is no stop key (:meth:`look`). Only STOP, Space and the drive keys cancel a navigation.
* No drive starts or goes on while the stop key cannot reach the window (:meth:`focus_lost` until
  :meth:`focus_gained` or a key press): a D-pad press then is refused, saying why
  (:meth:`pointer_may_drive`).
* While the robot scans for a map, every intent that would move it on its own (a goal, a jog, a
  patrol, a server command that may drive) is refused with the reason (``scan_rule``); held drives
  and STOP go on as always.
* Every stop the controller makes is said once, with what to do next.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from ..base.i18n import N_, _
from ..base.notices import Kind, Level, Notice
from ..client.lease import EndReason
from ..model.observables import OperatorState, RobotModel, SpeedSetting
from ..settings.store import Profile
from ..values.intents import GotoGoal, Intent, RequestPicture, StartVideo, Stop, picture_source
from ..values.state import ConnectionState, LinkHealth, LinkLevel, NavState, Phase, RobotState
from ..values.target import Target
from . import intent_rules
from .commands import COMMANDS, CommandRegistry, CommandState
from .held_drive import HeldDrive
from .motion_limits import RobotLimits
from .motion_watch import MotionWatch
from .password_lookup import PasswordLookup
from .ports import ClientLink, NoView, SecretStore, View
from .scan_rule import scan_refusal

REPLAY_REASON = N_("Replay — nothing is sent to a robot")
KEYBOARD_LOST = N_("the window lost the keyboard")
"""Why a held drive stops on a focus loss (a suspend names its own reason)."""


class Controller:
    """See the module notes. One per robot session; call everything from the UI thread.

    ``robot`` is the robot's state, ``operator`` the speed and view choices of the window
    (shared by every robot it shows); ``view`` may be replaced when another window shows it.
    """

    def __init__(
        self,
        robot: RobotModel,
        operator: OperatorState,
        link: ClientLink,
        view: View,
        *,
        clock: Callable[[], float] = time.monotonic,
        registry: CommandRegistry = COMMANDS,
        secrets: SecretStore | None = None,
        profile: Profile | None = None,
    ) -> None:
        self.robot = robot
        self.operator = operator
        self.link = link
        self.view = view
        self.clock = clock
        self.registry = registry
        self.secrets = secrets
        self.profile = profile or Profile()
        self._states: dict[str, CommandState] = {}
        self._nav_cancelled = False
        """We sent the stop that ends the current navigation; the server has not said so yet."""
        self.tap: Callable[[str, dict[str, Any]], None] | None = None
        """The flight recorder's tap: every intent sent, and every connect (without its password)."""
        self.drive = HeldDrive(self)
        """The keys held, the stick and the lease they share (``held_drive``)."""
        self.passwords = PasswordLookup(self, self._start_connect, self._busy_connecting)
        """The password step of :meth:`connect` (``password_lookup``)."""
        self.motion = MotionWatch(link, lambda n: self.view.notify(n), self.drive.reapply, clock)
        """The robot's limits (the cap, the stopping distance) and how each jog ended."""
        self.replay: str | None = None
        """Set to the recording's name while the window shows a replay: then nothing is sent at all
        (drive keys, D-pad, STOP and every server command say "replay"), and no lease is granted."""
        self.drive_gate: Callable[[], str | None] | None = None
        """Why a held drive may not start now (None: it may), asked on each first press: the window's
        guardian not yet armed for this robot (``rtmu.guardian.shared.GuardianSeat.waiting_reason``)."""
        link.on_notice = self._on_link_notice
        self._unobserve = [
            robot.connection.observe(self._on_connection),
            robot.health.observe(self._on_health),
            robot.navigation.observe(self._on_navigation),
            robot.robot.observe(self._on_robot),
            operator.near_people.observe(lambda _old, _new: self.drive.reapply()),
        ]
        self.refresh_commands()

    def close(self) -> None:
        """Unhook from the model and the link (after the robot was stopped); idempotent."""
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        if self.link.on_notice == self._on_link_notice:
            self.link.on_notice = None
        self.view = NoView()

    # -- CommandContext ----------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self.robot.connection.value.connected

    def supports(self, name: str) -> bool:
        return self.robot.connection.value.supports(name)

    def connection_phase(self) -> Phase:
        return self.robot.connection.value.phase

    def image_source(self) -> str | None:
        """The data a picture is requested with (:func:`~rtmu.client.video_feed.picture_source`)."""
        return picture_source(self.robot.connection.value.offers)

    # -- commands ----------------------------------------------------------------------------
    def run(self, name: str) -> bool:
        """Run (or, for hold commands, press) command ``name``; False if it is disabled."""
        cmd = self.registry.get(name)
        reason = REPLAY_REASON if self.replay and cmd.needs_connection else cmd.unavailable(self)
        if reason is not None:
            self.view.notify(
                Notice.warning(
                    Kind.COMMAND, _("{command}: {reason}").format(command=_(cmd.label), reason=_(reason))
                )
            )
            return False
        cmd.activate(self)
        return True

    def release_command(self, name: str) -> None:
        """Key of a hold command released (always honoured, even if the command became disabled)."""
        cmd = self.registry.get(name)
        if cmd.hold:
            cmd.deactivate(self)

    def command_states(self) -> dict[str, CommandState]:
        return dict(self._states)

    def refresh_commands(self) -> None:
        """Recompute every command's state and tell the view about those that changed."""
        states = self.registry.states(self)
        if self.replay:  # a replay sends nothing: every command that would is shown disabled, saying why
            off = CommandState(False, REPLAY_REASON)
            states = {k: off if self.registry.get(k).needs_connection else v for k, v in states.items()}
        changed = {k: v for k, v in states.items() if self._states.get(k) != v}
        self._states = states
        if changed:
            self.view.commands_changed(changed)

    # -- held motion (``held_drive``) ----------------------------------------------------------
    @property
    def held(self) -> frozenset[str]:
        return self.drive.held

    def press(self, direction: str) -> None:
        self.drive.press(direction)

    def release(self, direction: str) -> None:
        self.drive.release(direction)

    @property
    def analog_active(self) -> bool:
        """The stick is being listened to (dead-man held, not blocked by a stop)."""
        return self.drive.analog_active

    @property
    def analog_ratios(self) -> tuple[float, float] | None:
        """The stick's (trans, rot) in % while its dead-man is held (what "why?" asks about)."""
        return self.drive.analog_ratios

    @property
    def analog_blocked(self) -> bool:
        """A stop ended the stick's drive: the dead-man must be released before it drives again."""
        return self.drive.analog_blocked

    def analog(self, trans: float, rot: float) -> None:
        """The stick while the dead-man is held: trans/rot in −100…100 % (rot positive = left)."""
        self.drive.analog(trans, rot)

    def analog_release(self) -> None:
        """The dead-man was let go (or the pad is gone): stop the stick's drive; it may drive again."""
        self.drive.analog_release()

    @property
    def keys_reach(self) -> bool:
        """The window has the keyboard, so the stop key reaches it (False from focus loss to focus gain)."""
        return self.drive.keys_reach

    @keys_reach.setter
    def keys_reach(self, reach: bool) -> None:
        self.drive.keys_reach = reach

    @property
    def needs_tick(self) -> bool:
        """Keys, the stick or a live lease drive, or a jog is watched: :meth:`tick` is needed."""
        return self.drive.needs_renewal or self.motion.jogs.jog is not None

    def tick(self) -> None:
        """Renew the lease while keys are held; end a watched jog that is over. Call every
        :data:`~rtmu.control.held_drive.TICK` s from the UI thread's timer."""
        self.motion.tick(self.robot.robot.value)
        self.drive.renew()

    def stop(self) -> None:
        """Stop now. Always sent, whatever the link looks like; held keys must be pressed again.

        Also ends a navigation: the server's ``stop`` mode takes over from its goal. A replay has no
        robot to stop: it says so and sends nothing."""
        if self.replay:
            self.drive.halt(EndReason.STOPPED)
            self.say_replay()
            return
        if self.navigating:
            self._nav_cancelled = True
        self._end_jog("STOP")
        self.drive.halt(EndReason.STOPPED)
        self.link.lease.end(EndReason.STOPPED)
        if self.robot.connection.value.phase in (Phase.CONNECTED, Phase.RECONNECTING, Phase.CONNECTING):
            self._record(Stop())
            self.link.send(Stop())

    def focus_lost(self, why: str = KEYBOARD_LOST) -> None:
        """The window lost keyboard focus: key releases may never arrive, so stop a held drive.

        A navigation goes on: the server drives it, no key is held for it.

        Keys held now stay blocked until a real release is seen after focus returns (see the
        module notes): auto-repeat of a key held all along must not start the robot again.
        """
        if self.drive.driving:
            self.stop()
            then = _("Click the map, then press again") if why == KEYBOARD_LOST else _("Press again")
            self.view.notify(
                Notice.stopped(
                    Kind.SAFETY, _("Stopped: {why}. {then} to drive.").format(why=_(why), then=then)
                )
            )
        self.drive.keys_lost()

    def focus_gained(self) -> None:
        """The window has the keyboard again: releases from now on are real (optional for a view)."""
        self.drive.keys_back()

    def pointer_may_drive(self) -> bool:
        """A D-pad (pointer, touch) hold may start only while the stop key reaches the window: else it
        is refused, saying why (a key press proves the keyboard is here; a pointer press does not)."""
        if not self.keys_reach:
            said = _(
                "Not driving: Space could not stop it, the keyboard is elsewhere. Click the map, then drive."
            )
            self.view.notify(Notice.warning(Kind.SAFETY, said))
        return self.keys_reach

    def look(self, what: str, *, keys_leave: bool = False) -> None:
        """The operator looks elsewhere (``what``: "the camera page", "a dialog", "the menu"): a held
        drive ends, its keys blocked until released, and says so; a navigation goes on, and nothing is
        sent for it. ``keys_leave``: the keyboard goes to another surface of the window (a menu), so
        key-ups seen until the next press are not real ones (as after a focus loss)."""
        if self.drive.holding:
            self.drive.halt(EndReason.STOPPED)
            self.view.notify(
                Notice.stopped(
                    Kind.SAFETY, _("Stopped for {what}. Press again to drive.").format(what=what), Level.INFO
                )
            )
        if keys_leave:
            self.drive.keys_left()

    # -- speed -------------------------------------------------------------------------------
    def speed_up(self) -> None:
        self._set_speed(self.operator.speed.value.faster(), "maximum")

    def speed_down(self) -> None:
        self._set_speed(self.operator.speed.value.slower(), "minimum")

    def _set_speed(self, new: SpeedSetting, limit: str) -> None:
        if not self.operator.speed.set(new):
            self.view.notify(
                Notice.info(
                    Kind.SPEED_LIMIT,
                    (
                        _("Speed is already at its maximum ({percent} %)")
                        if limit == "maximum"
                        else _("Speed is already at its minimum ({percent} %)")
                    ).format(percent=new.percent),
                )
            )
            return
        self.view.notify(Notice.info(Kind.SPEED, _("Speed {percent} %").format(percent=new.percent)))
        self.drive.reapply()

    # -- every other intent: the guard ---------------------------------------------------------
    def ask(self, intent: Intent) -> Any:
        """Send one operator intent to this robot, after the rules that hold for every intent.

        Refused, with the reason shown, in a replay, while not connected (for an intent that needs
        the server), where the server does not offer it, where ``intent_rules`` refuses it (a
        console motion request or a fix the operator has not confirmed), and — for one that moves the
        robot — while it scans for a map (``scan_rule``). An intent that moves the robot ends a held
        drive first (the network side sends its stop before the intent), and a new goal makes drive
        keys drive again once the server has taken it. Returns what ``link.send`` returns (a Future
        of the answer), or None when refused. STOP has its own path: :meth:`stop`."""
        if isinstance(intent, Stop):
            self.stop()
            return None
        if self.replay:
            self.say_replay()
            return None
        offers = self.robot.connection.value.offers
        if (intent.needs or intent.moves or not intent.offered(())) and not self.connected:
            self.view.notify(
                Notice.warning(intent.kind, _("{label}: not connected").format(label=intent.label))
            )
            return None
        if not intent.offered(offers):
            missing = (
                _("offer {value}").format(value=intent.needs[0])
                if intent.needs
                else _("offer {lower}").format(lower=intent.label.lower())
            )
            if isinstance(intent, (RequestPicture, StartVideo)):
                missing = _("offer camera pictures")
            self.view.notify(
                Notice.warning(intent.kind, _("This server does not {missing}").format(missing=missing))
            )
            return None
        refusal = scan_refusal(intent, self.robot.scan.value)  # while scanning: only held drives move it
        if refusal is not None:
            self.view.notify(Notice.warning(intent.kind, refusal))
            return None
        goals = self.robot.navigation.value.goals
        if isinstance(intent, GotoGoal) and goals and intent.name not in goals:
            self.view.notify(
                Notice.warning(
                    Kind.NAVIGATION, _("This map has no goal called {name!r}").format(name=intent.name)
                )
            )
            return None
        refused = intent_rules.refusal(intent)  # a console call of a motion request, a fix, unconfirmed
        if refused is not None:
            self.view.notify(Notice.warning(intent.kind, f"{intent.label}: {refused}"))
            return None
        moving = intent_rules.moves(intent)
        if moving:
            self.drive.halt(EndReason.STOPPED)  # the network side sends its stop before the intent
            self._nav_cancelled = False
        self._record(intent)
        sent = self.link.send(intent)
        if moving:
            self.motion.intent_sent(intent, self.robot.robot.value)  # a jog is watched to its outcome
            if self.motion.jogs.jog is not None:
                self.view.driving()  # a still robot's numbers change nothing: the tick finds its end
        return sent

    def _record(self, intent: Intent) -> None:
        tap = self.tap
        if tap is not None:
            with contextlib.suppress(Exception):  # recording never stands between operator and robot
                tap(type(intent).__name__, intent.record())

    # -- navigation (the server drives) --------------------------------------------------------
    @property
    def navigating(self) -> bool:
        """The server navigates now, and we have not already sent the stop that ends it."""
        return self.robot.navigation.value.navigating and not self._nav_cancelled

    def _on_navigation(self, old: NavState, new: NavState) -> None:
        if not new.navigating or (old.navigating and new.target != old.target):
            self._nav_cancelled = False  # it ended (or someone sent it elsewhere): keys drive again

    def say_replay(self) -> None:
        """Say that a replay sends nothing (the operator asked something of a recording)."""
        self.view.notify(Notice.warning(Kind.SAFETY, f"{_(REPLAY_REASON)}: {self.replay}"))

    # -- connection --------------------------------------------------------------------------
    def select_profile(self, profile: Profile) -> None:
        """Use ``profile`` for the next connect and restore the view and speed it was left with."""
        self.profile = profile
        with contextlib.suppress(ValueError):
            self.operator.speed.set(SpeedSetting(profile.speed))
        self.operator.view.update(
            zoom=profile.zoom, follow_robot=profile.follow_robot, show_sonar=profile.show_sonar
        )

    def current_profile(self) -> Profile:
        """The profile with the view options and speed as they are now (save it on exit)."""
        v = self.operator.view.value
        return replace(
            self.profile,
            zoom=v.zoom,
            follow_robot=v.follow_robot,
            show_sonar=v.show_sonar,
            speed=self.operator.speed.value.percent,
        )

    def connect(self, password: str | None = None) -> None:
        """Connect with the current profile; asks the view for the password when none is known.

        A remembered password is looked up off the UI thread (a keyring may block on D-Bus or
        an unlock prompt) when the link offers ``run_blocking``; the connection starts when
        the answer comes back, unless the profile changed meanwhile.
        """
        profile = self.profile
        if self._busy_connecting():
            return
        if password is None and profile.user:
            self.passwords.find(profile)
            return
        self._start_connect(password or "")

    def _busy_connecting(self) -> bool:
        phase = self.robot.connection.value.phase
        return self.passwords.pending or phase in (Phase.CONNECTING, Phase.CONNECTED, Phase.RECONNECTING)

    def _start_connect(self, password: str) -> None:
        p = self.profile
        self.drive.halt(EndReason.DISCONNECTED)
        tap = self.tap
        if tap is not None:
            with contextlib.suppress(Exception):
                tap("connect", {"host": p.host, "port": p.port, "user": p.user, "profile": p.name})
        self.link.connect(
            Target(p.host, p.port, p.user, password, profile=p.name, auto_reconnect=p.auto_reconnect,
                   protocol=p.protocol or None)
        )  # fmt: skip

    def disconnect(self) -> None:
        self.stop()
        tap = self.tap
        if tap is not None:
            with contextlib.suppress(Exception):
                tap("disconnect", {})
        self.link.disconnect()

    # -- dialogs -----------------------------------------------------------------------------
    def open_dialog(self, name: str) -> None:
        """A dialog a command needs (``turn``, ``go``: an amount; ``commands``: the palette).

        Opening one is looking (:meth:`look`): it takes the keyboard, so a held drive ends — a Turn or
        Go jog would take over from it anyway — but a navigation goes on until the operator runs what
        the dialog asks, or presses STOP (the dialog carries the stop keys)."""
        self.look(_("a dialog"))
        self.view.open_dialog(name)

    @property
    def limits(self) -> RobotLimits:
        """The robot's top speed and braking (``motion_limits``): the cap and the stopping distance."""
        return self.motion.limits

    def _on_robot(self, _old: RobotState, new: RobotState) -> None:
        self.motion.robot_changed(new, self.link.lease.view().ratios if self.drive.granted else None)

    def _end_jog(self, why: str) -> None:
        self.motion.end_jog(why, self.robot.robot.value)

    # -- reactions to the model --------------------------------------------------------------
    def _on_connection(self, old: ConnectionState, new: ConnectionState) -> None:
        if new.phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED:
            self.motion.connected(self.supports, ask=not self.replay)  # a replay asks a recording nothing
        elif new.phase is not Phase.CONNECTED and old.phase is Phase.CONNECTED:
            self.motion.disconnected()
        if new.phase is not Phase.CONNECTED and old.phase is Phase.CONNECTED:
            self.drive.halt(EndReason.DISCONNECTED)
        if new.phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED:
            self.view.notify(
                Notice.info(
                    Kind.CONNECTION, _("Connected to {host}:{port}").format(host=new.host, port=new.port)
                )
            )
        elif new.phase is Phase.FAILED and new.error and new.error != old.error:
            self.view.notify(Notice.error(Kind.CONNECTION, new.error))
        elif new.phase is Phase.RECONNECTING and old.phase is Phase.CONNECTED:
            self.view.notify(
                Notice.warning(
                    Kind.CONNECTION,
                    _("Link lost: reconnecting ({error})").format(error=new.error)
                    if new.error
                    else _("Reconnecting"),
                )
            )
        self.refresh_commands()

    def _on_health(self, old: LinkHealth, new: LinkHealth) -> None:
        if new.level in (LinkLevel.STALE, LinkLevel.LOST) and old.level is LinkLevel.OK:
            moving = self.drive.driving
            self.drive.halt(EndReason.LINK, quiet=True)
            if moving:
                self.link.send(Stop("link " + new.level.value))
                self.drive.say_link_stop(new.level)

    def _on_link_notice(self, notice: Notice) -> None:
        self.view.notify(notice)
