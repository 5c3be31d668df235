"""The hint a still drive raises: a drive held for :data:`~rtmu.client.why_still.HINT_AFTER` s and no motion.

Fed on every tick of the window's timer: a drive is held (a drive key down in the key router, the
controller driving, or the gamepad's stick) and the robot's last status shows no speed. When
:class:`~rtmu.client.why_still.StillWhileHeld` says so — once per held drive — the selected robot is asked
"why won't it move?" (reads only) with the drive asked for, and the answer is told as a warning
banner that names the window item (``?``) where the fix is. A robot that started moving while the
answer came back is not told anything.

Also the one place that says what the window knows of its side of a drive
(:meth:`WhyContext.question`), for the why window and this hint alike.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..client.why_still import StillWhileHeld  # noqa: E402
from ..control.held_drive import ratios_for  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..model.observables import Phase, RobotModel  # noqa: E402
from ..values.intents import AskWhy  # noqa: E402
from .banners import BannerStack  # noqa: E402
from .keys import KeyRouter  # noqa: E402
from .state_words import sentence_words  # noqa: E402

if TYPE_CHECKING:  # the rules and their answer load with the first question (client.why_still)
    from ..client.why_values import Answer

TOPIC = "why"
"""The banner topic of the hint (one banner, replaced by the next hint)."""
SHOWN_FOR = 12.0


class WhyContext:
    """What the window knows of the drive: the keys held or the stick's ratios (a stick pushed a little
    asks for a drive ARIA's dead zone swallows), the link shown, a key ignored after a stop."""

    def __init__(self, robot: SelectedRobot, model: RobotModel, router: KeyRouter) -> None:
        self.robot, self.model, self.router = robot, model, router

    def held_directions(self) -> frozenset[str]:
        controller = self.robot.session.controller
        keys = {name.removeprefix("drive_") for name in self.router.held.values()}
        return frozenset(controller.held | keys)

    def driving(self) -> bool:
        """A drive is asked for now (a key down, the controller driving, the stick under its dead-man)."""
        controller = self.robot.session.controller
        return bool(self.router.held) or bool(controller.held) or controller.analog_active

    def question(self, *, navigate: bool = False) -> AskWhy:
        controller = self.robot.session.controller
        held, stick = self.held_directions(), controller.analog_ratios
        ratios = ratios_for(held, 100.0)  # keys first, as the drive itself takes them
        trans, rot = (ratios.trans, ratios.rot) if held or stick is None else stick
        connected = self.model.connection.value.phase is Phase.CONNECTED
        blocked = (
            bool(self.router.held)
            and not controller.held
            and connected
            and controller.supports("ratioDrive")
            and not controller.navigating
        )
        return AskWhy(
            navigate=navigate,
            trans=trans,
            rot=rot,
            link=self.model.health.value.level.value if connected else "down",
            keys_blocked=blocked,
        )


class WhyHint:
    """See the module notes. ``tick()`` from the window's timer."""

    def __init__(self, context: WhyContext, banners: BannerStack, clock: Callable[[], float]) -> None:
        self.context, self.banners, self.clock = context, banners, clock
        self.still = StillWhileHeld()
        self.asked = 0
        """Hints raised (each asked the robot once): for tests."""
        self.last: Answer | None = None

    def tick(self) -> None:
        ctx = self.context
        moving = ctx.model.robot.value.moving
        if not self.still.update(self.clock(), ctx.driving(), moving):
            return
        self.asked += 1
        future = ctx.robot.ask(ctx.question())
        if isinstance(future, concurrent.futures.Future):
            future.add_done_callback(lambda f: GLib.idle_add(self._answered, f))

    def _answered(self, future: concurrent.futures.Future[Any]) -> bool:
        if future.cancelled() or future.exception() is not None:
            return False
        answer: Answer = future.result()
        self.last = answer
        if self.context.model.robot.value.moving:
            return False  # it moves now: nothing to tell
        if answer.can_move:
            text = _("The robot does not move, and nothing RTMU can read says why. Why won't it move? (?)")
        else:
            text = _("Not moving: {sentence} — Why won't it move? (?) has the details.").format(
                sentence=sentence_words(answer.sentence())
            )
        self.banners.tell(TOPIC, "warning", text, timeout=SHOWN_FOR)
        return False
