"""The session's share of "why won't it move?": ask the server, carry out a fix, hear an LD robot's faults.

:class:`WhyFeed` answers :class:`~rtmu.values.intents.AskWhy` the way ``rtmu why`` does — it reads
the server's own data over the session's connection (:func:`~rtmu.client.why_gather.gather`, reads
only: looking never moves the robot) and adds our own side — the link as the window shows it, why
the last drive lease ended, whether the guardian watches, a key ignored after a stop — then
:func:`~rtmu.client.why.diagnose` says it in one sentence. Not connected, or over a link
that carries nothing now (stale, lost), the answer is our link, at once: nothing is asked over it.

:class:`~rtmu.values.intents.ApplyFix` finds the cause again from the server's data before it
sends anything (so only a fix the robot still needs is made, and the window cannot name one the
robot does not show), carries it out with :func:`~rtmu.client.why_fix.apply` — a fix that needs a
yes is sent only when the intent says the operator gave it — and answers with the new answer.

Where the robot lists ``faultsUpdate`` (an LD robot), a change of its faults is told to the
operator at once, as a safety notice: a fault is a reason it will not move. So is a login that may
not send ``stop`` (the loud reason of :func:`~rtmu.client.why.diagnose`), told on every login: the
operator must know before the first drive, not only when asking why.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import ClassVar

from ..base.i18n import _, ngettext
from ..base.notices import Kind, Notice
from ..base.textsafe import visible
from ..values.intents import ApplyFix, AskWhy, Intent
from ..values.state import LinkLevel
from .call_values import Packet
from .connection import AriaClient
from .drive_loop import DriveFeed
from .feed import Feed, FeedContext
from .subscriptions import Subscription
from .why import diagnose
from .why_fix import apply
from .why_gather import gather as gather_facts
from .why_gather import split_fields
from .why_values import Answer, Facts, Motion, OurSide

FAULTS_SHOWN = 3
"""Faults named in the notice (the why answer lists up to five, the console all of them)."""
LINK_CARRIES_NOTHING = frozenset({LinkLevel.STALE, LinkLevel.LOST})
"""Link levels at which the robot is not asked: the answer is our link, from what the login already knows."""
NOT_ASKED_OVER_A_BAD_LINK = (
    "the robot was not asked: our link carries nothing now (the login's rights are shown)"
)
HELD_ANSWER_KEPT = 60.0
"""Seconds the answer asked while a drive was held is recalled when a later question finds nothing."""


@dataclass(frozen=True, slots=True)
class FixReport:
    """What :class:`~rtmu.values.intents.ApplyFix` did, and what the robot says now."""

    key: str
    sent: bool
    worked: bool
    message: str
    answer: Answer


class WhyFeed(Feed):
    """See the module notes."""

    handles: ClassVar[tuple[type[Intent], ...]] = (AskWhy, ApplyFix)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._faults: tuple[str, ...] | None = None
        """The faults last heard on ``faultsUpdate`` (None: none heard on this connection)."""
        self._held_answer: tuple[float, Answer] | None = None
        """When and what the last question asked while a drive was held answered (None: it could move)."""

    def subscriptions(self, client: AriaClient) -> list[Subscription]:
        return [Subscription("faultsUpdate", -1, self._on_faults)]

    def connected(self, client: AriaClient) -> None:
        self._faults, self._held_answer = None, None
        for reason in diagnose(_login_facts(client)).reasons:
            if reason.loud:
                self.ctx.notice(Notice.warning(Kind.SAFETY, reason.sentence()))

    def handle(self, intent: Intent) -> object:
        if isinstance(intent, AskWhy):
            return self.ask(intent)
        assert isinstance(intent, ApplyFix)
        return self.fix(intent)

    # -- asking ------------------------------------------------------------------------------------
    def our_side(self, intent: AskWhy | None = None) -> OurSide:
        """Our own side of a drive, from the network thread (lease, guardian) and the window (the rest)."""
        client = self.ctx.client
        connected = client is not None and client.connected
        shown = intent.link if intent is not None else ""
        link = LinkLevel(shown) if shown in {level.value for level in LinkLevel} else None
        ended = self.ctx.lease.ended
        return OurSide(
            link=link if connected else LinkLevel.DOWN,
            lease_ended=ended.value if ended is not None else "",
            keys_blocked=intent.keys_blocked if intent is not None else False,
            guardian=self._guardian_missing(client) if connected else "",
        )

    def _guardian_missing(self, client: AriaClient | None) -> str:
        if not self.ctx.config.guardian or client is None or not client.supports("ratioDrive"):
            return ""
        try:
            drive = self.ctx.feed(DriveFeed)
        except LookupError:
            return ""
        reason = drive.guardian.unavailable_reason
        return "" if reason is None else f"it is not running ({reason})"

    async def ask(self, intent: AskWhy) -> Answer:
        ours = self.our_side(intent)
        client = self.ctx.client
        if client is None or not client.connected:
            return diagnose(Facts(ours=ours), navigate=intent.navigate)
        if ours.link in LINK_CARRIES_NOTHING:  # asking over it would only wait out each reply's timeout
            unasked = _login_facts(client, ours, NOT_ASKED_OVER_A_BAD_LINK)
            return diagnose(unasked, navigate=intent.navigate)
        facts = await gather_facts(client, self.ctx.config.reply_timeout, ours)
        motion = Motion(intent.trans, intent.rot) if intent.trans or intent.rot else None
        return self._recall(diagnose(facts, motion, navigate=intent.navigate), held=motion is not None)

    def _recall(self, answer: Answer, *, held: bool) -> Answer:
        """Keep the answer asked while a drive was held; add it as a note to a later one that finds
        nothing. Some causes show only while the drive is held — ARIA's drive mode says "Stalled",
        and letting go switches to the stop mode, which does not — so the operator who lets go and
        then asks is still told what the hint found (as what was read then, not as a cause now)."""
        now = time.monotonic()
        if held:
            self._held_answer = None if answer.can_move else (now, answer)
            return answer
        earlier = self._held_answer
        if earlier is None or not answer.can_move or now - earlier[0] > HELD_ANSWER_KEPT:
            return answer
        note = f"while the drive was held {now - earlier[0]:.0f} s ago: {earlier[1].sentence()}"
        return replace(answer, notes=(*answer.notes, note))

    # -- fixing ------------------------------------------------------------------------------------
    async def fix(self, intent: ApplyFix) -> FixReport:
        client = self.require()
        timeout = self.ctx.config.reply_timeout
        ours = self.our_side()
        facts = await gather_facts(client, timeout, ours)
        answer = diagnose(facts, navigate=intent.navigate)
        reason = next((r for r in answer.reasons if r.fix is not None and r.fix.key == intent.key), None)
        if reason is None or reason.fix is None:
            said = "not sent: the robot no longer shows what this fix is for"
            return FixReport(intent.key, False, False, said, answer)
        result = await apply(client, reason.fix, facts, lambda _question: intent.confirmed, timeout)
        after = diagnose(await gather_facts(client, timeout, ours), navigate=intent.navigate)
        return FixReport(intent.key, result.sent, result.worked, result.message, after)

    # -- an LD robot's faults ------------------------------------------------------------------------
    def _on_faults(self, packet: Packet) -> None:
        fields = split_fields(packet.payload)
        if packet.payload and not fields:
            return  # a layout RTMU cannot read safely: the why answer shows it raw
        faults = tuple(f for f in fields if f.strip())
        if faults == self._faults or (not faults and self._faults is None):
            self._faults = faults
            return
        self._faults = faults
        if not faults:
            self.ctx.notice(Notice.info(Kind.SAFETY, _("The robot reports no faults any more.")))
            return
        shown = "; ".join(visible(f[:100]) for f in faults[:FAULTS_SHOWN])
        more = (
            _(" (+{count} more)").format(count=len(faults) - FAULTS_SHOWN)
            if len(faults) > FAULTS_SHOWN
            else ""
        )
        self.ctx.notice(
            Notice.warning(
                Kind.SAFETY,
                ngettext(
                    "The robot reports {count} fault: {faults}{more}. "
                    "Why won't it move? (key ?) says what to do.",
                    "The robot reports {count} faults: {faults}{more}. "
                    "Why won't it move? (key ?) says what to do.",
                    len(faults),
                ).format(count=len(faults), faults=shown, more=more),
            )
        )


def _login_facts(client: AriaClient, ours: OurSide | None = None, *notes: str) -> Facts:
    """What the login itself tells, with no request sent: this user's rights (its data list)."""
    offers = frozenset(e.name for e in client.datalist)
    return Facts(offers=offers, user=client.user, ours=ours or OurSide(), notes=notes)
