"""``rtmu config HOST[:PORT] [--json] [ACTION]``: the server's configuration (ArConfig), and its care.

Without an action: every section and parameter with its value, type, limits and priority. With
``--set``: one ``setConfig`` of all the values given; the server checks them and either takes them
all or answers with its first error, which is printed (exit 6). Exit 4 when the server offers no
configuration; exit 18 when it offers one RTMU cannot show or edit yet — an Omron LD robot's
``getConfigValues`` family (protocol 6MTX), named as such (``rtmu call`` reads it raw). The care
actions (``--defaults``, ``--reset``, ``--export``, ``--import``, ``--reload``) are in
:mod:`._config_care`.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_FOREIGN_CONFIG, EXIT_OK, EXIT_REFUSED, EXIT_USAGE, NETWORK
from ..base.i18n import _, ngettext
from ..base.textsafe import visible
from ..client.roles import Role
from ..protocol.payloads.config import ConfigParam, ParamType, Priority
from . import _config_care
from ._common import add_connection_arguments, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.config_feed import ConfigApi, ServerConfig
    from ..client.connection import AriaClient

MAX_ASSIGNMENTS = 1000


class Assignment(argparse.Action):
    """``--set SECTION/PARAM=VALUE`` (repeatable): parsed at once, so a typo fails before connecting."""

    def __call__(self, parser: Any, namespace: Any, values: Any, option_string: Any = None) -> None:
        got = list(getattr(namespace, self.dest) or [])
        for text in values:
            got.append(parse_assignment(text, parser))
        setattr(namespace, self.dest, got)


def parse_assignment(text: str, parser: Any) -> tuple[str, str, str]:
    where, eq, value = text.partition("=")
    section, slash, name = where.rpartition("/")
    if not eq or not slash or not section.strip() or not name.strip():
        parser.error(f"--set wants SECTION/PARAM=VALUE, not {text!r}")
    try:
        text.encode("latin-1")
    except UnicodeEncodeError:
        parser.error(f"--set {text!r}: ARIA strings carry latin-1 characters only")
    return section.strip(), name.strip(), value


EXITS = (*NETWORK, EXIT_REFUSED, EXIT_FOREIGN_CONFIG)
"""6: the server refused a value, in its own words (or an import does not fit it: nothing is sent)."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "config",
        help=_("show or change the server's configuration (ArConfig: getConfigBySections, setConfig)"),
        description=(
            _(
                "Print the server's configuration: sections, then parameters with value, type, limits "
                "and priority. One action at most: --set SECTION/PARAM=VALUE (repeatable) changes values in "
                "one setConfig; --defaults lists what differs from the factory values (getConfigDefaults); "
                "--reset SECTION/PARAM or --reset SECTION puts factory values back; --export FILE writes "
                "every value to a TOML file (an existing file only with --force); --import FILE checks the "
                "whole file against the server's parameters and sends it in one setConfig, or nothing; "
                "--reload makes the server read its configuration file again. A --reset target the server "
                "does not have, or a file that exists or is not an export, is a usage error; an --import "
                "that does not fit the server's parameters is refused and nothing is sent. An Omron LD "
                "robot's configuration (getConfigValues) is named, not shown: rtmu call reads it raw."
            )
        ),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json", action="store_true", help=_("one JSON object (the configuration, or the answer)")
    )
    actions = p.add_mutually_exclusive_group()
    actions.add_argument(
        "--set",
        dest="assignments",
        nargs="+",
        action=Assignment,
        metavar="SECTION/PARAM=VALUE",
        help=_("change these values (one setConfig)"),
    )
    actions.add_argument(
        "--defaults", action="store_true", help=_("list the parameters that differ from their factory values")
    )
    actions.add_argument(
        "--reset",
        metavar="SECTION/PARAM",
        help=_("put one parameter, or a whole SECTION, back to factory values"),
    )
    actions.add_argument(
        "--export", type=Path, metavar="FILE", help=_("write the whole configuration to FILE")
    )
    actions.add_argument(
        "--import",
        dest="import_file",
        type=Path,
        metavar="FILE",
        help=_("set every value of an exported FILE"),
    )
    actions.add_argument(
        "--reload", action="store_true", help=_("make the server read its configuration again")
    )
    p.add_argument("--force", action="store_true", help=_("with --export: replace FILE if it exists"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.config_feed import ForeignConfig, fetch_config

    assignments: list[tuple[str, str, str]] = args.assignments or []
    if len(assignments) > MAX_ASSIGNMENTS:
        print(
            _("rtmu config: at most {MAX_ASSIGNMENTS} values at once").format(
                MAX_ASSIGNMENTS=MAX_ASSIGNMENTS
            ),
            file=sys.stderr,
        )
        return EXIT_USAGE

    problem = _config_care.check_usage(args)
    if problem:
        print(_("rtmu config: {problem}").format(problem=problem), file=sys.stderr)
        return EXIT_USAGE

    async def body(client: AriaClient) -> int:
        try:
            if assignments:
                return await _set(client, assignments, args)
            done = await _config_care.run(client, args)
            if done is not None:
                return done
            config = await fetch_config(client, args.timeout)
        except ForeignConfig as exc:
            if args.json:
                print_json({"api": api_key(exc.api), "data": list(exc.listed), "editable": False})
            raise
        if args.json:
            print_json(config_json(config))
        else:
            print_text(config)
        return EXIT_OK

    return run_with_client("config", args, body, role=Role.OBSERVER)


async def _set(client: AriaClient, assignments: list[tuple[str, str, str]], args: argparse.Namespace) -> int:
    from ..client.config_feed import set_config

    changes: dict[str, dict[str, str]] = {}
    for section, name, value in assignments:
        changes.setdefault(section, {})[name] = value
    answer = await set_config(client, changes, args.timeout)
    if args.json:
        print_json({"accepted": answer.accepted, "error": answer.error})
    elif answer.accepted:
        print(
            ngettext("accepted: {count} value", "accepted: {count} values", len(assignments)).format(
                count=len(assignments)
            ),
            flush=True,
        )
    if not answer.accepted:
        print(
            _("rtmu config: the server refused: {visible}").format(visible=visible(answer.error)),
            file=sys.stderr,
        )
        return EXIT_REFUSED
    return EXIT_OK


def _finite(value: Any) -> Any:
    return None if isinstance(value, float) and not math.isfinite(value) else value


def param_json(p: ConfigParam, config: ServerConfig) -> dict[str, Any]:
    out: dict[str, Any] = {
        "name": p.name,
        "type": p.kind.name.lower(),
        "value": _finite(p.value),
        "description": p.description,
        "priority": Priority.of(p.priority).name.lower(),
        "editable": config.editable(p),
    }
    if p.kind in (ParamType.INT, ParamType.DOUBLE):
        out["min"], out["max"] = _finite(p.minimum), _finite(p.maximum)
    if p.choices:
        out["choices"] = list(p.choices)
    if p.restart:
        out["restart"] = p.restart
    if p.children:
        out["members"] = [param_json(c, config) for c in p.children]
    return out


def api_key(api: ConfigApi) -> str:
    return api.name.lower().replace("_", "-")


def config_json(config: ServerConfig) -> dict[str, Any]:
    from ..client.config_feed import ConfigApi

    return {
        "api": api_key(ConfigApi.ARCONFIG),
        "source": config.source,
        "last_editable": Priority.of(config.last_editable).name.lower(),
        "sections": [
            {
                "name": s.name,
                "comment": s.comment,
                "params": [param_json(p, config) for p in s.params if p.kind is not ParamType.SEPARATOR],
            }
            for s in config.sections
        ],
    }


def _limits(p: ConfigParam) -> str:
    if p.choices:
        return " one of " + ", ".join(visible(c) for c in p.choices)
    if p.kind not in (ParamType.INT, ParamType.DOUBLE):
        return ""
    lo = "" if p.minimum is None or not math.isfinite(p.minimum) else f"{p.minimum:g}"
    hi = "" if p.maximum is None or not math.isfinite(p.maximum) else f"{p.maximum:g}"
    if p.kind is ParamType.INT and (lo == "-2147483648"):
        lo = ""
    if p.kind is ParamType.INT and (hi == "2147483647"):
        hi = ""
    return f" {lo}…{hi}" if lo or hi else ""


def print_text(config: ServerConfig) -> None:
    for s in config.sections:
        comment = f"  ({visible(s.comment)})" if s.comment else ""
        print(f"[{visible(s.name)}]{comment}")
        for p in s.params:
            if p.kind is ParamType.SEPARATOR:
                continue
            ro = "" if config.editable(p) else ", read-only"
            kind = f"{p.kind.name.lower()}{_limits(p)}, {Priority.of(p.priority).name.lower()}{ro}"
            value = "" if p.kind is ParamType.LIST else visible(p.value_text())
            print(f"  {visible(p.name)} = {value}    [{kind}]")
            if p.description:
                print(f"      {visible(p.description)}")
    if config.cut:
        print(_("({cut} more parameters not shown: the configuration is too large)").format(cut=config.cut))
    sys.stdout.flush()
