"""Where the window shows a notice: by its kind, never by its words (``ui.notice_router``, no display)."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from rtmu.base.notices import Kind, Notice
from rtmu.model.observables import ConnectionState, NavState, Phase
from rtmu.ui.notice_router import Banner, Dismiss, NoticeRouter, Route, link_banner, route, speed_banner

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
