"""The ``rtmu`` command: argument parsing and wiring; each subcommand lives in ``rtmu.subcommands``.

A subcommand module defines ``register(subparsers)`` that adds its parser and
sets ``handler=`` (a function taking the parsed namespace and returning the exit
code). Adding a subcommand touches one new file.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import pkgutil
import signal
import sys
from collections.abc import Sequence

from . import subcommands
from .base import exit_codes, logs
from .base.exit_codes import EXIT_USAGE
from .subcommands import _integration
from .subcommands.json_schemas import COMMAND_SCHEMA
from .versions import VersionAction


class HelpFormatter(argparse.HelpFormatter):
    """argparse's own wrapping, except that indented lines (the exit-code table) are kept as written."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        paragraphs = []
        for paragraph in text.split("\n\n"):
            if paragraph.startswith(" ") or "\n " in paragraph:
                paragraphs.append("\n".join(indent + line for line in paragraph.splitlines()))
            else:
                paragraphs.append(super()._fill_text(paragraph, width, indent))
        return "\n\n".join(paragraphs)


def exits_epilog(codes: tuple[int, ...] | None) -> str:
    """The help's closing part: these codes' lines of the one table (all of them for ``rtmu --help``)."""
    return "Exit codes (one table for every rtmu command):\n" + exit_codes.table_text(codes)


def actions_of(command: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    """The parsers of a subcommand's own action words (``rtmu files HOST ls``), if it has them."""
    return [
        parser
        for action in command._actions
        if isinstance(action, argparse._SubParsersAction)
        for parser in action.choices.values()
    ]


def name_schema(command: argparse.ArgumentParser, schema: str | None) -> None:
    """Say in ``--json``'s help which published schema its lines follow (``subcommands.json_schemas``)."""
    for action in command._actions:
        if schema is not None and "--json" in action.option_strings and action.help:
            action.help += f" (schema {schema!r}: python -m rtmu.subcommands.json_schemas {schema})"


def finish_help(command: argparse.ArgumentParser, codes: tuple[int, ...], schema: str | None) -> None:
    """One style for a subcommand's help and its action words' helps: the exit codes, the schema named."""
    for parser in (command, *actions_of(command)):
        parser.formatter_class = HelpFormatter
        parser.epilog = exits_epilog(codes)
        name_schema(parser, schema)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rtmu",
        description="Teleoperate an ARIA (ArNetworking) robot; with no subcommand, open the window.",
        epilog=exits_epilog(None),
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "--version", action=VersionAction, help="show the versions of rtmu, its protocol and toolkit; exit"
    )
    sub = parser.add_subparsers(dest="subcommand", metavar="SUBCOMMAND")
    for info in sorted(pkgutil.iter_modules(subcommands.__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{subcommands.__name__}.{info.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(sub)
            codes = getattr(module, "EXITS", exit_codes.NETWORK)
            finish_help(sub.choices[info.name], codes, COMMAND_SCHEMA.get(info.name))
    gui = importlib.util.find_spec("rtmu.ui.app")
    if gui is not None:
        from .ui import app as gui_app

        gui_app.add_gui_arguments(parser)
    _integration.add_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    logs.configure()  # developer notices off the operator's terminal (RTMU_LOG=warning shows them)
    parser = build_parser()
    args = parser.parse_args(argv)
    handler = getattr(args, "handler", None)
    installing = _integration.handle(args, parser) if handler is None else None
    if installing is not None:
        return installing
    if handler is None:
        if importlib.util.find_spec("rtmu.ui.app") is None:
            print("rtmu: the operator window is not built yet; try 'rtmu --help'", file=sys.stderr)
            return EXIT_USAGE
        from .ui import app as gui_app

        return gui_app.run_gui(args)
    try:
        code = int(handler(args) or 0)
        sys.stdout.flush()  # a block-buffered pipe fails here, not at exit (exit 120 and a warning)
        return code
    except BrokenPipeError:
        # Whoever read our output went away (`rtmu mapinfo … | head`): no traceback for that. The
        # handler's own finally blocks (a drive's stop) have run; nothing more will be printed.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 128 + signal.SIGPIPE
