"""``rtmu decode FILE``: show every ArNetworking packet of a capture, hex dump or raw byte file.

The tool for when a robot misbehaves: which end said what, in which order,
with which fields, and what the receiver would have thrown away. Text output
folds long runs of one packet kind (a 63 824-line map) to their first and last
few lines and ends with a per-connection summary; ``--all`` prints everything
in full; ``--json`` prints one object per packet per line.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any, TextIO

from ..base.exit_codes import EXIT_BAD_FILE, EXIT_OK, EXIT_SIGPIPE, EXIT_USAGE
from ..base.i18n import N_, _
from ..base.textsafe import json_safe, visible
from ..capture import CaptureError, CaptureSource, UnreadableInput, open_capture
from ..capture.conversation import (
    Conversation,
    DecodedPacket,
    DecodeItem,
    TrailingDrops,
)
from ..capture.reader import DIRECTIONS, FORMATS
from ..capture.session_decoder import CaptureDecoder
from ._decode_text import relative, write_text, write_text_summary

if TYPE_CHECKING:
    from ..capture import CaptureSource

EXITS = (EXIT_OK, EXIT_USAGE, EXIT_BAD_FILE, EXIT_SIGPIPE)
_DESCRIPTION = N_("""\
Show every ArNetworking packet of a capture: which end sent it, its command and
name (control commands by direction, data names from that connection's own
LIST), length, checksum, decoded fields, and what a receiver would drop.

Inputs: pcap or pcapng (TCP reassembled on any port, UDP datagrams attributed
to their connection), an RTMU recording (FILE.mcap from the window or rtmu
record: its raw channel, every connection in it), a hex dump (xxd, hexdump, od, tshark, plain hex) or raw
bytes (one stream; --direction says who sent it when the packets do not).""")

_EPILOG = N_("""\
text output folds runs of one packet kind to their first 3 and last 2 lines;
--all prints everything. --json prints one object per packet and line:
  conn dir transport time command name length checksum_ok fields
  [error] [note] [dropped_before] [payload]
and, where a stream (or datagram) ends in bytes no packet follows, one line
with "kind": "dropped", command and name null, length = the bytes dropped,
checksum_ok false and the drop counts as fields.
exit status: 0 the file was read (even with bad packets), 1 it cannot be read,
4 it is not a recognised format.

examples:
  rtmu decode session.pcap
  rtmu decode ~/.local/share/rtmu/recordings/20261125T041500Z_lab_7272.mcap
  rtmu decode --json session.pcap | jq 'select(.name == "ratioDrive") | .fields'
  rtmu decode --name getMapBinary --all session.pcap
  xxd bytes.bin > dump.txt && rtmu decode --direction c2s dump.txt""")


def register(subparsers: argparse._SubParsersAction) -> None:

    parser = subparsers.add_parser(
        "decode",
        help=_("decode ArNetworking traffic from a pcap/pcapng capture, a hex dump or raw bytes"),
        description=_(_DESCRIPTION),
        epilog=_(_EPILOG),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "file", metavar="FILE", help=_("capture (pcap, pcapng), recording (.mcap), hex dump or raw bytes")
    )
    parser.add_argument("--format", choices=FORMATS, default="auto", help=_("input format (default: detect)"))
    parser.add_argument(
        "--direction",
        choices=DIRECTIONS,
        default="auto",
        help=_("hex/raw input: who sent the bytes (default: guess from the packets, else s2c)"),
    )
    parser.add_argument("--json", action="store_true", help=_("one JSON object per packet per line"))
    parser.add_argument("--all", action="store_true", help=_("print every packet and every field in full"))
    parser.add_argument(
        "--conn", type=int, action="append", metavar="N", help=_("only connection N (repeatable)")
    )
    parser.add_argument(
        "--name",
        action="append",
        metavar="NAME",
        help=_("only packets with this name or command number (repeatable)"),
    )
    parser.add_argument("--payload", action="store_true", help=_("add each payload in hex"))
    parser.add_argument(
        "--summary",
        action=argparse.BooleanOptionalAction,
        default=None,
        help=_("per-connection summary at the end (default: on for text, off for --json)"),
    )
    parser.set_defaults(handler=run)


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
