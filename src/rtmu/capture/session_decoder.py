"""Turn captured byte streams into annotated ArNetworking packets, one connection at a time.

For ``rtmu decode`` and the golden tests. Each connection (TCP flow or bare
stream) gets a session with one framing decoder per direction, its own data
list (learned from the LIST packets it carries, so data names are right even
though every server numbers differently) and the handshake facts needed to
attribute UDP datagrams to it. Control commands are named by direction (5 is
TCP_ONLY from a client but CONNECTED from a server). Data payloads are decoded
through the payload registry; a payload that does not decode is reported with
its error and never stops the run.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from ..protocol import payloads  # noqa: F401 -- importing the package registers every payload type
from ..protocol.commands import ClientCommand, ServerCommand, is_control_command
from ..protocol.decoder import BadPacket, PacketDecoder
from ..protocol.fields import FieldReader
from ..protocol.packet import MIN_LENGTH, SYNC, Packet
from ..protocol.payloads import base as payload_base
from ..protocol.payloads import control
from ..protocol.payloads.base import Payload, Side
from . import CaptureEvent, Datagram, Endpoint, Flow, StreamData, StreamEnd, StreamGap
from .conversation import (
    C2S,
    S2C,
    Conversation,
    DecodedPacket,
    DecodeItem,
    DropReport,
    TrailingDrops,
)

HELD_BEFORE_ID = 64
"""Bad packets kept for a TCP flow that has not yet shown a good one (it may not be ArNetworking)."""
DROP_KEYS = ("garbage_bytes", "bad_length", "bad_checksum", "truncated_at_close", "capture_gap_bytes")
DEFAULT_SERVER_PORT = 7272

_SERVER_ONLY = frozenset(
    (
        ServerCommand.REJECTED,
        ServerCommand.TCP_ONLY,
        ServerCommand.LISTARGRET,
        ServerCommand.LISTARGRETSINGLE,
        ServerCommand.LISTGROUPANDFLAGS,
        ServerCommand.LISTGROUPANDFLAGSSINGLE,
    )
)
_LIST_COMMANDS = {
    ServerCommand.LIST: ("name", "description", True),
    ServerCommand.LISTSINGLE: ("name", "description", False),
    ServerCommand.LISTARGRET: ("arguments", "returns", True),
    ServerCommand.LISTARGRETSINGLE: ("arguments", "returns", False),
    ServerCommand.LISTGROUPANDFLAGS: ("group", "flags", True),
    ServerCommand.LISTGROUPANDFLAGSSINGLE: ("group", "flags", False),
}
_CLIENT_TYPES = {0: "unspecified", 1: "real", 2: "simulated", 3: "none"}


# -- the payload registry ---------------------------------------------------------------
def payload_type_for(name: str, side: Side) -> type[Payload] | None:
    """The registered type for ``name`` on ``side`` (``payload_type_for`` if the registry offers it)."""
    finder: Callable[[str, Side], type[Payload] | None] = getattr(
        payload_base, "payload_type_for", payload_base.payload_type
    )
    return finder(name, side)


def side_of(direction: str) -> Side:
    """What a data packet carries: replies from the server, arguments from the client."""
    return Side.REPLY if direction == S2C else Side.ARGS


# -- the decoder ---------------------------------------------------------------
class CaptureDecoder:
    """Run capture events through per-connection sessions; iterate :meth:`run` for the packets."""

    def __init__(self, *, decode_payloads: bool = True, report_trailing_drops: bool = False) -> None:
        self.decode_payloads = decode_payloads
        self.report_trailing_drops = report_trailing_drops
        self.sessions: list[Conversation] = []
        """Sessions with a connection id, in id order."""
        self._by_flow: dict[int, Conversation] = {}
        self._udp_routes: dict[tuple[Endpoint, Endpoint], tuple[Conversation, str]] = {}
        self._udp_orphans: dict[tuple[Endpoint, Endpoint], Conversation] = {}
        self._next_id = 1
        self.ignored_tcp_flows = 0
        """TCP connections in which no valid ArNetworking packet was found (HTTP, SSH…)."""
        self.ignored_datagrams = 0
        """UDP datagrams that do not start with ArNetworking's sync bytes."""

    def run(self, events: Iterable[CaptureEvent]) -> Iterator[DecodeItem]:
        for event in events:
            if isinstance(event, StreamData):
                yield from self._stream_data(event)
            elif isinstance(event, Datagram):
                yield from self._datagram(event)
            elif isinstance(event, StreamGap):
                yield from self._stream_gap(event)
            elif isinstance(event, StreamEnd):
                yield from self._stream_end(event)
        for session in list(self._by_flow.values()):
            if session.id is None:
                self.ignored_tcp_flows += 1
        self._by_flow.clear()

    # -- sessions ---------------------------------------------------------
    def _session_for(self, flow: Flow) -> Conversation:
        session = self._by_flow.get(flow.id)
        if session is None:
            session = Conversation(flow.transport, flow, flow.first, flow.second)
            self._by_flow[flow.id] = session
            if flow.transport == "stream":
                self._number(session)
        return session

    def _number(self, session: Conversation) -> None:
        session.id = self._next_id
        self._next_id += 1
        self.sessions.append(session)

    def _release(self, session: Conversation) -> Iterator[DecodeItem]:
        """Give the session its id (first good packet) and let out what it held meanwhile."""
        if session.id is None:
            self._number(session)
            for item in session.held:
                item.conn = session.id  # type: ignore[assignment]
                yield item
            session.held.clear()

    def _emit(self, session: Conversation, items: list[DecodeItem]) -> Iterator[DecodeItem]:
        if session.id is not None:
            yield from items
            return
        if any(isinstance(i, DecodedPacket) and i.checksum_ok for i in items):
            yield from self._release(session)
            for item in items:
                item.conn = session.id  # type: ignore[assignment]
                yield item
            return
        for item in items:
            if len(session.held) < HELD_BEFORE_ID:
                session.held.append(item)
            else:
                session.held_overflow += 1

    # -- TCP / stream -----------------------------------------------------
    def _stream_data(self, event: StreamData) -> Iterator[DecodeItem]:
        session = self._session_for(event.flow)
        if session.server is None:
            session.server = event.flow.server
        if session.server is None:
            session.server = _guess_server(event.flow, event.src, event.data)
            session.server_guessed = True
        session.touch(event.time)
        direction = session.direction_from(event.src)
        decoder = session.decoders[direction]
        before = decoder.stats.as_dict()
        packets = decoder.feed(event.data)
        items = self._framed(session, direction, event.flow.transport, event.time, decoder, before, packets)
        yield from self._emit(session, items)

    def _stream_gap(self, event: StreamGap) -> Iterator[DecodeItem]:
        session = self._session_for(event.flow)
        if session.server is None:
            session.server = event.flow.server or event.flow.second
            session.server_guessed = event.flow.server is None
        direction = session.direction_from(event.src)
        decoder = session.decoders[direction]
        before = decoder.stats.as_dict()
        packets = decoder.close()  # a packet cannot straddle missing bytes
        gap = {"capture_gap_bytes": event.missing}
        items = self._framed(
            session, direction, event.flow.transport, event.time, decoder, before, packets, gap
        )
        yield from self._emit(session, items)

    def _stream_end(self, event: StreamEnd) -> Iterator[DecodeItem]:
        session = self._by_flow.get(event.flow.id)
        if session is None:
            return
        direction = session.direction_from(event.src) if session.server else S2C
        decoder = session.decoders[direction]
        before = decoder.stats.as_dict()
        packets = decoder.close()
        items = self._framed(session, direction, event.flow.transport, event.time, decoder, before, packets)
        leftover = session.pending_drops.pop((direction, event.flow.transport), None)  # nothing follows
        self._trailing(session, direction, event.flow.transport, event.time, leftover, items)
        yield from self._emit(session, items)
        session.ended.add(direction)
        if len(session.ended) == 2 or event.flow.transport == "stream":
            del self._by_flow[event.flow.id]
            if session.id is None:
                self.ignored_tcp_flows += 1

    def _framed(
        self,
        session: Conversation,
        direction: str,
        transport: str,
        time: float | None,
        decoder: PacketDecoder,
        before: dict[str, int],
        packets: list[Packet],
        extra: dict[str, int] | None = None,
    ) -> list[DecodeItem]:
        """One feed's output as items: what was dropped, then bad packets, then good packets.

        The decoder keeps bad packets apart from good ones, so their relative order
        within one chunk is not known; drops and bad packets come first.
        """
        after = decoder.stats.as_dict()
        new = Counter({k: after[k] - before[k] for k in DROP_KEYS if k in after and after[k] != before[k]})
        if extra:
            new.update(extra)
        items: list[DecodeItem] = []
        pending = session.pending_drops.setdefault((direction, transport), Counter())
        if new:
            session.totals[direction].drops.update(new)
            pending.update(new)
            items.append(DropReport(session.id or 0, direction, transport, time, dict(new)))
        for raw in decoder.bad_packets:
            items.append(self._bad(session, direction, transport, time, raw))
        decoder.bad_packets.clear()
        for packet in packets:
            items.append(self._annotate(session, direction, transport, time, packet))
        if pending:
            first = next((i for i in items if isinstance(i, DecodedPacket)), None)
            if first is not None:
                first.dropped_before = dict(pending)
                pending.clear()
        return items

    def _trailing(
        self,
        session: Conversation,
        direction: str,
        transport: str,
        time: float | None,
        leftover: Counter[str] | None,
        items: list[DecodeItem],
    ) -> None:
        if leftover and self.report_trailing_drops:
            items.append(TrailingDrops(session.id or 0, direction, transport, time, dict(leftover)))

    # -- UDP -----------------------------------------------------------------
    def _datagram(self, event: Datagram) -> Iterator[DecodeItem]:
        if not event.data.startswith(SYNC):
            self.ignored_datagrams += 1
            return
        route = self._route(event)
        if route is None:
            session = self._orphan(event)
            direction = session.direction_from(event.src)
        else:
            session, direction = route
        session.touch(event.time)
        session.udp_datagrams += 1
        session.udp_flows.add((event.src, event.dst))
        decoder = PacketDecoder(keep_bad=True)  # one packet per datagram; nothing carries over
        packets = decoder.feed(event.data)
        packets += decoder.close()
        before = dict.fromkeys(DROP_KEYS, 0)
        items = self._framed(session, direction, "udp", event.time, decoder, before, packets)
        leftover = session.pending_drops.pop((direction, "udp"), None)  # a datagram stands alone
        self._trailing(session, direction, "udp", event.time, leftover, items)
        yield from self._emit(session, items)

    def _orphan(self, event: Datagram) -> Conversation:
        key = (event.src, event.dst) if event.src <= event.dst else (event.dst, event.src)
        session = self._udp_orphans.get(key)
        if session is None:
            session = Conversation("udp", None, event.src, event.dst)
            session.server = _port_guess(event.src, event.dst)
            session.server_guessed = True
            self._udp_orphans[key] = session
        return session

    def _route(self, event: Datagram) -> tuple[Conversation, str] | None:
        """Which TCP session a datagram belongs to: learnt routes, UDP keys, then announced ports."""
        src, dst = event.src, event.dst
        route = self._udp_routes.get((src, dst))
        if route is not None:
            return route
        found = self._by_key(event) or self._by_ports(src, dst)
        if found is not None:
            session, direction = found
            self._udp_routes[(src, dst)] = (session, direction)
            self._udp_routes[(dst, src)] = (session, S2C if direction == C2S else C2S)
        return found

    def _by_key(self, event: Datagram) -> tuple[Conversation, str] | None:
        data = event.data
        if len(data) != MIN_LENGTH + 4 or data[4] != 3 or data[5] != 0:
            return None
        key = int.from_bytes(data[6:10], "little")
        for session in reversed(self.sessions):
            client, server = session.client, session.server
            if client and session.auth_key == key and event.src.host == client.host:
                return session, C2S
            if server and session.intro_key == key and event.src.host == server.host:
                return session, S2C
        return None

    def _by_ports(self, src: Endpoint, dst: Endpoint) -> tuple[Conversation, str] | None:
        loose: list[tuple[Conversation, str]] = []
        for session in reversed(self.sessions):
            client, server = session.client, session.server
            if client is None or server is None or not session.server_udp_port:
                continue
            server_udp = Endpoint(server.host, session.server_udp_port)
            for a, b, direction in ((src, dst, S2C), (dst, src, C2S)):
                if a == server_udp and b.host == client.host:
                    if session.client_udp_port == b.port:
                        return session, direction
                    loose.append((session, direction))
        return loose[0] if len(loose) == 1 else None

    # -- one packet --------------------------------------------------------------
    def _name(self, session: Conversation, direction: str, command: int) -> str | None:
        if not is_control_command(command):
            return session.datalist.name(command)
        enum = ServerCommand if direction == S2C else ClientCommand
        try:
            return enum(command).name
        except ValueError:
            return None

    def _bad(
        self, session: Conversation, direction: str, transport: str, time: float | None, raw: BadPacket
    ) -> DecodedPacket:
        totals = session.totals[direction]
        totals.packets += 1
        totals.bytes += raw.length
        name = self._name(session, direction, raw.command)
        totals.by_name[f"{name or raw.command} (bad checksum)"] += 1
        return DecodedPacket(
            session.id or 0,
            direction,
            transport,
            time,
            raw.command,
            name,
            raw.length,
            False,
            raw.raw[6:-2],
            {},
            note="checksum mismatch: dropped by the receiver",
        )

    def _annotate(
        self, session: Conversation, direction: str, transport: str, time: float | None, packet: Packet
    ) -> DecodedPacket:
        command = packet.command
        payload = packet.payload
        fields: dict[str, Any] = {}
        error = note = None
        try:
            if is_control_command(command):
                fields = self._control(session, direction, packet)
            else:
                fields, note = self._data(session, direction, command, payload)
        except _PartialDecode as exc:
            fields, error = exc.fields, exc.message
        except Exception as exc:  # a peer's bytes or a payload type's bug: show it, never stop
            error = f"{type(exc).__name__}: {exc}"
        name = self._name(session, direction, command)
        totals = session.totals[direction]
        totals.packets += 1
        totals.bytes += len(payload) + MIN_LENGTH
        totals.by_name[name or str(command)] += 1
        return DecodedPacket(
            session.id or 0,
            direction,
            transport,
            time,
            command,
            name,
            len(payload) + MIN_LENGTH,
            True,
            payload,
            fields,
            error,
            note,
        )

    def _data(
        self, session: Conversation, direction: str, command: int, payload: bytes
    ) -> tuple[dict[str, Any], str | None]:
        entry = session.datalist.entry(command)
        if not payload:
            note = (
                "end of reply"
                if direction == S2C and entry and "RETURN_UNTIL_EMPTY" in entry.flag_set
                else "empty"
            )
            try:  # a type that gives the empty packet a meaning says so; for the others it is no error
                fields = self._typed(entry.name, side_of(direction), payload)[0] if entry else {}
            except Exception:
                fields = {}
            return fields, note
        if entry is None:
            return {}, "unknown data number" if session.datalist.have_list else None
        return self._typed(entry.name, side_of(direction), payload)

    def _typed(self, name: str, side: Side, payload: bytes) -> tuple[dict[str, Any], str | None]:
        if not self.decode_payloads:
            return {}, None
        kind = payload_type_for(name, side)
        if kind is None:
            return {}, None
        return kind.decode(payload).to_fields(), None

    def _control(self, session: Conversation, direction: str, packet: Packet) -> dict[str, Any]:
        """A control packet's fields, decoded by the same types the client and the server use."""
        command = packet.command
        if direction == S2C and command in _LIST_COMMANDS:
            session.datalist.absorb(packet)
            return _list_fields(packet)
        kind = control.control_type(command, side_of(direction))
        if kind is None:
            return {}
        decoded = kind.decode(packet.payload)
        _learn_handshake(session, decoded)
        if isinstance(decoded, control.Request):
            return self._request_fields(session, decoded)
        if isinstance(decoded, control.RequestStop):
            return {"data": decoded.number, "data_name": session.datalist.name(decoded.number)}
        fields = decoded.to_fields()
        if isinstance(decoded, control.Rejected):
            fields["explanation"] = decoded.explanation
        elif isinstance(decoded, control.ClientIntroduction):
            fields["client_type_name"] = _CLIENT_TYPES.get(decoded.client_type, "?")
        return fields

    def _request_fields(self, session: Conversation, request: control.Request) -> dict[str, Any]:
        """A REQUEST with its data's name and, where a type is registered, its arguments decoded."""
        data_name = session.datalist.name(request.number)
        fields: dict[str, Any] = {
            "data": request.number,
            "data_name": data_name,
            "interval_ms": request.interval_ms,
        }
        if request.args:
            fields["args_length"] = len(request.args)
            fields["args"] = request.args.hex()
            if data_name:
                try:
                    decoded, _ = self._typed(data_name, Side.ARGS, request.args)
                except Exception as exc:
                    raise _PartialDecode(fields, f"arguments: {type(exc).__name__}: {exc}") from exc
                if decoded:
                    fields["args"] = decoded
        return fields


def _learn_handshake(session: Conversation, decoded: control.ControlPayload) -> None:
    """Keep what attributes UDP datagrams to this session, and what the summary reports."""
    if isinstance(decoded, control.ServerIntroduction):
        session.server_udp_port = decoded.udp_port
        session.auth_key = decoded.auth_key
        session.intro_key = decoded.intro_key
    elif isinstance(decoded, control.ClientIntroduction):
        session.client_udp_port = decoded.udp_port
        session.user = decoded.user
    elif isinstance(decoded, control.Rejected):
        session.rejected = decoded.explanation


class _PartialDecode(Exception):
    """Some fields decoded before a later part failed: keep them and report the failure."""

    def __init__(self, fields: dict[str, Any], message: str) -> None:
        super().__init__(message)
        self.fields = fields
        self.message = message


def _list_fields(packet: Packet) -> dict[str, Any]:
    """All entries of a list packet, in the words of its kind (name/description, group/flags…)."""
    first, second, counted = _LIST_COMMANDS[ServerCommand(packet.command)]
    r = FieldReader(packet.payload)
    count = r.ubyte2("count") if counted else 1
    entries: list[dict[str, Any]] = []
    while len(entries) < count and not r.at_end():
        entries.append({"number": r.ubyte2("data number"), first: r.string(first), second: r.string(second)})
    fields: dict[str, Any] = {"count": count, "entries": entries}
    if len(entries) < count:  # ARIA drops entries that overflow its packet buffer
        fields["entries_missing"] = count - len(entries)
    return fields


def _guess_server(flow: Flow, src: Endpoint, data: bytes) -> Endpoint:
    """No SYN seen: decide from what ``src`` sends first, then from the ports."""
    verdict = _sender_is_server(data)
    if verdict is None:
        if flow.transport == "stream":
            verdict = True  # assume the dump came from the robot
        else:
            return _port_guess(flow.first, flow.second)
    return src if verdict else flow.peer_of(src)


def _sender_is_server(data: bytes) -> bool | None:
    probe = PacketDecoder()
    for packet in probe.feed(data[: 1 << 16])[:32]:
        cmd, payload = packet.command, packet.payload
        if cmd == ServerCommand.INTRODUCTION:
            return payload.startswith(b"alpha\x00")
        if cmd in _SERVER_ONLY:
            return True
        if cmd == ClientCommand.LIST:
            return False
        if cmd == ServerCommand.LIST and len(payload) >= 4:
            return int.from_bytes(payload[:2], "little") < 256  # LIST starts with a count
        if cmd == ClientCommand.REQUESTSTOP and len(payload) == 2:
            return False
    return None


def _port_guess(a: Endpoint, b: Endpoint) -> Endpoint:
    """ARIA's default port, else the lower port number (clients use ephemeral ports)."""
    if a.port == DEFAULT_SERVER_PORT or b.port == DEFAULT_SERVER_PORT:
        return a if a.port == DEFAULT_SERVER_PORT else b
    return a if a.port <= b.port else b
