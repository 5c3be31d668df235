"""``rtmu files HOST[:PORT] ls|get|put|rm``: files in the robot's shared folder (ARIA's ArServerFileUtils).

Paths on the robot are relative to the folder it shares (``maps/office.map``); ``..``, a leading ``/``
and control characters are refused before anything is sent. A download is written to a hidden
temporary file beside the destination and renamed only when complete; an existing destination is
refused without ``--force`` (checked before connecting). ``put`` refuses to replace a file the robot
lists without ``--force``. ``rm`` asks on the terminal, naming the file, unless ``--yes``; without a
terminal it needs ``--yes``.
"""

from __future__ import annotations

import argparse
import datetime
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_REFUSED, EXIT_USAGE, NETWORK
from ..base.i18n import N_, _, number
from ..base.textsafe import visible
from ..base.units import quantity
from ..client.roles import Role
from ..protocol.payloads.files import DirEntry
from ._actions import action_parser, end_progress, progress_printer
from ._common import add_connection_arguments, fail, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient

EXITS = (*NETWORK, EXIT_REFUSED)
DESCRIPTION = N_(
    "Files in the folder the robot shares (paths relative to it). A bad path, a local file that exists "
    "without --force, or rm without --yes and no terminal to ask on are usage errors, found before "
    "connecting; a reply that cannot be trusted (a listing entry with a hostile name, a file longer than "
    "listed) is a protocol failure; what the robot refuses (no such file or folder, outside its folder, "
    "another client uploading the same file) is a refusal in its own words."
)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "files",
        help=_("list, download, upload and delete files on the robot (getDirListing, getFile, putFile …)"),
        description=_(DESCRIPTION),
    )
    add_connection_arguments(p)
    actions = p.add_subparsers(dest="action", metavar="ls|get|put|rm", required=True)
    ls = action_parser(
        actions, "ls", "list a folder", "List a folder on the robot (default: its shared folder)."
    )
    ls.add_argument("folder", nargs="?", default="", metavar="DIR", help=_("folder on the robot"))
    get = action_parser(
        actions, "get", "download a file", "Download REMOTE into LOCAL (default: its name, here)."
    )
    get.add_argument("remote", metavar="REMOTE", help=_("file on the robot"))
    get.add_argument("--out", type=Path, metavar="LOCAL", help=_("file (or existing folder) to write"))
    get.add_argument("--force", action="store_true", help=_("replace LOCAL if it exists"))
    put = action_parser(
        actions,
        "put",
        "upload a file",
        "Upload LOCAL as REMOTE (default: its own name, in the robot's default folder if it names one; "
        "a REMOTE ending in / is a folder).",
    )
    put.add_argument("local", type=Path, metavar="LOCAL", help=_("file to upload"))
    put.add_argument("remote", nargs="?", default=None, metavar="REMOTE", help=_("where on the robot"))
    put.add_argument("--force", action="store_true", help=_("replace REMOTE if the robot has it"))
    put.add_argument(
        "--interleaved", action="store_true", help=_("wait for the robot's answer to every packet (slower)")
    )
    rm = action_parser(actions, "rm", "delete a file", "Delete one file on the robot (asks first).")
    rm.add_argument("remote", metavar="REMOTE", help=_("file on the robot"))
    rm.add_argument("--yes", action="store_true", help=_("do not ask"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.download import LocalFileError

    try:
        body = {"ls": _ls, "get": _get, "put": _put, "rm": _rm}[args.action](args)
    except (ValueError, LocalFileError) as exc:
        return fail("files", str(exc), EXIT_USAGE)
    if isinstance(body, int):
        return body
    return run_with_client("files", args, body, role=Role.OBSERVER)  # files, never motion


def entry_json(e: DirEntry) -> dict[str, Any]:
    kind = "folder" if e.is_folder else "file"
    return {"name": e.name, "type": kind, "size": e.size, "mtime": e.mtime, "atime": e.atime}


def _when(seconds: int) -> str:
    return datetime.datetime.fromtimestamp(seconds).strftime("%Y-%m-%d %H:%M")


def _ls(args: argparse.Namespace) -> Any:
    from ..client.remote_files import list_folder, remote_path

    folder = remote_path(args.folder, folder=True)

    async def body(client: AriaClient) -> int:
        listing = await list_folder(client, folder, timeout=args.timeout)
        entries = listing.sorted()
        if args.json:
            print_json(
                {"folder": folder, "source": listing.source, "entries": [entry_json(e) for e in entries]}
            )
            return EXIT_OK
        for e in entries:
            size = "-" if e.is_folder else str(e.size)
            print(f"{size:>12}  {_when(e.mtime)}  {visible(e.name)}{'/' if e.is_folder else ''}")
        sys.stdout.flush()
        return EXIT_OK

    return body


def _get(args: argparse.Namespace) -> Any:
    from ..client.download import check_destination, download_file
    from ..client.remote_files import remote_path

    remote = remote_path(args.remote)
    name = remote.rpartition("/")[2]
    local: Path = args.out if args.out is not None else Path(name)
    if local.is_dir():
        local = local / name
    check_destination(local, overwrite=args.force)

    async def body(client: AriaClient) -> int:
        printer = progress_printer(f"getting {visible(remote)}")
        try:
            done = await download_file(
                client, remote, local, overwrite=args.force, progress=printer, timeout=args.timeout
            )
        finally:
            end_progress(printer)
        if args.json:
            print_json(
                {"remote": remote, "local": str(local), "bytes": done.size, "seconds": round(done.seconds, 3),
                 "mtime": done.mtime, "listed_size": done.listed_size}
            )  # fmt: skip
        note = ""
        if done.listed_size is not None and done.listed_size != done.size:
            note = f" (the robot listed {done.listed_size} bytes)"
        print(
            _("wrote {local}: {size} bytes in {seconds}{note}").format(
                local=local, size=number(done.size), seconds=quantity(done.seconds, "s", 2), note=note
            ),
            file=sys.stderr,
        )
        return EXIT_OK

    return body


def _put(args: argparse.Namespace) -> Any:
    from ..client.remote_files import default_folder, find_entry, offers, remote_path, wire_name
    from ..client.upload import check_source, upload_file

    local: Path = args.local
    check_source(local)
    given = args.remote
    name = wire_name(local.name)
    remote = None if given is None else remote_path(given + name if given.endswith("/") else given)

    async def body(client: AriaClient) -> int:
        target = remote
        if target is None:
            folder = (
                await default_folder(client, timeout=args.timeout) if offers(client, "default_folder") else ""
            )
            target = f"{folder}/{name}" if folder else remote_path(name)
        if not args.force and offers(client, "list"):
            try:
                existing = await find_entry(client, target, timeout=args.timeout)
            except Exception:  # the folder may not exist: the upload itself will say so
                existing = None
            if existing is not None:
                what = "a folder" if existing.is_folder else "a file"
                return fail(
                    "files",
                    f"the robot already has {what} {target!r} (give --force to replace it)",
                    EXIT_USAGE,
                )
        printer = progress_printer(f"putting {visible(target)}")
        try:
            done = await upload_file(
                client, local, target, progress=printer, timeout=args.timeout,
                interleaved=True if args.interleaved else None,
            )  # fmt: skip
        finally:
            end_progress(printer)
        if args.json:
            print_json(
                {"local": str(local), "remote": target, "bytes": done.size, "seconds": round(done.seconds, 3)}
            )
        print(
            _("uploaded {local} as {visible}: {size} bytes in {seconds}").format(
                local=local,
                visible=visible(target),
                size=number(done.size),
                seconds=quantity(done.seconds, "s", 2),
            ),
            file=sys.stderr,
        )
        return EXIT_OK

    return body


def _rm(args: argparse.Namespace) -> Any:
    from ..client.remote_files import delete_file, remote_path

    remote = remote_path(args.remote)
    if not args.yes:
        host, port = args.server
        if sys.stdin is None or not sys.stdin.isatty():
            return fail(
                "files", "rm asks before deleting: give --yes (there is no terminal to ask on)", EXIT_USAGE
            )
        answer = input(f"Delete {remote!r} on {host}:{port}? [y/N] ").strip().lower()
        if answer not in ("y", "yes"):
            print(_("rtmu files: not deleted"), file=sys.stderr)
            return EXIT_USAGE

    async def body(client: AriaClient) -> int:
        await delete_file(client, remote, timeout=args.timeout)
        if args.json:
            print_json({"deleted": remote})
        else:
            print(_("deleted {visible}").format(visible=visible(remote)), file=sys.stderr)
        return EXIT_OK

    return body
