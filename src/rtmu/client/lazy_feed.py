"""A feed whose module is imported when its first intent comes, not when every session starts.

Most of a session's feeds follow the connection from its first packet; a few only answer the
operator — the files on the robot, the console, the server's own commands — and subscribe to
nothing, do nothing on connect and read no robot update. Their modules (and what those import)
cost every window's launch and memory though few operators open them. :class:`LazyFeed` names
such a feed by module and class with the intent types it handles, so :meth:`Session.dispatch
<rtmu.client.session.Session.dispatch>` still finds it by intent type; :class:`DeferredFeed`
stands in for it and builds the real feed on its first intent (a one-off import on the network
loop, a few milliseconds). ``tests/test_import_cost.py`` checks that the modules stay unloaded,
``tests/client/test_lazy_feed.py`` that each named class handles exactly what its entry says and
has no per-connection hook it would miss by starting late.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

from ..values.intents import Intent
from ..values.state import RobotState
from .feed import Feed, FeedContext


@dataclass(frozen=True)
class LazyFeed:
    """A feed named, not imported: ``module``'s class ``name``, handling ``handles``."""

    module: str
    name: str
    handles: tuple[type[Intent], ...]

    def load(self) -> type[Feed]:
        kind = getattr(importlib.import_module(self.module), self.name)
        if not (isinstance(kind, type) and issubclass(kind, Feed)):
            raise TypeError(f"{self.module}.{self.name} is not a Feed")
        return kind

    def names(self, kind: type) -> bool:
        """Whether ``kind`` is the class this entry names (without importing it)."""
        return kind.__module__ == self.module and kind.__qualname__ == self.name

    def __call__(self, ctx: FeedContext) -> DeferredFeed:
        return DeferredFeed(ctx, self)


class DeferredFeed(Feed):
    """Stands in for a :class:`LazyFeed` until an intent (or another feed) needs the real one."""

    def __init__(self, ctx: FeedContext, entry: LazyFeed) -> None:
        super().__init__(ctx)
        self.entry = entry
        self.real: Feed | None = None

    def intent_types(self) -> tuple[type[Intent], ...]:
        return self.entry.handles

    def loaded(self) -> Feed:
        """The real feed, built on first use."""
        if self.real is None:
            self.real = self.entry.load()(self.ctx)
        return self.real

    def handle(self, intent: Intent) -> Any:
        return self.loaded().handle(intent)

    # A feed never built has nothing of the connection to forget; a built one hears the rest.
    def lost(self) -> None:
        if self.real is not None:
            self.real.lost()

    def disconnected(self) -> None:
        if self.real is not None:
            self.real.disconnected()

    def robot_changed(self, robot: RobotState) -> None:
        if self.real is not None:
            self.real.robot_changed(robot)
