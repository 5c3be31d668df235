"""``rtmu decode``'s text output: packet lines, folded runs and the summary, for people.

The words are the operator's language (``base.i18n``); numbers are written as the protocol and the
capture give them (times, lengths, counts: columns a person compares with Wireshark). What a packet
carries — names, fields, strings — comes from the capture and is shown as it is, escaped once per
line. ``--json`` (``decode.py``) never comes here and stays English.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, TextIO

from ..base.i18n import N_, _, ngettext, number
from ..base.textsafe import visible
from ..base.units import quantity
from ..capture.conversation import (
    C2S,
    S2C,
    Conversation,
    DecodedPacket,
    DecodeItem,
    DropReport,
    TrailingDrops,
)
from ..capture.session_decoder import CaptureDecoder

if TYPE_CHECKING:
    from ..capture import CaptureSource

RUN_HEAD = 3
RUN_TAIL = 2
SHORT_TEXT = 72
SHORT_LIST = 6
SHORT_ENTRIES = 12
SHORT_ENTRY = 40
PREVIEW_BYTES = 24
LINK_NAMES = {
    0: "BSD loopback",
    1: "Ethernet",
    12: "raw IP",
    14: "raw IP",
    101: "raw IP",
    108: "OpenBSD loopback",
    113: "Linux cooked",
    228: "raw IPv4",
    229: "raw IPv6",
    276: "Linux cooked v2",
}
DROP_WORDS: dict[str, Callable[[int], str]] = {
    "garbage_bytes": lambda n: ngettext("{count} garbage byte", "{count} garbage bytes", n),
    "bad_length": lambda n: ngettext("{count} bad length field", "{count} bad length fields", n),
    "bad_checksum": lambda n: ngettext("{count} bad checksum", "{count} bad checksums", n),
    "truncated_at_close": lambda n: ngettext(
        "{count} packet cut off at the end", "{count} packets cut off at the end", n
    ),
    "capture_gap_bytes": lambda n: ngettext(
        "{count} byte missing from the capture", "{count} bytes missing from the capture", n
    ),
}
"""Each drop count's words (its key is the --json field), in the operator's language and plural."""
CAPTURE_NOTES: tuple[Callable[[int], str], ...] = (
    lambda n: ngettext("note: {count} frame was not TCP/UDP over IP (skipped)",
                       "note: {count} frames were not TCP/UDP over IP (skipped)", n),
    lambda n: ngettext("note: {count} IP fragment (not reassembled, skipped)",
                       "note: {count} IP fragments (not reassembled, skipped)", n),
    lambda n: ngettext("note: {count} frame cut by the snap length",
                       "note: {count} frames cut by the snap length", n),
    lambda n: ngettext("note: {count} TCP byte retransmitted (counted once)",
                       "note: {count} TCP bytes retransmitted (counted once)", n),
    lambda n: ngettext("note: {count} TCP segment arrived out of order (reordered)",
                       "note: {count} TCP segments arrived out of order (reordered)", n),
    lambda n: ngettext("note: {count} hole in TCP streams (bytes never captured)",
                       "note: {count} holes in TCP streams (bytes never captured)", n),
    lambda n: ngettext("note: {count} TCP connection carried no ArNetworking packet (ignored)",
                       "note: {count} TCP connections carried no ArNetworking packet (ignored)", n),
    lambda n: ngettext("note: {count} UDP datagram was not ArNetworking (ignored)",
                       "note: {count} UDP datagrams were not ArNetworking (ignored)", n),
)  # fmt: skip
"""The summary's notes on the capture, in the order ``write_text_summary`` counts them."""
NOTES = (
    N_("checksum mismatch: dropped by the receiver"),
    N_("end of reply"),
    N_("empty"),
    N_("unknown data number"),
)
"""The notes the capture decoder puts on a packet (English in --json), marked: the text says them
translated."""


def _drops_text(counts: dict[str, int]) -> str:
    return ", ".join(
        DROP_WORDS[k](n).format(count=n) if k in DROP_WORDS else f"{n} {k}" for k, n in counts.items()
    )


def relative(time: float | None, source: CaptureSource) -> float | None:
    base = source.stats.first_time
    if time is None or base is None:
        return None
    return round(time - base, 6)


class _TextWriter:
    """Prints packets; folds runs of one (conn, dir, transport, command) to head and tail."""

    def __init__(self, out: TextIO, source: CaptureSource, full: bool, payload: bool) -> None:
        self.out = out
        self.source = source
        self.full = full
        self.payload = payload
        self.lines: list[str] = []
        self.run_key: tuple[Any, ...] | None = None
        self.run_count = 0
        self.run_first_time: float | None = None
        self.tail: deque[DecodedPacket] = deque(maxlen=RUN_TAIL)
        self.hidden = 0
        self.hidden_last: DecodedPacket | None = None

    def item(self, item: DecodeItem) -> None:
        if isinstance(item, TrailingDrops):
            return  # its drops were printed as they happened
        if isinstance(item, DropReport):
            self._end_run()
            self._emit(self._drop_line(item))
            return
        if self.full:
            self._emit(self._packet_line(item))
            return
        plain = item.checksum_ok and not item.error
        key = (item.conn, item.direction, item.transport, item.command) if plain else None
        if key is None or key != self.run_key:
            self._end_run()
            self.run_key = key
            self.run_count = 0
        self.run_count += 1
        if self.run_count <= RUN_HEAD or key is None:
            self._emit(self._packet_line(item))
            return
        if len(self.tail) == RUN_TAIL:
            self.hidden += 1
            self.hidden_last = self.tail[0]
            if self.hidden == 1:
                self.run_first_time = self.tail[0].time
        self.tail.append(item)

    def _end_run(self) -> None:
        if self.hidden:
            last = self.hidden_last
            assert last is not None
            span = ""
            start = relative(self.run_first_time, self.source)
            end = relative(last.time, self.source)
            if start is not None and end is not None:
                span = " " + _("over {duration}").format(duration=quantity(end - start, "s", 3))
            label = last.name or _("command {number}").format(number=last.command)
            more = ngettext(
                "… {count} more {label} packet{span} (--all shows it) …",
                "… {count} more {label} packets{span} (--all shows them) …",
                self.hidden,
            ).format(count=self.hidden, label=label, span=span)
            self._emit(f"{'':>10} {last.conn:>3} {last.direction} {last.transport:<6} {more}")
        for packet in self.tail:
            self._emit(self._packet_line(packet))
        self.tail.clear()
        self.hidden = 0
        self.hidden_last = None
        self.run_key = None

    def finish(self) -> None:
        self._end_run()
        self.flush()

    def _emit(self, line: str) -> None:
        self.lines.append(visible(line))  # packet strings come from the capture: untrusted text
        if len(self.lines) >= 2048:
            self.flush()

    def flush(self) -> None:
        if self.lines:
            self.out.write("\n".join(self.lines) + "\n")
            self.lines.clear()

    def _time(self, time: float | None) -> str:
        rel = relative(time, self.source)
        return f"{rel:>10.6f}" if rel is not None else f"{'-':>10}"

    def _drop_line(self, drop: DropReport) -> str:
        what = _("!! dropped: {what}").format(what=_drops_text(drop.counts))
        return f"{self._time(drop.time)} {drop.conn:>3} {drop.direction} {drop.transport:<6} {what}"

    def _packet_line(self, p: DecodedPacket) -> str:
        name = p.name if p.name else ("?" if p.is_data else _("(unknown control)"))
        where = f"{self._time(p.time)} {p.conn:>3} {p.direction} {p.transport:<6}"
        head = f"{where} {p.command:>5} {name:<22} {p.length:>5}"
        parts: list[str] = []
        if not p.checksum_ok:
            parts.append(_("BAD CHECKSUM"))
        if p.fields:
            parts.append(format_fields(p.fields, self.full))
        if p.note:
            parts.append(f"({_(p.note)})")
        if p.error:
            # the codec's own detail stays as it says it (it imports nothing of the operator's language)
            parts.append(_("!! does not decode: {error}").format(error=p.error))
        if p.payload and (
            self.payload or (not p.fields and not p.error and p.note is None) or not p.checksum_ok
        ):
            parts.append(_preview(p.payload, self.full or self.payload))
        return f"{head}  {' '.join(parts)}" if parts else head


def write_text(
    out: TextIO, items: Iterable[DecodeItem], source: CaptureSource, *, full: bool, payload: bool
) -> None:
    writer = _TextWriter(out, source, full, payload)
    kind = source.kind
    out.write(f"# {visible(source.path.name)}: {kind}{_link(source)}\n")
    # TRANSLATORS: the column heads of rtmu decode's packet lines (each over its column; keep them short).
    time, name, length = _("time"), _("name"), _("length")
    fields = _("fields (checksum ok unless marked)")
    out.write(f"# {time:>8} {'conn':>3} dir transport cmd {name:<22} {length:>5}  {fields}\n")
    for item in items:
        writer.item(item)
    writer.finish()


def _link(source: CaptureSource) -> str:
    lt = source.stats.link_type
    if lt is None:
        return ""
    return ", " + _("link type {number} ({name})").format(
        number=lt, name=LINK_NAMES.get(lt) or _("unsupported")
    )


def _preview(payload: bytes, full: bool) -> str:
    shown = payload if full else payload[:PREVIEW_BYTES]
    hidden = len(payload) - len(shown)
    more = (
        " " + ngettext("…(+{count} byte)", "…(+{count} bytes)", hidden).format(count=hidden) if hidden else ""
    )
    text = "".join(chr(b) if 32 <= b < 127 else "." for b in shown)
    return f"[{shown.hex(' ')}{more}] |{text}|"


def format_fields(fields: dict[str, Any], full: bool = False) -> str:
    """``key=value`` pairs; long strings and lists are shortened unless ``full``."""
    entries = fields.get("entries")
    if isinstance(entries, list) and entries and isinstance(entries[0], dict) and "number" in entries[0]:
        rest = {k: v for k, v in fields.items() if k != "entries"}
        shown = entries if full else entries[:SHORT_ENTRIES]
        text = ", ".join(_entry(e, full) for e in shown)
        if len(shown) < len(entries):
            text += f", … +{len(entries) - len(shown)}"
        return (format_fields(rest, full) + " " if rest else "") + _("entries: {entries}").format(
            entries=text
        )
    return " ".join(f"{k}={_value(v, full)}" for k, v in fields.items())


def _entry(entry: dict[str, Any], full: bool) -> str:
    """One list entry: its number and texts (only the name, or the group and flags, when short)."""
    values = [str(v) for k, v in entry.items() if k != "number" and v != ""]
    if not full and "name" in entry:
        values = [str(entry["name"])]
    text = "/".join(values)
    if not full and len(text) > SHORT_ENTRY:
        text = text[:SHORT_ENTRY] + "…"
    return f"{entry['number']} {text}" if text else str(entry["number"])


def _value(value: Any, full: bool) -> str:
    """A field's value as text. A string is quoted and NOT escaped here: every text line is escaped
    once, whole, when it is written (``visible``: control characters, so one packet stays one line,
    and backslashes) — escaping here too showed a ``\\`` in a password key as four."""
    if isinstance(value, str):
        if not full and len(value) > SHORT_TEXT:
            value = value[:SHORT_TEXT] + "…"
        quote = '"' if "'" in value and '"' not in value else "'"
        return f"{quote}{value}{quote}"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, dict):
        return "{" + " ".join(f"{k}={_value(v, full)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        shown = value if full else value[:SHORT_LIST]
        inner = ", ".join(_value(v, full) for v in shown)
        if len(shown) < len(value):
            inner += f", … +{len(value) - len(shown)} (n={len(value)})"
        return f"[{inner}]"
    return str(value)


def write_text_summary(out: TextIO, decoder: CaptureDecoder, source: CaptureSource, *, full: bool) -> None:
    stats = source.stats
    lines = ["", _("== summary")]
    if stats.kind in ("pcap", "pcapng"):
        frames = ngettext("capture: {count} frame", "capture: {count} frames", stats.frames)
        frames = frames.format(count=stats.frames)
        if stats.first_time is not None and stats.last_time is not None:
            frames += ", " + quantity(stats.last_time - stats.first_time, "s", 3)
        lines.append(frames)
    if not decoder.sessions:
        lines.append(_("no ArNetworking packets found"))
    for session in decoder.sessions:
        lines.extend(_session_lines(session, source, full))
    counts = (
        stats.not_ip, stats.ip_fragments, stats.truncated_frames, stats.retransmitted_bytes,
        stats.out_of_order_segments, stats.tcp_gaps, decoder.ignored_tcp_flows, decoder.ignored_datagrams,
    )  # fmt: skip
    lines.extend(say(n).format(count=n) for n, say in zip(counts, CAPTURE_NOTES, strict=True) if n)
    out.write("\n".join(visible(line) for line in lines) + "\n")


def _session_lines(session: Conversation, source: CaptureSource, full: bool) -> list[str]:
    start = relative(session.first_time, source)
    end = relative(session.last_time, source)
    when = ""
    if start is not None and end is not None:
        when = "  " + _("{start}–{end} s").format(start=number(start, 3), end=number(end, 3))
    if session.transport == "stream":
        by_server = session.server == session.ends[0]
        who = _("bytes sent by the server") if by_server else _("bytes sent by the client")
        if session.server_guessed:
            who += " " + _("(guessed; use --direction to say)")
    else:
        who = (
            _("client {client}  server {server} (guessed)")
            if session.server_guessed
            else _("client {client}  server {server}")
        )
        who = who.format(client=session.client, server=session.server)
    head = _("conn {number}: {transport} {who}{when}")
    lines = [head.format(number=session.id, transport=session.transport, who=who, when=when)]
    if session.udp_datagrams and session.transport != "udp":
        flows = "; ".join(sorted({" ↔ ".join(sorted((str(a), str(b)))) for a, b in session.udp_flows}))
        udp = ngettext(
            "  + {count} UDP datagram ({flows})", "  + {count} UDP datagrams ({flows})", session.udp_datagrams
        )
        lines.append(udp.format(count=session.udp_datagrams, flows=flows))
    if session.rejected:
        lines.append(_("  rejected: {reason}").format(reason=_(session.rejected)))
    if session.datalist.have_list:
        count = len(session.datalist)
        lines.append(
            ngettext("  data list: {count} name", "  data list: {count} names", count).format(count=count)
        )
    for direction in (C2S, S2C):
        totals = session.totals[direction]
        if not totals.packets and not totals.drops:
            continue
        names = totals.by_name.most_common()
        shown = names if full else names[:10]
        text = ", ".join(f"{n} ×{c}" for n, c in shown)
        if len(shown) < len(names):
            hidden = len(names) - len(shown)
            text += ", " + ngettext("… +{count} name", "… +{count} names", hidden).format(count=hidden)
        packets = ngettext("{count} packet", "{count} packets", totals.packets).format(count=totals.packets)
        size = ngettext("{count} byte", "{count} bytes", totals.bytes).format(count=totals.bytes)
        lines.append(f"  {direction} {packets}, {size}: {text}")
    drops = [f"{d} " + _drops_text(session.totals[d].drops) for d in (C2S, S2C) if session.totals[d].drops]
    lines.append(_("  dropped: {what}").format(what="; ".join(drops) if drops else _("nothing")))
    if session.held_overflow:
        held = session.held_overflow
        held_words = ngettext(
            "  ({count} bad packet before the first good one was not shown)",
            "  ({count} bad packets before the first good one were not shown)",
            held,
        )
        lines.append(held_words.format(count=held))
    return lines
