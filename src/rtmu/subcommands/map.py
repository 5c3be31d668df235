"""``rtmu map HOST[:PORT] --out FILE``: download the server's map and write it as an ARIA ``.map`` file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.errors import ProtocolFault
from ..client.roles import Role
from ._common import UsageError, add_connection_arguments, fail, run_with_client
from ._output import add_force_option, check_file, write_whole

if TYPE_CHECKING:
    from ..client.connection import AriaClient


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "map",
        help=_("download the robot's map to a .map file"),
        description=_(
            "Download the server's map (getMapBinary when offered; --text forces getMap) "
            "and write it in ARIA's .map format."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--out", type=Path, required=True, metavar="FILE", help=_("where to write the map"))
    p.add_argument("--text", action="store_true", help=_("use getMap (one text line per packet)"))
    add_force_option(p)
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.mapload import download_map
    from ..mapfile.errors import MapFormatError
    from ..mapfile.writer import map_bytes

    try:
        check_file(args.out, force=args.force)  # before connecting: nothing downloaded for nothing
    except UsageError as exc:
        return fail("map", str(exc), EXIT_USAGE)

    async def body(client: AriaClient) -> int:
        got = await download_map(client, prefer_binary=not args.text, timeout=args.timeout)
        if got.data is None:
            return fail("map", f"{args.server[0]}:{args.server[1]} has no map loaded", EXIT_UNSUPPORTED)
        try:
            payload = map_bytes(got.data)
        except (MapFormatError, ValueError) as exc:  # parsed, yet not writable as a .map file
            reason = f"the map from {got.source!r} cannot be written as a .map file: {exc}"
            raise ProtocolFault(reason) from None
        written = write_whole(args.out, payload, force=args.force)
        name = f" ({visible(got.name)})" if got.name else ""
        if written != args.out:
            print(
                _("rtmu map: {out} appeared meanwhile; kept it, wrote {written}").format(
                    out=args.out, written=written
                ),
                file=sys.stderr,
            )
        print(
            _(
                "wrote {written}{name}: {num_points} points, {num_lines} lines via {source} in "
                "{packets} packets"
            ).format(
                written=written,
                name=name,
                num_points=got.data.num_points,
                num_lines=got.data.num_lines,
                source=got.source,
                packets=got.packets,
            ),
            file=sys.stderr,
        )
        return EXIT_OK

    return run_with_client("map", args, body, role=Role.OBSERVER)
