"""The window session's share of the server's drawings: list, per-drawing requests, typed state.

:class:`DrawingsFeed` runs on the network loop. On each connection it reads ``getDrawingList``
(:mod:`.drawing_list`) and asks for every drawing that is *shown* at that drawing's own refresh
period; a hidden drawing's request is ended (REQUESTSTOP), so the server stops sending it. What
is shown is the server's visibility (``AlwaysOn`` / ``AlwaysOff`` cannot be changed) or, for
``DefaultOn`` / ``DefaultOff``, the operator's choice, which outlives reconnects.

Everything from the server is bounded: at most ``MAX_DRAWINGS`` drawings, one packet of at most
3 998 points per sample (a count that does not fit its bytes is refused and named on the layer),
a refresh period no shorter than :data:`MIN_REFRESH_MS`, and at most one published
:class:`~rtmu.values.state.DrawingsChanged` per :data:`PUBLISH_EVERY` s however fast samples come. A
shape RTMU cannot draw is listed (``drawable=False``) and never asked for.

The session keeps its own sonar (and LD laser) handling: where the session holds a subscription of
a drawing's data name, this feed's request replaces it, so it hands every packet of that name on
to the session's handler (``FeedContext.handler_for``).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Mapping
from typing import ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.drawings import Drawing, Visibility
from ..values.intents import DrawingChoices, Intent, ShowDrawing
from ..values.state import DrawingLayer, DrawingsChanged, DrawingsState
from .connection import AriaClient, Packet
from .drawing_list import LIST, decode_points, drawing_list, drawing_sample
from .errors import ClientError
from .feed import Feed, FeedContext

log = logging.getLogger(__name__)

MIN_REFRESH_MS = 50
"""A drawing is never asked for more often than this, whatever period the server suggests."""
MAX_REFRESH_MS = 2**31 - 1
"""…nor less often than this: a request's period is a signed 32-bit count of ms on the wire (ARIA's
``byte4``), and a drawing list may suggest up to 2³²−1 (24 days or 49 are the same thing: one sample)."""
PUBLISH_EVERY = 0.05
"""Seconds between two published states at most (samples arriving faster are coalesced)."""


class DrawingsFeed(Feed):
    """Drawings for one session (network loop only)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (ShowDrawing, DrawingChoices)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._timeout = ctx.config.reply_timeout
        self._client: AriaClient | None = None
        self._drawings: tuple[Drawing, ...] = ()
        self._points: dict[str, tuple[tuple[int, int], ...]] = {}
        self._problems: dict[str, str] = {}
        self._requested: set[str] = set()
        self._choices: dict[str, bool] = {}
        self._offered = False
        self._note = ""
        self._flush_pending = False
        self.bad_samples = 0
        """Samples refused on this session (malformed or too many points)."""

    # -- connection --------------------------------------------------------------------------
    def connected(self, client: AriaClient) -> None:
        """A fresh login: forget the last server's drawings; read this one's list where it has one."""
        self._reset(client)
        if client.supports(LIST):
            self._offered = True
            self.ctx.spawn(self._fetch(client), "drawings")
        self._publish_now()

    def disconnected(self) -> None:
        self._reset(None)
        self._publish_now()

    def _reset(self, client: AriaClient | None) -> None:
        self._client = client
        self._drawings = ()
        self._points.clear()
        self._problems.clear()
        self._requested.clear()
        self._offered = False
        self._note = ""

    async def _fetch(self, client: AriaClient) -> None:
        try:
            listed = await drawing_list(client, self._timeout)
        except ClientError as exc:
            if client is self._client:
                self._note = f"the server's drawings could not be read: {exc}"
                self._publish_now()
            return
        if client is not self._client:
            return
        self._note = listed.dropped_text()
        self._drawings = tuple(sorted(listed.drawings, key=lambda d: d.layer))
        for d in self._drawings:  # the session subscribed its sonar/lasers itself: a hidden one ends here
            if self.ctx.handler_for(d.name) is not None and not self.shown(d):
                client.stop_request(d.name)
        unknown = [d for d in self._drawings if d.known_shape is None]
        if unknown:
            log.info("drawings with shapes RTMU cannot draw: %s", ", ".join(repr(d.shape) for d in unknown))
        self._sync()
        self._publish_now()

    # -- what the operator chose -------------------------------------------------------------
    def handle(self, intent: Intent) -> None:
        if isinstance(intent, ShowDrawing):
            self.set_shown(intent.name, intent.shown)
        elif isinstance(intent, DrawingChoices):
            self.set_choices(intent.choices)

    def set_choices(self, choices: Mapping[str, bool]) -> None:
        """The operator's remembered choices for this server (settings), before or after connecting."""
        self._choices = {str(k): bool(v) for k, v in list(choices.items())[:1024]}
        self._sync()
        self._publish_now()

    def set_shown(self, name: str, shown: bool) -> None:
        """Show or hide one drawing; ignored where the server does not let the operator choose."""
        self._choices[name] = shown
        self._sync()
        self._publish_now()

    def shown(self, d: Drawing) -> bool:
        kind = d.visibility_kind
        if kind is Visibility.ALWAYS_ON:
            return True
        if kind is Visibility.ALWAYS_OFF:
            return False
        return self._choices.get(d.name, d.shown_by_default)

    @property
    def requested(self) -> frozenset[str]:
        """Drawings asked for now on this connection."""
        return frozenset(self._requested)

    # -- requests ----------------------------------------------------------------------------
    def _sync(self) -> None:
        client = self._client
        if client is None or not client.connected:
            return
        for d in self._drawings:
            wanted = self.shown(d) and d.known_shape is not None
            if wanted and d.name not in self._requested:
                self._requested.add(d.name)
                try:
                    self._ask(client, d)
                except (ClientError, ProtocolError, ValueError) as exc:  # this drawing only: the rest go on
                    self._problems[d.name] = f"could not be asked for: {exc}"
                    log.info("drawing %r could not be asked for: %s", d.name, exc)
            elif not wanted and d.name in self._requested:
                self._requested.discard(d.name)
                client.stop_request(d.name)
                self._points.pop(d.name, None)
                self._problems.pop(d.name, None)

    def _ask(self, client: AriaClient, d: Drawing) -> None:
        if d.refresh_ms > 0:
            client.request(d.name, period_ms(d.refresh_ms), self._on_packet)
        else:  # "don't poll": the server sends it when it changes; one sample to start with
            client.request(d.name, -1, self._on_packet)
            self.ctx.spawn(self._first_sample(client, d.name), f"drawing-{d.name[:40]}")

    async def _first_sample(self, client: AriaClient, name: str) -> None:
        with contextlib.suppress(ClientError):
            sample = await drawing_sample(client, name, self._timeout)
            if client is self._client and name in self._requested:
                self._points[name] = sample.points
                self._schedule_publish()

    def _on_packet(self, packet: Packet) -> None:
        name = packet.name
        also = self.ctx.handler_for(name)
        if also is not None:
            try:
                also(packet)
            except Exception:
                log.exception("the session's handler for %s failed", name)
        if name not in self._requested:
            return
        try:
            self._points[name] = decode_points(name, packet.payload).points
            self._problems.pop(name, None)
        except ClientError as exc:
            self.bad_samples += 1
            self._points.pop(name, None)
            self._problems[name] = str(exc)
        self._schedule_publish()

    # -- publishing --------------------------------------------------------------------------
    def _schedule_publish(self) -> None:
        if self._flush_pending:
            return
        self._flush_pending = True
        asyncio.get_running_loop().call_later(PUBLISH_EVERY, self._flush)

    def _flush(self) -> None:
        self._flush_pending = False
        self._publish_now()

    def _publish_now(self) -> None:
        layers = tuple(
            DrawingLayer(
                name=d.name,
                shape=d.shape,
                drawable=d.known_shape is not None,
                color=d.primary_color & 0xFFFFFF,
                size=d.size,
                layer=d.layer,
                refresh_ms=period_ms(d.refresh_ms) if d.refresh_ms > 0 else 0,
                shown=self.shown(d) and d.known_shape is not None,
                may_toggle=d.operator_may_toggle and d.known_shape is not None,
                points=self._points.get(d.name, ()),
                problem=self._problems.get(d.name, ""),
            )
            for d in self._drawings
        )
        self.ctx.publish(DrawingsChanged(DrawingsState(layers, self._offered, self._note)))


def period_ms(suggested: int) -> int:
    """The period a drawing is asked for at: the server's suggestion within what is sane and sendable."""
    return min(max(suggested, MIN_REFRESH_MS), MAX_REFRESH_MS)
