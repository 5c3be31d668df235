"""Where the window says things: each notice by its ``Kind``, and the connection's life as ONE banner.

A :class:`~rtmu.base.notices.Notice` is routed by its kind, never by the words in its text:
connection notices fold into the ``link`` banner that the model drives, speed ones into the
``speed`` banner, camera ones into the camera page (failing a picture request under way) and its
banner, navigation outcomes into one ``navigation`` banner updated in place; anything else gets a
banner of its own, keyed by its text. The connection's life (connecting, connected, lost →
reconnecting (n), failed) is drawn from the model into that one ``link`` banner; a deliberate
disconnect shows nothing. The speed step and a stalled network thread have a banner each.

The rules are plain functions returning :class:`Banner` values, so they are tested without a
display; :class:`NoticeRouter` applies them to the window's banners.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple, Protocol

from ..base.i18n import N_, Said, _
from ..base.notices import Kind, Level, Notice
from ..model.observables import SPEED_MAX, ConnectionState, LinkLevel, NavState, Phase
from .nav_text import link_lost_note
from .state_words import sentence_words


@dataclass(frozen=True, slots=True)
class Banner:
    """One banner to show: its topic (one banner per topic, updated in place), level and words."""

    topic: str
    level: str
    text: str
    timeout: float | None
    """Seconds on screen; None: until dismissed or replaced."""
    fraction: float | None = None
    """A level bar under the text (0…1: the speed step)."""


class Dismiss(NamedTuple):
    """Take the banner of ``topic`` away."""

    topic: str


@dataclass(frozen=True, slots=True)
class Route:
    """Where one notice goes: a banner (or none), and whether it fails a picture request under way."""

    banner: Banner | None = None
    fails_picture: bool = False


def route(notice: Notice, connection: ConnectionState, speed_percent: int) -> Route:
    """Where ``notice`` is shown, from its kind and level (the connection and speed step the window shows)."""
    kind, level, text = notice.kind, notice.level, notice.text
    if kind is Kind.CONNECTION or (text and text == connection.error):
        return Route()  # the link banner shows the connection's life from the model
    if isinstance(text, Said):  # a sentence built from values (a navigation outcome): in the operator's words
        text = text.words()
    if kind is Kind.LINK:
        if level is Level.INFO:
            return Route(Banner("link", "info", text, 4.0))
        if connection.phase is Phase.CONNECTED:
            return Route(Banner("link", level.value, text, None))
        return Route()
    if kind is Kind.SPEED_LIMIT:
        words = (
            _("Speed at its maximum: {percent} %")
            if speed_percent >= SPEED_MAX
            else _("Speed at its minimum: {percent} %")
        ).format(percent=speed_percent)
        return Route(Banner("speed", "warning", words, 2.5, speed_percent / SPEED_MAX))
    if kind is Kind.SPEED:
        return Route()  # the speed banner follows the model
    if kind is Kind.NAVIGATION:  # outcomes and cancellations: one banner, updated in place
        return Route(Banner("navigation", level.value, text, 8.0 if level is Level.INFO else 12.0))
    if kind is Kind.CAMERA:
        return Route(Banner("camera", level.value, text, 5.0), fails_picture=True)
    return Route(Banner(f"notice:{text}", level.value, text, 6.0 if level is Level.ERROR else 4.0))


def link_banner(old: ConnectionState, new: ConnectionState, navigation: NavState) -> Banner | Dismiss | None:
    """The ``link`` banner for a change of connection (None: the banner stays as it is)."""
    where = f"{new.host}:{new.port}" if new.host else ""
    phase = new.phase
    if phase is Phase.CONNECTING and old.phase is not Phase.CONNECTING:
        return Banner("link", "info", _("Connecting to {where}…").format(where=where), None)
    if phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED:
        if old.phase is Phase.RECONNECTING:
            return Banner(
                "link",
                "info",
                _("Reconnected to {where}: press a key to drive again").format(where=where),
                4.0,
            )
        return Banner("link", "info", _("Connected to {where}").format(where=where), 3.0)
    if phase is Phase.RECONNECTING:
        count = f" ({new.attempt})" if new.attempt else ""
        note = link_lost_note(navigation)
        return Banner(
            "link",
            "warning",
            _("Link lost — reconnecting{count}…{note}").format(count=count, note=note),
            None,
        )
    if phase is Phase.FAILED and (new.error != old.error or old.phase is not Phase.FAILED):
        lost = old.phase in (Phase.CONNECTED, Phase.RECONNECTING)
        reason = sentence_words(new.error) if new.error else _("no reason given")
        note = link_lost_note(navigation)
        text = (
            _("Link lost: {reason}.{note}").format(reason=reason, note=note)
            if lost
            else _("Could not connect to {where}: {reason}").format(where=where, reason=reason)
        )
        return Banner("link", "error", text, 10.0)
    if phase is Phase.DISCONNECTED and old.phase is not Phase.DISCONNECTED:
        return Dismiss("link")  # deliberate: no banner at all
    return None


def say_stop(notice: Notice, robot: str | None = None) -> None:
    """A stop's explanation goes to stderr too, once, as the window shows it (``Notice.stop``): the
    terminal the window was started from, or a site's journal, keeps every stop's measured cause."""
    if notice.stop:
        where = f"{robot}: " if robot else ""
        print(f"rtmu: {where}{notice.text}", file=sys.stderr, flush=True)


LOOP_LAG_WARN = 0.5
"""Seconds without a network-loop heartbeat after which the window warns that drive commands (and
stops) are not going out; the warning goes once the lag is under half of this again."""


def loop_lag_banner(lag: float | None, connected: bool, shown: bool) -> Banner | Dismiss | None:
    """The ``loop`` banner while the network thread is stalled: then even a stop cannot leave the
    process (``lag``: seconds since its last heartbeat; ``shown``: the banner is up now)."""
    if connected and lag is not None and lag > LOOP_LAG_WARN:
        text = _(
            "The network thread has not run for {lag:.1f} s: drive commands and stops are not going out; "
            "the robot may keep moving until the server's watchdog stops it"
        ).format(lag=lag)
        return Banner("loop", "error", text, None)
    if shown and (not connected or lag is None or lag < LOOP_LAG_WARN / 2):
        return Dismiss("loop")
    return None


LINK_STOP_WORDS = N_("Stopped: the link")
"""How the controller's stop for a stale or lost link begins (``Controller._say_link_stop``)."""
LINK_BACK_AFTER = 1.0
"""Seconds of a healthy link after which a "Stopped: the link is stale" banner gives way: it stays
only while it is true (a later healthy drive never runs under it)."""


def link_back_banner(shown: str | None, ok_for: float | None) -> Banner | None:
    """The ``link`` banner once the link has been healthy for ``ok_for`` seconds (None: not healthy now)
    while it still says a link stop (``shown``): the stop is over, and the banner says how to go on."""
    if (
        shown is None
        or not shown.startswith(_(LINK_STOP_WORDS))
        or ok_for is None
        or ok_for < LINK_BACK_AFTER
    ):
        return None
    return Banner("link", "info", _("The link is back: press a key to drive again"), 4.0)


def speed_banner(percent: int) -> Banner:
    """The speed step the operator just chose, with its bar."""
    return Banner("speed", "info", _("Speed {percent} %").format(percent=percent), 2.5, percent / SPEED_MAX)


class Banners(Protocol):
    """The window's banner column (``ui.banners.BannerStack``)."""

    def tell(
        self, topic: str, level: str, text: str, *, timeout: float | None = 4.0, fraction: float | None = None
    ) -> None: ...

    def dismiss(self, topic: str) -> None: ...

    def topics(self) -> list[str]: ...

    def text(self, topic: str) -> str | None: ...


class PictureRequest(Protocol):
    """The camera page's picture request (``ui.camera.CameraView``)."""

    @property
    def waiting(self) -> bool: ...

    def failed(self, reason: str) -> None: ...


class NoticeRouter:
    """Applies :func:`route` and :func:`link_banner` to the window's banners and camera page."""

    def __init__(
        self,
        banners: Banners,
        *,
        connection: Callable[[], ConnectionState],
        speed_percent: Callable[[], int],
        picture: Callable[[], PictureRequest],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.banners = banners
        self._connection, self._speed, self._picture = connection, speed_percent, picture
        self._clock = clock
        self._ok_since: float | None = None

    def show(self, notice: Notice) -> None:
        """Show a controller or network notice where its kind belongs."""
        found = route(notice, self._connection(), self._speed())
        picture = self._picture()
        if found.fails_picture and picture.waiting:
            picture.failed(notice.text)
        self.apply(found.banner)

    def connection_changed(self, old: ConnectionState, new: ConnectionState, navigation: NavState) -> None:
        self.apply(link_banner(old, new, navigation))

    def loop_lag(self, lag: float | None, connected: bool) -> None:
        """The network thread's lag now (None: unknown): the ``loop`` banner while it is stalled."""
        self.apply(loop_lag_banner(lag, connected, "loop" in self.banners.topics()))

    def link_health(self, level: LinkLevel) -> None:
        """The link's health now (polled by the window's timer): a link stop's banner goes once it is
        healthy again for :data:`LINK_BACK_AFTER`."""
        now = self._clock()
        healthy = level is LinkLevel.OK and self._connection().phase is Phase.CONNECTED
        if not healthy:
            self._ok_since = None
            return
        if self._ok_since is None:
            self._ok_since = now
        self.apply(link_back_banner(self.banners.text("link"), now - self._ok_since))

    def apply(self, banner: Banner | Dismiss | None) -> None:
        if isinstance(banner, Dismiss):
            self.banners.dismiss(banner.topic)
        elif banner is not None:
            self.banners.tell(
                banner.topic, banner.level, banner.text, timeout=banner.timeout, fraction=banner.fraction
            )
