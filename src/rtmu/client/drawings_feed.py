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

The network loop pays almost nothing per sample however fast they come: a packet only replaces
its drawing's newest raw sample (the older one is dropped unread); samples are decoded when a
state is published, and the window gets at most ``drawing_budget.MAX_SHOWN_POINTS`` points in
all (each layer's ``total_points`` says how many its sample had).

The session keeps its own sonar (and LD laser) handling: where the session holds a subscription of
a drawing's data name, this feed's request replaces it, so it hands every packet of that name on
to the session's handler (``FeedContext.handler_for``).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Mapping
from typing import ClassVar

import numpy as np

from ..protocol.errors import ProtocolError
from ..protocol.payloads.drawings import Drawing, Visibility
from ..values.intents import DrawingChoices, Intent, ShowDrawing
from ..values.state import DrawingLayer, DrawingsChanged, DrawingsState
from .call_values import Packet
from .connection import AriaClient
from .drawing_budget import sample_array, thin
from .drawing_list import LIST, drawing_list, drawing_sample
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
LOOP_SHARE = 0.1
"""At most this share of the network loop's time goes to publishing drawings: after a state that
took ``t`` s of CPU to make, the next waits at least ``t / LOOP_SHARE`` (a flood is shown less
often rather than let it delay a ``ratioDrive``)."""


class DrawingsFeed(Feed):
    """Drawings for one session (network loop only)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (ShowDrawing, DrawingChoices)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._timeout = ctx.config.reply_timeout
        self._client: AriaClient | None = None
        self._drawings: tuple[Drawing, ...] = ()
        self._points: dict[str, tuple[tuple[int, int], ...]] = {}
        """What the window was last given of each drawing (thinned to the budget)."""
        self._raw: dict[str, bytes] = {}
        """Each drawing's newest sample not yet decoded (an older one is dropped unread)."""
        self._arrays: dict[str, np.ndarray] = {}
        """Each drawing's last good sample, decoded (numpy views, no Python objects per point)."""
        self._last_raw: dict[str, bytes] = {}
        self._problems: dict[str, str] = {}
        self._requested: set[str] = set()
        self._choices: dict[str, bool] = {}
        self._offered = False
        self._note = ""
        self._flush_pending = False
        self._cost = 0.0
        """CPU seconds the last published state took to make (paces the next: :data:`LOOP_SHARE`)."""
        self.bad_samples = 0
        """Samples refused on this session (malformed or too many points)."""
        self.samples = 0
        """Samples received on this session (most of a flood is dropped unread)."""

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
        self._raw.clear()
        self._arrays.clear()
        self._last_raw.clear()
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
                self._forget(d.name)
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
            if client is self._client and name in self._requested and name not in self._arrays:
                self._arrays[name] = np.array(sample.points, dtype=np.int32).reshape(-1, 2)
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
        self.samples += 1
        if name not in self._raw and packet.payload == self._last_raw.get(name):
            return  # the sample shown already (a laser at rest): nothing to decode, publish or draw
        self._raw[name] = packet.payload  # the newest only: decoded when published
        self._schedule_publish()

    def _forget(self, name: str) -> None:
        self._points.pop(name, None)
        self._raw.pop(name, None)
        self._arrays.pop(name, None)
        self._last_raw.pop(name, None)

    def _decode_fresh(self) -> None:
        """Decode the newest raw sample of each drawing that sent one since the last state."""
        raw, self._raw = self._raw, {}
        for name, payload in list(raw.items()):
            if payload == self._last_raw.get(name):
                del raw[name]  # the same sample again (a laser at rest): nothing to decode or thin
                continue
            self._last_raw[name] = payload
            try:
                self._arrays[name] = sample_array(name, payload)
                self._problems.pop(name, None)
            except ClientError as exc:
                self.bad_samples += 1
                self._arrays.pop(name, None)
                self._problems[name] = str(exc)
        if raw:
            shapes = {d.name: d.shape for d in self._drawings}
            kept = {n: (shapes.get(n, ""), a) for n, a in self._arrays.items() if n in self._requested}
            self._points = thin(kept)

    # -- publishing --------------------------------------------------------------------------
    def _schedule_publish(self) -> None:
        if self._flush_pending:
            return
        self._flush_pending = True
        asyncio.get_running_loop().call_later(max(PUBLISH_EVERY, self._cost / LOOP_SHARE), self._flush)

    def _flush(self) -> None:
        self._flush_pending = False
        started = time.thread_time()
        self._publish_now()
        self._cost = time.thread_time() - started

    def _publish_now(self) -> None:
        self._decode_fresh()
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
                total_points=len(self._arrays[d.name]) if d.name in self._arrays else 0,
                problem=self._problems.get(d.name, ""),
            )
            for d in self._drawings
        )
        self.ctx.publish(DrawingsChanged(DrawingsState(layers, self._offered, self._note)))


def period_ms(suggested: int) -> int:
    """The period a drawing is asked for at: the server's suggestion within what is sane and sendable."""
    return min(max(suggested, MIN_REFRESH_MS), MAX_REFRESH_MS)
