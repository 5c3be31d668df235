"""One capability of a session: what it subscribes to, what it does per connection, which intents it handles.

Every capability of the network side — status, navigation, the map, popups, the camera head, live
video, drawings, configuration, the server's commands, driving itself — is a :class:`Feed`, built
the same way (``Feed(ctx)``) with the one :class:`FeedContext` its session gives it. The session
makes each feed's :meth:`Feed.subscriptions` on every connection, calls :meth:`Feed.connected` and
:meth:`Feed.disconnected`, and hands every operator intent (:mod:`rtmu.values.intents`) to the feed
whose :attr:`Feed.handles` names its type. A new capability is one more feed (and its intents):
nothing else in the session changes (``SessionConfig.extra_feeds``).

Everything here runs on the network thread's loop, and must stay cheap there: decoding is a few
microseconds a packet, slow work goes to executors, results leave as typed state changes.
"""

from __future__ import annotations

from collections.abc import Callable, Coroutine, Iterable
from typing import Any, ClassVar, Protocol, TypeVar

from ..base.notices import Notice
from ..values.intents import Intent
from ..values.state import MapModel, RobotState, StateChange
from ..values.target import Target
from .connection import AriaClient
from .errors import NotSupported, ServerClosed
from .lease import DriveLease
from .session_config import SessionConfig
from .subscriptions import Handler, Subscription

F = TypeVar("F", bound="Feed")


class FeedContext(Protocol):
    """What a feed may use of its session (the session is the one implementation)."""

    config: SessionConfig
    clock: Callable[[], float]
    lease: DriveLease
    """The drive lease the UI grants and renews (the drive loop turns it into ``ratioDrive``)."""

    @property
    def client(self) -> AriaClient | None:
        """This connection's client (None between connections)."""

    @property
    def target(self) -> Target | None:
        """Where the session connects (None when it was told to disconnect)."""

    @property
    def robot(self) -> RobotState:
        """The robot as last published."""

    @property
    def map(self) -> MapModel:
        """The map as last published."""

    def publish(self, change: StateChange) -> None:
        """A new whole value for one part of the robot's state (dropped when it did not change)."""

    def robot_update(self, **changes: Any) -> None:
        """Change fields of the published :class:`RobotState`."""

    def notice(self, notice: Notice) -> None:
        """A message for the operator, typed by what it is about."""

    def decode(self, name: str, payload: bytes) -> Any:
        """The reply payload of data ``name`` decoded; None (counted, logged sparingly) when malformed."""

    def spawn(self, coro: Coroutine[Any, Any, Any], name: str) -> None:
        """Run ``coro`` as this connection's task (cancelled when the connection ends)."""

    def kick(self) -> None:
        """Let the drive loop re-evaluate now."""

    def sync_subscriptions(self) -> None:
        """A condition of an ``only_while`` subscription may have changed: start or end those."""

    def handler_for(self, name: str) -> Handler | None:
        """The handler the session's subscriptions hold for data ``name`` (a feed that takes the
        request over, as drawings do for sonar, hands the packets on to it)."""

    def feed(self, kind: type[F]) -> F:
        """Another feed of this session."""


class Feed:
    """Base of every feed; a subclass overrides only what it needs."""

    handles: ClassVar[tuple[type[Intent], ...]] = ()
    """The intent types this feed carries out (each type belongs to exactly one feed)."""

    def __init__(self, ctx: FeedContext) -> None:
        self.ctx = ctx

    def intent_types(self) -> tuple[type[Intent], ...]:
        """:attr:`handles` (a stand-in for a feed not imported yet names its feed's: ``lazy_feed``)."""
        return self.handles

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        """What to subscribe to on every connection, where the server offers it."""
        return ()

    def connected(self, client: AriaClient) -> None:
        """A fresh login (after this feed's subscriptions are made); spawn one-off questions here."""

    def lost(self) -> None:
        """The link died, not by our choice (a reconnect may follow): keep showing the last values."""

    def disconnected(self) -> None:
        """The operator disconnected (or connects elsewhere): forget what belonged to the connection."""

    def robot_changed(self, robot: RobotState) -> None:
        """A new robot value was published (navigation reads its words and pose)."""

    def handle(self, intent: Intent) -> Any:
        """Carry out ``intent`` (one of :attr:`handles`); may return an awaitable for a result."""
        raise NotSupported(type(intent).__name__, f"{type(self).__name__} does not handle it")

    # -- shared helpers ------------------------------------------------------------------------
    def require(self, *names: str) -> AriaClient:
        """This connection's client, offering one of ``names`` (none: just connected)."""
        client = self.ctx.client
        if client is None or not client.connected:
            raise ServerClosed("not connected")
        if names and not any(client.supports(n) for n in names):
            raise NotSupported(names[0])
        return client
