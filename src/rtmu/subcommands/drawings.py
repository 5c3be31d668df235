"""``rtmu drawings HOST[:PORT] [--json]``: what the server draws on its map, with one sample of each.

One line per drawing of ``getDrawingList`` — name, shape, colour, size, layer, refresh period,
visibility — and how many points one request of its data returned now. A shape RTMU cannot draw
is listed with a note; a drawing whose sample is malformed or never comes says so, and the other
drawings are still shown. A list longer than RTMU keeps (256) is printed as far as it is kept, and
what was left out is said on stderr. Exit 0 with the list, 4 when the server lists no drawings.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.errors import ClientError
from ..client.roles import Role
from ..protocol.payloads.drawings import Drawing
from ._common import add_connection_arguments, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient

SAMPLES_AT_ONCE = 16
"""Drawings sampled at the same time: a long list whose samples never come waits its timeout a few times,
not once for each drawing."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "drawings",
        help=_("list the server's drawings (getDrawingList) with one current sample of each"),
        description=(
            _(
                "Print each drawing the server lists (sonar, lasers, paths …): shape, colour, size, layer, "
                "refresh period, visibility and the points one request returns now (exit 4 when it "
                "lists none)."
            )
        ),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json", action="store_true", help=_("one JSON array: every field and the sampled points")
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    import asyncio

    from ..client.drawing_list import drawing_list

    async def body(client: AriaClient) -> int:
        listed = await drawing_list(client, args.timeout)  # NotSupported (exit 4) without a list
        rows: list[dict[str, Any]] = []
        for start in range(0, len(listed.drawings), SAMPLES_AT_ONCE):
            batch = listed.drawings[start : start + SAMPLES_AT_ONCE]
            rows += await asyncio.gather(*(_sample(client, d, args.timeout) for d in batch))
        if listed.dropped:
            print(
                _("rtmu drawings: {dropped_text} (not sampled, not shown)").format(
                    dropped_text=listed.dropped_text()
                ),
                file=sys.stderr,
            )
        if args.json:
            print_json(rows)
        elif not rows:
            print(_("the server lists no drawings"), flush=True)
        else:
            for row in rows:
                print(_line(row), flush=True)
        return EXIT_OK

    return run_with_client("drawings", args, body, role=Role.OBSERVER)


async def _sample(client: AriaClient, d: Drawing, timeout: float) -> dict[str, Any]:
    from ..client.drawing_list import drawing_sample

    row: dict[str, Any] = {
        "name": d.name,
        "shape": d.shape,
        "drawn": d.known_shape is not None,
        "primary_color": f"#{d.primary_color & 0xFFFFFF:06x}",
        "secondary_color": f"#{d.secondary_color & 0xFFFFFF:06x}",
        "size": d.size,
        "layer": d.layer,
        "refresh_ms": d.refresh_ms,
        "visibility": d.visibility_kind.value,
        "points": None,
        "error": "",
    }
    try:
        row["points"] = [list(p) for p in (await drawing_sample(client, d.name, timeout)).points]
    except ClientError as exc:
        row["error"] = str(exc)
    return row


def _line(row: dict[str, Any]) -> str:
    refresh = f"every {row['refresh_ms']} ms" if row["refresh_ms"] else "when sent"
    words = [
        visible(row["name"]),
        visible(row["shape"]),
        row["primary_color"],
        f"size {row['size']}",
        f"layer {row['layer']}",
        refresh,
        visible(row["visibility"]),
    ]
    if row["error"]:
        words.append(f"no sample: {visible(row['error'])}")
    else:
        words.append(f"{len(row['points'])} points")
    if not row["drawn"]:
        words.append("(shape not known to RTMU: not drawn)")
    return "  ".join(words)
