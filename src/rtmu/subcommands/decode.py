"""``rtmu decode FILE``: show every ArNetworking packet of a capture, hex dump or raw byte file.

The tool for when a robot misbehaves: which end said what, in which order,
with which fields, and what the receiver would have thrown away. Text output
folds long runs of one packet kind (a 63 824-line map) to their first and last
few lines and ends with a per-connection summary; ``--all`` prints everything
in full; ``--json`` prints one object per packet per line.
"""

from __future__ import annotations

import argparse

from ..base.exit_codes import EXIT_BAD_FILE, EXIT_OK, EXIT_SIGPIPE, EXIT_USAGE
from ..base.i18n import N_, _
from ..capture.choices import DIRECTIONS, FORMATS

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
    from ._decode_run import run as decode  # (the reader and decoder load only to run)

    return decode(args)
