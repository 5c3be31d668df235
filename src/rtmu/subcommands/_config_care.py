"""``rtmu config`` care: --defaults, --reset, --export, --import, --reload (one network action each)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ..base.exit_codes import EXIT_OK, EXIT_REFUSED, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import visible
from ._common import UsageError, print_json

if TYPE_CHECKING:
    from ..client.connection import AriaClient


def _refused(words: str) -> int:
    print(_("rtmu config: {visible}").format(visible=visible(words)), file=sys.stderr)
    return EXIT_REFUSED


async def show_defaults(client: AriaClient, args: argparse.Namespace) -> int:
    from ..client.config_care import differences, fetch_defaults
    from ..client.config_feed import fetch_config

    config = await fetch_config(client, args.timeout)
    factory = await fetch_defaults(client, args.timeout)
    diffs = differences(config, factory)
    if args.json:
        rows = [
            {
                "section": d.section,
                "name": d.name,
                "value": d.value,
                "default": d.default,
                "editable": d.editable,
            }
            for d in diffs
        ]
        print_json({"differences": rows, "factory_values": len(factory.values), "cut": factory.cut})
        return EXIT_OK
    if not diffs:
        print(_("every parameter has its factory value"))
    for d in diffs:
        ro = "" if d.editable else "  (read-only)"
        where = f"{visible(d.section)}/{visible(d.name)}"
        print(
            _("{where} = {visible}    factory: {visible2}{ro}").format(
                where=where, visible=visible(d.value), visible2=visible(d.default), ro=ro
            )
        )
    if factory.cut:
        print(_("({cut} factory values not read: too many or too long)").format(cut=factory.cut))
    sys.stdout.flush()
    return EXIT_OK


async def do_reset(client: AriaClient, args: argparse.Namespace) -> int:
    from ..client.config_care import fetch_defaults, reset, reset_targets
    from ..client.config_feed import fetch_config

    config = await fetch_config(client, args.timeout)
    factory = await fetch_defaults(client, args.timeout)
    try:
        changes = reset_targets(config, factory, args.reset.strip())
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    names = [f"{s}/{n}" for s, values in changes.items() for n in values]
    if not changes:
        _say(
            args,
            {"reset": [], "accepted": True, "error": ""},
            "already at its factory value(s): nothing sent",
        )
        return EXIT_OK
    answer = await reset(client, changes, args.timeout)
    _say(
        args,
        {"reset": names, "accepted": answer.accepted, "error": answer.error},
        "reset to factory values: " + ", ".join(visible(n) for n in names) if answer.accepted else "",
    )
    return EXIT_OK if answer.accepted else _refused(f"the server refused: {answer.error}")


async def do_export(client: AriaClient, args: argparse.Namespace) -> int:
    from ..client.config_feed import fetch_config
    from ..client.config_file import ConfigFileError, export_text, valued, write_export

    path: Path = args.export
    if path.exists() and not args.force:  # say so before asking the server for anything
        raise UsageError(f"{path} already exists (give --force to replace it)")
    config = await fetch_config(client, args.timeout)
    host, port = args.server
    text = export_text(config, f"{host}:{port}")
    try:
        write_export(path, text, force=args.force)
    except ConfigFileError as exc:
        raise UsageError(str(exc)) from None
    count = len(valued(config))
    _say(args, {"exported": str(path), "parameters": count}, f"wrote {count} parameters to {path}")
    return EXIT_OK


async def do_import(client: AriaClient, args: argparse.Namespace) -> int:
    from ..client.config_feed import fetch_config, set_config
    from ..client.config_file import ConfigFileError, plan_import, read_file

    try:
        values = read_file(args.import_file)
    except ConfigFileError as exc:
        raise UsageError(str(exc)) from None
    config = await fetch_config(client, args.timeout)
    plan = plan_import(config, values)
    if plan.problems:
        if args.json:
            print_json({"accepted": False, "problems": list(plan.problems), "sent": 0})
        for problem in plan.problems[:50]:
            print(_("rtmu config: {visible}").format(visible=visible(problem)), file=sys.stderr)
        if len(plan.problems) > 50:
            print(
                _("rtmu config: … and {value} more problems").format(value=len(plan.problems) - 50),
                file=sys.stderr,
            )
        return _refused("nothing was imported: the file does not fit this server's configuration")
    count = sum(len(v) for v in plan.changes.values())
    if not count:
        _say(
            args,
            {"accepted": True, "sent": 0, "unchanged": plan.unchanged},
            "every value is already as the file says",
        )
        return EXIT_OK
    answer = await set_config(client, plan.changes, args.timeout)
    _say(
        args,
        {"accepted": answer.accepted, "sent": count, "unchanged": plan.unchanged, "error": answer.error},
        f"imported {count} value{'s' if count != 1 else ''} ({plan.unchanged} already as the file says)"
        if answer.accepted
        else "",
    )
    return EXIT_OK if answer.accepted else _refused(f"the server refused the import: {answer.error}")


async def do_reload(client: AriaClient, args: argparse.Namespace) -> int:
    from ..client.config_care import reload_config

    await reload_config(client, args.timeout)
    _say(args, {"reloaded": True}, "the server read its configuration again")
    return EXIT_OK


def _say(args: argparse.Namespace, obj: dict[str, object], text: str) -> None:
    if args.json:
        print_json(obj)
    elif text:
        print(text, flush=True)


ACTIONS = {"defaults": show_defaults, "reset": do_reset, "export": do_export, "import_file": do_import}


async def run(client: AriaClient, args: argparse.Namespace) -> int | None:
    """The care action asked for, or None when none was (the plain listing)."""
    if args.reload:
        return await do_reload(client, args)
    for key, action in ACTIONS.items():
        if getattr(args, key):
            return await action(client, args)
    return None


def check_usage(args: argparse.Namespace) -> str:
    """Why the options do not go together ("" when they do)."""
    if args.force and not args.export:
        return "--force only goes with --export"
    return ""


__all__ = ["EXIT_REFUSED", "EXIT_USAGE", "check_usage", "run"]
