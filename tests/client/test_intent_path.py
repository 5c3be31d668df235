"""One path for every intent: widget → selected robot's controller guard → runner.send → the feed.

Against the simulator over loopback, through a robot session built as the window builds it
(recording on): a new capability is one payload, one intent and one feed and reaches the robot and
the recording with nothing else edited; a held drive ends before an intent that moves the robot;
a replay refuses every intent; a refused intent never reaches the wire.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from recorder.mcapread import read
from recorder.simsession import recorded_session
from rtmu.client.feed import Feed
from rtmu.client.link import Link, open_tcp
from rtmu.client.session_config import SessionConfig
from rtmu.protocol.datalist import DataList
from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.fields import FieldReader, FieldWriter
from rtmu.protocol.payloads.base import Payload, Side
from rtmu.recorder import topics
from rtmu.sim import SimConfig
from rtmu.values.intents import GotoGoal, Intent, Patrol, TurnBy
from rtmu.values.state import MapPhase


# -- a capability the product does not have: one payload, one intent, one feed ------------------
@dataclass(frozen=True)
class NameTag(Payload):
    """``identSetSelfIdentifier`` args, written here from scratch (deliberately not registered)."""

    DATA_NAME = "identSetSelfIdentifier"
    SIDE = Side.ARGS
    tag: str

    def encode(self) -> bytes:
        return FieldWriter().string(self.tag).bytes()

    @classmethod
    def decode(cls, payload: bytes) -> NameTag:
        return cls(FieldReader(payload).string())


@dataclass(frozen=True)
class TagMe(Intent):
    needs: ClassVar[tuple[str, ...]] = ("identSetSelfIdentifier",)
    label: ClassVar[str] = "Tag this client"
    tag: str = ""


class TagFeed(Feed):
    handles: ClassVar[tuple[type[Intent], ...]] = (TagMe,)

    def handle(self, intent: Intent) -> None:
        assert isinstance(intent, TagMe)
        self.require("identSetSelfIdentifier").send(NameTag(intent.tag))


def test_a_new_intent_with_its_feed_reaches_the_robot_and_the_recording(tmp_path: Path) -> None:
    config = SessionConfig(extra_feeds=(TagFeed,))
    with recorded_session(tmp_path, config=config) as (session, ui, _view, sim):
        session.controller.ask(TagMe("probe-7"))
        ui.wait_for(lambda: any(s.self_identifier == "probe-7" for s in sim.server.sessions), timeout=5)
    (path,) = tmp_path.glob("*.mcap")
    intents = read(path).records(topics.INTENTS)
    assert {"intent": "TagMe", "tag": "probe-7"} in intents


def test_an_intent_the_server_does_not_offer_is_refused_before_the_wire(tmp_path: Path) -> None:
    with recorded_session(tmp_path) as (session, ui, view, _sim):
        assert session.controller.ask(Patrol("Loop")) is None  # the default simulator has no patrol
        ui.drain()
        assert any("does not offer patrol" in text for _level, text in view.notices)
    (path,) = tmp_path.glob("*.mcap")
    assert not [r for r in read(path).records(topics.INTENTS) if r.get("intent") == "Patrol"]


# -- the guard: a held drive ends before anything else moves the robot ---------------------------
class WireSpy:
    """An opener whose links keep every byte the client wrote, to read the requests in order."""

    def __init__(self) -> None:
        self.written = bytearray()

    async def open(self, host: str, port: int) -> Link:
        link = await open_tcp(host, port)
        spy = self

        class Spied:
            def write(self, data: bytes) -> None:
                spy.written += data
                link.write(data)

            def __getattr__(self, name: str) -> Any:
                return getattr(link, name)

        return Spied()  # type: ignore[return-value]

    def requests(self, datalist: DataList) -> list[str]:
        names = []
        for packet in PacketDecoder().feed(bytes(self.written)):
            name = datalist.name(packet.command)
            if name is not None:
                names.append(name)
        return names


def test_a_held_drive_ends_before_patrol_and_stays_ended(tmp_path: Path) -> None:
    spy = WireSpy()
    sim = SimConfig(port=0, profile="aram", seed=1)
    with recorded_session(tmp_path, sim=sim, opener=spy.open) as (session, ui, _view, _server):
        controller = session.controller
        controller.press("forward")
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline:  # held, renewed at 10 Hz as the window does
            controller.tick()
            ui.drain()
            time.sleep(0.1)
        assert session.controller.ask(Patrol("Loop")) is not None
        for _ in range(5):  # the key is still down: its renewals must not drive again
            controller.tick()
            ui.drain()
            time.sleep(0.1)
        session.runner.sync()
        client = session.runner.session.client if session.runner.session else None
        assert client is not None
        sent = spy.requests(client.datalist)
    assert "ratioDrive" in sent
    patrol = sent.index("patrol")
    motion = [name for name in sent[:patrol] if name in ("ratioDrive", "stop")]
    assert motion[-1] == "stop", sent[patrol - 6 : patrol + 2]  # the held drive ended first
    assert "ratioDrive" not in sent[patrol:], "the held key drove again after the patrol"


def test_a_goal_while_a_key_is_held_goes_out_after_the_stop(tmp_path: Path) -> None:
    spy = WireSpy()
    with recorded_session(tmp_path, opener=spy.open) as (session, ui, _view, _sim):
        ui.wait_for(lambda: session.state.map.value.state is MapPhase.READY, timeout=15)
        ui.wait_for(lambda: bool(session.state.navigation.value.goals), timeout=10)
        goal = session.state.navigation.value.goals[0]
        session.controller.press("forward")
        session.controller.tick()
        ui.drain()
        time.sleep(0.3)
        session.controller.ask(GotoGoal(goal))
        session.runner.sync()
        client = session.runner.session.client if session.runner.session else None
        assert client is not None
        sent = spy.requests(client.datalist)
    goto = sent.index("gotoGoal")
    assert "ratioDrive" in sent[:goto]
    motion = [name for name in sent[:goto] if name in ("ratioDrive", "stop")]
    assert motion[-1] == "stop", sent[goto - 6 : goto + 2]


def test_a_replay_refuses_every_intent_and_sends_nothing(tmp_path: Path) -> None:
    spy = WireSpy()
    with recorded_session(tmp_path, opener=spy.open) as (session, ui, view, _sim):
        session.runner.sync()
        before = len(spy.written)
        session.controller.replay = "a recording"
        for intent in (TurnBy(90.0), Patrol("Loop"), GotoGoal("Lab")):
            assert session.controller.ask(intent) is None
        ui.drain()
        session.runner.sync()
        assert any("Replay" in text for _level, text in view.notices)
        assert len(spy.written) == before or _only_routine(spy, before, session)


def _only_routine(spy: WireSpy, before: int, session: Any) -> bool:
    """Status polls and pings may go out meanwhile; none of the refused intents may."""
    client = session.runner.session.client
    tail = WireSpy()
    tail.written = spy.written[before:]
    return not {"turnByAngle", "patrol", "gotoGoal"} & set(tail.requests(client.datalist))
