"""``rtmu image HOST[:PORT] --out FILE.jpg``: save one camera picture."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.roles import Role
from ._common import UsageError, add_connection_arguments, fail, run_with_client
from ._options import add_quality_option
from ._output import add_force_option, check_file, write_whole

if TYPE_CHECKING:
    from ..client.connection import AriaClient

MAX_SIDE = 8192
"""Largest width or height accepted from a server; no robot camera comes near it."""


def picture_problem(jpeg: bytes, width: int, height: int) -> str | None:
    """Why ``jpeg`` is not a sane picture of the claimed size, in plain words; None when it is.

    Its header is read first and its data must be able to fill the size it declares
    (:mod:`rtmu.client.jpeg_bounds`); then it is decoded at 1/8 scale, which reads all its data at
    a fraction of its pixels' memory. Bytes that are not a JPEG, truncated pictures and size fields
    that lie are caught before anything lands on disk.
    """
    from ..client.jpeg_bounds import decode_problem, fill_problem, read_header

    if width > MAX_SIDE or height > MAX_SIDE:
        return f"the server claims a {width}x{height} picture, over the {MAX_SIDE}x{MAX_SIDE} limit"
    if not jpeg.startswith(b"\xff\xd8"):
        return f"the {len(jpeg)} bytes the server sent are not a complete JPEG picture"
    header = read_header(jpeg)
    if header.size is not None and (width, height) not in ((0, 0), header.size):
        w, h = header.size
        return f"the server says {width}x{height} but the picture is {w}x{h}"
    return fill_problem(jpeg, header) or decode_problem(jpeg)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "image",
        help=_("save one camera picture (JPEG)"),
        description=_("Request one picture (getPicture<camera>, else sendVideo) and save the JPEG."),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="FILE",
        help=_(
            "where to write the picture: FILE.jpg as the camera sent it, or another format Pillow "
            "writes (.png, .bmp, .tiff, .webp …), chosen by the name's ending"
        ),
    )
    p.add_argument("--camera", default=None, metavar="NAME", help=_("camera name (getPicture<NAME>)"))
    add_quality_option(p)
    add_force_option(p)
    p.set_defaults(handler=handle)


JPEG_ENDINGS = (".jpg", ".jpeg", ".jpe", ".jfif")


def image_format(path: Path) -> str:
    """The format the file name asks for ("JPEG", "PNG" …); :class:`UsageError` if none can be written."""
    ending = path.suffix.lower()
    if ending in JPEG_ENDINGS:
        return "JPEG"
    from PIL import Image

    Image.init()
    found = Image.registered_extensions().get(ending)
    if found is None or found not in Image.SAVE:
        named = f"ending {ending!r}" if ending else "no ending"
        raise UsageError(
            f"{path} has {named}: name the picture FILE.jpg (as sent), or .png, .bmp, .tiff or .webp"
        )
    return found


def converted(jpeg: bytes, fmt: str) -> bytes:
    """The picture in ``fmt`` (the JPEG bytes themselves for JPEG: nothing is re-compressed)."""
    if fmt == "JPEG":
        return jpeg
    import io

    from PIL import Image

    out = io.BytesIO()
    with Image.open(io.BytesIO(jpeg)) as img:
        img.save(out, format=fmt)
    return out.getvalue()


def handle(args: argparse.Namespace) -> int:
    from ..client.video_feed import video_source

    try:  # before connecting: a picture is not taken for a file that cannot be written
        fmt = image_format(args.out)
        check_file(args.out, force=args.force)
    except UsageError as exc:
        return fail("image", str(exc), EXIT_USAGE)

    async def body(client: AriaClient) -> int:
        source = video_source(client, args.camera)
        extra: tuple[bytes, ...] = ()
        if args.quality is not None:
            extra = (bytes([args.quality]),)
        reply = await client.request_once(source, *extra, timeout=args.timeout)
        picture = reply.decode()  # MalformedReply (exit 3, one line) if it does not decode
        jpeg = bytes(picture.jpeg)  # type: ignore[attr-defined]
        problem = picture_problem(jpeg, picture.width, picture.height)  # type: ignore[attr-defined]
        if problem is not None:
            return fail("image", f"{problem}; nothing saved", EXIT_CONNECTION)
        data = converted(jpeg, fmt)
        written = write_whole(args.out, data, force=args.force)
        if written != args.out:
            print(
                _("rtmu image: {out} appeared meanwhile; kept it, wrote {written}").format(
                    out=args.out, written=written
                ),
                file=sys.stderr,
            )
        size = f"{picture.width}x{picture.height}"  # type: ignore[attr-defined]
        print(
            _("wrote {written}: {size} {fmt}, {len} bytes from {visible}").format(
                written=written, size=size, fmt=fmt, len=len(data), visible=visible(source)
            ),
            file=sys.stderr,
        )
        return EXIT_OK

    return run_with_client("image", args, body, role=Role.OBSERVER)
