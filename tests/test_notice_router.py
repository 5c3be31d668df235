"""Where and how the window says things (``ui.notice_router``, ``ui.notes``), without a display.

A notice goes where its kind says, never by its words; the connection's life is one link banner."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from rtmu.base.notices import Kind, Notice
from rtmu.model.observables import ConnectionState, LinkLevel, NavState, Phase, SpeedSetting
from rtmu.settings.store import Profile
from rtmu.ui.notes import status_line
from rtmu.ui.notice_router import (
    Banner,
    Dismiss,
    NoticeRouter,
    Route,
    link_back_banner,
    link_banner,
    loop_lag_banner,
    route,
    speed_banner,
)

CONNECTED = ConnectionState(Phase.CONNECTED, host="127.0.0.1", port=7272)
RECONNECTING = ConnectionState(Phase.RECONNECTING, host="127.0.0.1", port=7272, attempt=2)


def test_each_kind_has_its_place() -> None:
    assert route(Notice.info(Kind.CONNECTION, "Connected"), CONNECTED, 50) == Route()
    assert route(Notice.info(Kind.SPEED, "Speed 60 %"), CONNECTED, 60) == Route()
    assert route(Notice.info(Kind.LINK, "Link fine again"), CONNECTED, 50).banner == Banner(
        "link", "info", "Link fine again", 4.0
    )
    stale = Notice.warning(Kind.LINK, "Stopped: the link is stale")
    assert route(stale, CONNECTED, 50).banner == Banner("link", "warning", stale.text, None)
    assert route(stale, RECONNECTING, 50) == Route(), "a lost link's own banner says it already"
    nav = route(Notice.error(Kind.NAVIGATION, "Failed to get to dock"), CONNECTED, 50).banner
    assert nav is not None and (nav.topic, nav.timeout) == ("navigation", 12.0)
    camera = route(Notice.error(Kind.CAMERA, "no picture"), CONNECTED, 50)
    assert camera == Route(Banner("camera", "error", "no picture", 5.0), fails_picture=True)


@pytest.mark.parametrize(("percent", "word"), [(100, "maximum"), (10, "minimum")])
def test_the_speed_limit_says_which_end_with_its_bar(percent: int, word: str) -> None:
    banner = route(Notice.warning(Kind.SPEED_LIMIT, "limit"), CONNECTED, percent).banner
    assert banner == Banner("speed", "warning", f"Speed at its {word}: {percent} %", 2.5, percent / 100)
    assert speed_banner(70) == Banner("speed", "info", "Speed 70 %", 2.5, 0.7)


def test_a_server_text_about_the_camera_stays_a_server_text() -> None:
    """Routed by kind: the word "camera" in a server's message does not make it a camera notice."""
    text = "The camera picture on the dock is dirty: please clean it"
    found = route(Notice.warning(Kind.SERVER, text), CONNECTED, 50)
    assert found == Route(Banner(f"notice:{text}", "warning", text, 4.0))
    assert route(Notice.error(Kind.GENERAL, "boom"), CONNECTED, 50).banner.timeout == 6.0  # type: ignore[union-attr]


def test_the_connection_error_is_said_once_by_the_link_banner() -> None:
    failed = ConnectionState(Phase.FAILED, host="h", port=1, error="refused")
    assert route(Notice.error(Kind.GENERAL, "refused"), failed, 50) == Route()


def test_the_connection_life_is_one_link_banner() -> None:
    off, nav = ConnectionState(), NavState()
    connecting = ConnectionState(Phase.CONNECTING, host="127.0.0.1", port=7272)
    assert link_banner(off, connecting, nav) == Banner("link", "info", "Connecting to 127.0.0.1:7272…", None)
    assert link_banner(connecting, connecting, nav) is None, "the same phase again changes nothing"
    assert link_banner(connecting, CONNECTED, nav) == Banner(
        "link", "info", "Connected to 127.0.0.1:7272", 3.0
    )
    lost = link_banner(CONNECTED, RECONNECTING, nav)
    assert isinstance(lost, Banner) and lost.text == "Link lost — reconnecting (2)…" and lost.timeout is None
    back = link_banner(RECONNECTING, CONNECTED, nav)
    assert isinstance(back, Banner) and "press a key to drive again" in back.text
    failed = ConnectionState(Phase.FAILED, host="127.0.0.1", port=7272, error="refused")
    assert link_banner(connecting, failed, nav) == Banner(
        "link", "error", "Could not connect to 127.0.0.1:7272: refused", 10.0
    )
    dropped = link_banner(CONNECTED, failed, nav)
    assert isinstance(dropped, Banner) and dropped.text == "Link lost: refused."
    assert link_banner(failed, failed, nav) is None
    assert link_banner(CONNECTED, off, nav) == Dismiss("link"), "a deliberate disconnect shows nothing"


def test_a_lost_link_says_the_robot_navigates_on_its_own() -> None:
    going = NavState(navigating=True, target="dock")
    lost = link_banner(CONNECTED, RECONNECTING, going)
    assert isinstance(lost, Banner) and "navigating on its own" in lost.text


@dataclass
class Told:
    """The banners' side of the router: what it was asked to show (a recording, no widgets)."""

    shown: list[tuple[str, str, str, float | None, float | None]] = field(default_factory=list)
    gone: list[str] = field(default_factory=list)

    def tell(
        self, topic: str, level: str, text: str, *, timeout: float | None = 4.0, fraction: float | None = None
    ) -> None:
        self.shown.append((topic, level, text, timeout, fraction))

    def dismiss(self, topic: str) -> None:
        self.gone.append(topic)

    def topics(self) -> list[str]:
        topics = [topic for topic, *_ in self.shown]
        return [t for t in dict.fromkeys(topics) if t not in self.gone]

    def text(self, topic: str) -> str | None:
        said = [text for t, _level, text, *_ in self.shown if t == topic]
        return said[-1] if said and topic in self.topics() else None


@dataclass
class Picture:
    waiting: bool = True
    error: str = ""

    def failed(self, reason: str) -> None:
        self.waiting, self.error = False, reason


def test_the_router_fails_a_waiting_picture_only_for_a_camera_notice() -> None:
    told, picture = Told(), Picture()
    router = NoticeRouter(
        told, connection=lambda: CONNECTED, speed_percent=lambda: 50, picture=lambda: picture
    )
    router.show(Notice.warning(Kind.SERVER, "camera text"))
    assert picture.waiting and told.shown == [("notice:camera text", "warning", "camera text", 4.0, None)]
    router.show(Notice.error(Kind.CAMERA, "the camera is off"))
    assert not picture.waiting and picture.error == "the camera is off"
    assert told.shown[-1] == ("camera", "error", "the camera is off", 5.0, None)
    router.connection_changed(CONNECTED, ConnectionState(), NavState())
    assert told.gone == ["link"]
    router.loop_lag(1.5, connected=True)
    assert told.shown[-1][0] == "loop"
    router.loop_lag(0.1, connected=True)
    assert told.gone == ["link", "loop"]


def test_a_link_stop_banner_goes_once_the_link_is_healthy_again() -> None:
    """ "Stopped: the link is stale" is true while it is up; a healthy link for a second ends it, and
    a later healthy drive never runs under it (issue 21)."""
    assert link_back_banner("Stopped: the link is stale. Press again once it is back.", 0.5) is None
    back = link_back_banner("Stopped: the link is stale. Press again once it is back.", 1.2)
    assert back == Banner("link", "info", "The link is back: press a key to drive again", 4.0)
    assert link_back_banner("Stopped: the link is lost.", None) is None, "still unhealthy"
    assert link_back_banner("Link lost — reconnecting (2)…", 5.0) is None, "the connection's own banner"
    assert link_back_banner(None, 5.0) is None

    told, now = Told(), [0.0]
    router = NoticeRouter(
        told, connection=lambda: CONNECTED, speed_percent=lambda: 50, picture=Picture, clock=lambda: now[0]
    )
    router.show(Notice.warning(Kind.LINK, "Stopped: the link is stale. Press again once it is back."))
    stale, ok = LinkLevel.STALE, LinkLevel.OK
    for t, level in ((0.1, stale), (0.5, ok), (1.2, stale), (1.4, ok)):
        now[0] = t
        router.link_health(level)
    assert told.text("link").startswith("Stopped"), "never healthy for a whole second yet"  # type: ignore[union-attr]
    now[0] = 2.5
    router.link_health(LinkLevel.OK)
    assert told.text("link") == "The link is back: press a key to drive again"


def test_a_stalled_network_thread_is_said_until_it_runs_again() -> None:
    assert loop_lag_banner(0.1, connected=True, shown=False) is None
    stalled = loop_lag_banner(0.8, connected=True, shown=False)
    assert isinstance(stalled, Banner) and stalled.topic == "loop" and stalled.timeout is None
    assert "0.8 s" in stalled.text and "stops are not going out" in stalled.text
    assert loop_lag_banner(0.4, connected=True, shown=True) is None, "kept until well under the limit"
    assert loop_lag_banner(0.2, connected=True, shown=True) == Dismiss("loop")
    assert loop_lag_banner(None, connected=False, shown=True) == Dismiss("loop")
    assert loop_lag_banner(9.0, connected=False, shown=False) is None, "no link: nothing to warn about"


def test_the_header_status_line() -> None:
    profile = Profile("lab", host="10.0.0.5", port=7272)
    off = ConnectionState()
    assert status_line(off, profile, "") == "lab · 10.0.0.5:7272 · not connected"
    on = ConnectionState(Phase.CONNECTED, host="10.0.0.5", port=7272)
    assert status_line(on, profile, "C:\\maps\\office.map") == "lab · 10.0.0.5:7272 · connected · office.map"
    named = Profile("lab 10.0.0.5:7272", host="10.0.0.5", port=7272)
    lost = ConnectionState(Phase.RECONNECTING, host="10.0.0.5", port=7272, error="timed out")
    assert status_line(lost, named, "office.map") == "lab 10.0.0.5:7272 · reconnecting (timed out)"


def test_a_profiles_speed_is_the_step_at_or_below_within_range() -> None:
    assert [SpeedSetting.nearest(p).percent for p in (0, 10, 55, 100, 140)] == [10, 10, 50, 100, 100]
