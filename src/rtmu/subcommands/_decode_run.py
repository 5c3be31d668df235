"""``rtmu decode``'s work: read the capture, decode it, print text or JSON (the parser is ``decode``).

Kept apart from the parser so that ``rtmu decode --help`` loads no capture reader, decoder or
payload module (issue 28: every ``--help`` within 0.15 s of CPU).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Iterable
from typing import Any, TextIO

from ..base.exit_codes import EXIT_BAD_FILE, EXIT_OK, EXIT_SIGPIPE, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import json_safe, visible
from ..capture import CaptureError, CaptureSource, UnreadableInput, open_capture
from ..capture.conversation import (
    Conversation,
    DecodedPacket,
    DecodeItem,
    TrailingDrops,
)
from ..capture.session_decoder import CaptureDecoder
from ._decode_text import relative, write_text, write_text_summary


def run(args: argparse.Namespace) -> int:

    try:
        source = open_capture(args.file, args.format, args.direction)
    except UnreadableInput as exc:
        return _failed(_("rtmu decode: the file cannot be read ({detail})"), exc, EXIT_USAGE)
    except CaptureError as exc:
        return _failed(_("rtmu decode: the file cannot be decoded ({detail})"), exc, EXIT_BAD_FILE)
    decoder = CaptureDecoder(report_trailing_drops=args.json)
    summary = args.summary if args.summary is not None else not args.json
    out = sys.stdout
    try:
        items = _filtered(decoder.run(source.events()), args)
        if args.json:
            _write_json(out, items, source, args.payload)
        else:
            write_text(out, items, source, full=args.all, payload=args.payload)
        if summary:
            if args.json:
                _write_json_summary(out, decoder, source)
            else:
                write_text_summary(out, decoder, source, full=args.all)
        out.flush()
    except UnreadableInput as exc:
        return _failed(_("rtmu decode: the file cannot be read ({detail})"), exc, EXIT_USAGE)
    except CaptureError as exc:
        return _failed(_("rtmu decode: the file cannot be decoded ({detail})"), exc, EXIT_BAD_FILE)
    except BrokenPipeError:  # `rtmu decode x | head`: the reader has seen enough (141, as every command)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_SIGPIPE
    for warning in source.stats.warnings:
        print(_("rtmu decode: warning: {visible}").format(visible=visible(warning)), file=sys.stderr)
    return EXIT_OK


def _failed(sentence: str, error: Exception, code: int) -> int:
    """One line on stderr: RTMU's sentence, the capture reader's own words (English) as its detail."""
    print(sentence.format(detail=visible(error)), file=sys.stderr)
    return code


def _filtered(items: Iterable[DecodeItem], args: argparse.Namespace) -> Iterable[DecodeItem]:
    conns = set(args.conn or ())
    names = set(args.name or ())
    if not conns and not names:
        return items
    return (
        item
        for item in items
        if (not conns or item.conn in conns)
        and (
            not names
            or (isinstance(item, DecodedPacket) and (item.name in names or str(item.command) in names))
        )
    )


# -- JSON -------------------------------------------------------------------
def packet_json(packet: DecodedPacket, source: CaptureSource, payload: bool = False) -> dict[str, Any]:
    record: dict[str, Any] = {
        "conn": packet.conn,
        "dir": packet.direction,
        "transport": packet.transport,
        "time": relative(packet.time, source),
        "command": packet.command,
        "name": packet.name,
        "length": packet.length,
        "checksum_ok": packet.checksum_ok,
        "fields": packet.fields,
    }
    if packet.error:
        record["error"] = packet.error
    if packet.note:
        record["note"] = packet.note
    if packet.dropped_before:
        record["dropped_before"] = packet.dropped_before
    if payload:
        record["payload"] = packet.payload.hex()
    return record


def trailing_drops_json(drops: TrailingDrops, source: CaptureSource) -> dict[str, Any]:
    """The packet keys, so a consumer can treat every line alike; ``kind`` says it is no packet."""
    return {
        "conn": drops.conn,
        "dir": drops.direction,
        "transport": drops.transport,
        "time": relative(drops.time, source),
        "kind": "dropped",
        "command": None,
        "name": None,
        "length": drops.counts.get("garbage_bytes", 0),
        "checksum_ok": False,
        "fields": drops.counts,
    }


def _dumps(record: dict[str, Any]) -> str:
    try:
        return json_safe(
            json.dumps(
                record, ensure_ascii=False, separators=(",", ":"), allow_nan=False, default=_json_default
            )
        )
    except ValueError:  # an infinity (ARIA's "INF" doubles): spell it as ARIA does
        return json_safe(
            json.dumps(_finite(record), ensure_ascii=False, separators=(",", ":"), default=_json_default)
        )


def _json_default(value: Any) -> Any:
    if isinstance(value, (bytes, bytearray, memoryview)):
        return bytes(value).hex()
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (set, frozenset)):
        return sorted(value)
    return str(value)


def _finite(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("INF" if value > 0 else "-INF")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def _write_json(out: TextIO, items: Iterable[DecodeItem], source: CaptureSource, payload: bool) -> None:
    batch: list[str] = []
    for item in items:
        if isinstance(item, DecodedPacket):
            batch.append(_dumps(packet_json(item, source, payload)))
        elif isinstance(item, TrailingDrops):
            batch.append(_dumps(trailing_drops_json(item, source)))
        else:
            continue
        if len(batch) >= 2048:
            out.write("\n".join(batch) + "\n")
            batch.clear()
    if batch:
        out.write("\n".join(batch) + "\n")


def _write_json_summary(out: TextIO, decoder: CaptureDecoder, source: CaptureSource) -> None:
    for session in decoder.sessions:
        record = {"kind": "summary", "conn": session.id, **_session_facts(session, source)}
        out.write(_dumps(record) + "\n")
    stats = source.stats
    capture = {
        "kind": "capture",
        "format": stats.kind,
        "link_type": stats.link_type,
        "frames": stats.frames,
        "not_ip_frames": stats.not_ip,
        "ip_fragments": stats.ip_fragments,
        "truncated_frames": stats.truncated_frames,
        "retransmitted_bytes": stats.retransmitted_bytes,
        "out_of_order_segments": stats.out_of_order_segments,
        "tcp_gaps": stats.tcp_gaps,
        "ignored_tcp_connections": decoder.ignored_tcp_flows,
        "ignored_udp_datagrams": decoder.ignored_datagrams,
        "warnings": stats.warnings,
    }
    out.write(_dumps(capture) + "\n")


def _session_facts(session: Conversation, source: CaptureSource) -> dict[str, Any]:
    return {
        "transport": session.transport,
        "client": str(session.client) if session.client else None,
        "server": str(session.server) if session.server else None,
        "server_guessed": session.server_guessed,
        "start": relative(session.first_time, source),
        "end": relative(session.last_time, source),
        "udp_datagrams": session.udp_datagrams,
        "data_names": len(session.datalist),
        "rejected": session.rejected,
        "directions": {
            d: {
                "packets": t.packets,
                "bytes": t.bytes,
                "by_name": dict(t.by_name.most_common()),
                "dropped": dict(t.drops),
            }
            for d, t in session.totals.items()
        },
    }
