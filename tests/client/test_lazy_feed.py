"""Feeds imported on their first intent (``client.lazy_feed``, issue 28: launch and memory).

Each lazy entry names the class and the intent types that class really handles, and the class has
no per-connection hook a late start would miss. Against the simulator: the files feed is not built
until its first intent, is built then and serves it, and stays the one instance the session hands out
(``Session.feed``) and hands its intents to after a reconnect. ``tests/test_import_cost.py`` counts
that the window's imports leave these modules out.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.client.feed import Feed
from rtmu.client.feeds import FEEDS, FILES, LAZY
from rtmu.client.lazy_feed import DeferredFeed, LazyFeed
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import Phase, RobotModel
from rtmu.sim import SimThread
from rtmu.values.intents import ListFiles
from rtmu.values.target import Target
from simulators import running

from .uiqueue import UiQueue


@pytest.mark.parametrize("entry", LAZY, ids=[e.name for e in LAZY])
def test_each_lazy_entry_names_its_feed_and_what_that_feed_handles(entry: LazyFeed) -> None:
    kind = entry.load()
    assert entry.names(kind)
    assert kind.handles == entry.handles
    # No subscription and no connect hook: a feed built after the login misses nothing.
    assert kind.subscriptions is Feed.subscriptions, f"{kind.__name__} subscribes: it cannot start late"
    assert kind.connected is Feed.connected, f"{kind.__name__} acts on connect: it cannot start late"
    assert entry in FEEDS


def test_an_entry_naming_no_feed_is_refused() -> None:
    with pytest.raises(TypeError, match="not a Feed"):
        LazyFeed("rtmu.client.lazy_feed", "LazyFeed", ()).load()


@pytest.fixture
def sim(tmp_path: Path) -> Iterator[SimThread]:
    root = tmp_path / "robot"
    root.mkdir()
    (root / "a.txt").write_bytes(b"abc")
    with running(files_dir=root) as s:
        yield s


def test_the_files_feed_is_built_by_its_first_intent_and_kept(sim: SimThread) -> None:
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post)
    runner.start()
    try:
        target = Target("127.0.0.1", sim.port, "", "", profile="t")
        runner.connect(target).result(10)
        ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED, 20)
        session = runner.session
        assert session is not None
        (stand_in,) = [f for f in session.feeds if isinstance(f, DeferredFeed) and f.entry is FILES]
        assert stand_in.real is None, "built before anyone asked for a file"

        listing = runner.send(ListFiles("")).result(30)
        assert [e.name for e in listing.entries] == ["a.txt"]
        built = stand_in.real
        assert built is not None and type(built).__name__ == "FilesFeed"
        assert session.feed(type(built)) is built  # one instance, however it is asked for

        runner.disconnect().result(10)
        ui.wait_for(lambda: model.connection.value.phase is Phase.DISCONNECTED, 20)
        runner.connect(target).result(10)
        ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED, 20)
        again = runner.send(ListFiles("")).result(30)
        assert [e.name for e in again.entries] == ["a.txt"] and stand_in.real is built
    finally:
        runner.close()
