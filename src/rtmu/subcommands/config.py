"""``rtmu config HOST[:PORT] [--json] [--set SECTION/PARAM=VALUE …]``: the server's configuration (ArConfig).

Without ``--set``: every section and parameter with its value, type, limits and priority. With
``--set``: one ``setConfig`` of all the values given; the server checks them and either takes them
all or answers with its first error, which is printed (exit 6). Exit 4 when the server offers no
configuration.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from ..base.exit_codes import EXIT_OK, EXIT_REFUSED, EXIT_USAGE, NETWORK
from ..base.textsafe import visible
from ..client.config_feed import ServerConfig, fetch_config, set_config
from ..client.connection import AriaClient
from ..client.roles import Role
from ..protocol.payloads.config import ConfigParam, ParamType, Priority
from ._common import add_connection_arguments, print_json, run_with_client

"""The server refused a value (its message is printed)."""
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


EXITS = (*NETWORK, EXIT_REFUSED)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "config",
        help="show or change the server's configuration (getConfigBySections, setConfig)",
        description=(
            "Print the server's configuration: sections, then parameters with value, type, limits "
            "and priority. --set SECTION/PARAM=VALUE (repeatable) changes values in one setConfig: "
            f"exit {EXIT_REFUSED} with the server's message when it refuses one (it then changes "
            "none), 4 when the server offers no configuration."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--json", action="store_true", help="one JSON object (the configuration, or the answer)")
    p.add_argument(
        "--set",
        dest="assignments",
        nargs="+",
        action=Assignment,
        metavar="SECTION/PARAM=VALUE",
        help="change these values (one setConfig)",
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    assignments: list[tuple[str, str, str]] = args.assignments or []
    if len(assignments) > MAX_ASSIGNMENTS:
        print(f"rtmu config: at most {MAX_ASSIGNMENTS} values at once", file=sys.stderr)
        return EXIT_USAGE

    async def body(client: AriaClient) -> int:
        if assignments:
            return await _set(client, assignments, args)
        config = await fetch_config(client, args.timeout)
        if args.json:
            print_json(config_json(config))
        else:
            print_text(config)
        return EXIT_OK

    return run_with_client("config", args, body, role=Role.OBSERVER)


async def _set(client: AriaClient, assignments: list[tuple[str, str, str]], args: argparse.Namespace) -> int:
    changes: dict[str, dict[str, str]] = {}
    for section, name, value in assignments:
        changes.setdefault(section, {})[name] = value
    answer = await set_config(client, changes, args.timeout)
    if args.json:
        print_json({"accepted": answer.accepted, "error": answer.error})
    elif answer.accepted:
        print(f"accepted: {len(assignments)} value{'s' if len(assignments) != 1 else ''}", flush=True)
    if not answer.accepted:
        print(f"rtmu config: the server refused: {visible(answer.error)}", file=sys.stderr)
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


def config_json(config: ServerConfig) -> dict[str, Any]:
    return {
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
        print(f"({config.cut} more parameters not shown: the configuration is too large)")
    sys.stdout.flush()
