"""``rtmu image HOST[:PORT] --out FILE.jpg``: save one camera picture."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..cli import EXIT_OK
from ..client.connection import AriaClient
from ..client.errors import NotSupported
from ._common import add_connection_arguments, run_with_client


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "image",
        help="save one camera picture (JPEG)",
        description="Request one picture (getPicture<camera>, else sendVideo) and save the JPEG.",
    )
    add_connection_arguments(p)
    p.add_argument("--out", type=Path, required=True, metavar="FILE.jpg", help="where to write the JPEG")
    p.add_argument("--camera", default=None, metavar="NAME", help="camera name (getPicture<NAME>)")
    p.add_argument("--quality", type=int, default=None, metavar="Q", help="JPEG quality 0…100 to ask for")
    p.set_defaults(handler=handle)


def picture_source(client: AriaClient, camera: str | None) -> str:
    if camera is not None:
        name = f"getPicture{camera}"
        if not client.supports(name):
            raise NotSupported(name, f"this server has no camera named {camera!r} ({name})")
        return name
    pictures = sorted(e.name for e in client.datalist if e.name.startswith("getPicture"))
    if pictures:
        return pictures[0]
    if client.supports("sendVideo"):
        return "sendVideo"
    raise NotSupported("getPicture", "this server offers no camera pictures (getPicture… or sendVideo)")


def handle(args: argparse.Namespace) -> int:
    async def body(client: AriaClient) -> int:
        source = picture_source(client, args.camera)
        extra: tuple[bytes, ...] = ()
        if args.quality is not None:
            extra = (bytes([max(0, min(100, args.quality))]),)
        reply = await client.request_once(source, *extra, timeout=args.timeout)
        picture = reply.decode()  # MalformedReply (exit 3, one line) if it does not decode
        jpeg = bytes(picture.jpeg)  # type: ignore[attr-defined]
        args.out.write_bytes(jpeg)
        size = f"{picture.width}x{picture.height}"  # type: ignore[attr-defined]
        print(f"wrote {args.out}: {size}, {len(jpeg)} bytes from {source}", file=sys.stderr)
        return EXIT_OK

    return run_with_client("image", args, body)
