"""The ``rtmu`` command: argument parsing and wiring; each subcommand lives in ``rtmu.subcommands``.

A subcommand module defines ``register(subparsers)`` that adds its parser and
sets ``handler=`` (a function taking the parsed namespace and returning the exit
code). Adding a subcommand touches one new file, named as the command.

A command imports only its own module: ``rtmu status …`` never loads the recorder, the simulator
or GTK, and ``rtmu --version`` no subcommand at all (``LazySubcommands``). ``rtmu --help``, the man
page and the completions load them all. ``tests/test_import_cost.py`` keeps it so.
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
from typing import Any

from . import subcommands
from .base import dataclass_code, exit_codes, logs
from .base.exit_codes import EXIT_USAGE
from .base.i18n import _
from .subcommands import _integration
from .versions import VersionAction

SINGLE_BLAS_THREAD = {"OPENBLAS_NUM_THREADS": "1"}
"""Set (unless the user set them) before numpy loads: RTMU's arrays are small, and numpy's OpenBLAS
otherwise starts a thread per core at import, 0.1 s of CPU in every launch of the window, spinning
for work that never comes."""


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
    return _("Exit codes (one table for every rtmu command):") + "\n" + exit_codes.table_text(codes)


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


NOT_COMMANDS = frozenset({"json_schemas"})
"""Modules of ``rtmu.subcommands`` that are data, not commands (they have no ``register``)."""


def subcommand_names() -> list[str]:
    """Every subcommand, sorted: one module of ``rtmu.subcommands`` each (``_``-modules are helpers)."""
    names = (m.name for m in pkgutil.iter_modules(subcommands.__path__) if not m.name.startswith("_"))
    return sorted(set(names) - NOT_COMMANDS)


def schema_of(name: str) -> str | None:
    """The published schema a subcommand's ``--json`` lines follow (by name: the schemas stay unloaded)."""
    from .subcommands._schema_names import COMMAND_SCHEMA

    return COMMAND_SCHEMA.get(name)


class LazySubcommands(argparse._SubParsersAction):
    """The subcommands, each module imported when its command is chosen (or when help lists them).

    Until then a command is a name in ``choices`` (so argparse accepts it and names it in errors)
    with no parser; :meth:`load` imports the module and lets its ``register`` add the real one.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._modules: dict[str, str] = {}

    def add_lazy(self, name: str, module: str) -> None:
        self._modules[name] = module
        self._name_parser_map[name] = None  # no parser until load()

    def load(self, name: str) -> None:
        module = self._modules.pop(name, None)
        if module is None:
            return
        del self._name_parser_map[name]
        # A command's module is imported here, while the arguments are parsed (``SUB --help`` too):
        # its dataclasses' methods come from the cache, as the window's do. (The bare ``--version``
        # and ``--help`` import no command and pay nothing for it.)
        dataclass_code.install()
        loaded = importlib.import_module(module)
        register = getattr(loaded, "register", None)
        if register is not None:
            register(self)
            command = self._name_parser_map.get(name)
            if command is not None:
                finish_help(command, getattr(loaded, "EXITS", exit_codes.NETWORK), schema_of(name))
        if self._name_parser_map.get(name) is None:  # a module that registered nothing under its name
            self._name_parser_map.pop(name, None)

    def load_all(self) -> None:
        for name in sorted(self._modules):
            self.load(name)
        self._choices_actions.sort(key=lambda action: action.dest)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        self.load(values[0])
        super().__call__(parser, namespace, values, option_string)


class _Parser(argparse.ArgumentParser):
    """The top-level parser: its help lists every subcommand, so formatting it loads them all."""

    lazy: LazySubcommands

    def format_help(self) -> str:
        self.lazy.load_all()
        return super().format_help()


def build_parser(*, lazy: bool = False) -> argparse.ArgumentParser:
    """The whole ``rtmu`` parser; ``lazy``: subcommand modules imported only when chosen."""
    parser = _Parser(
        prog="rtmu",
        description=_("Teleoperate an ARIA (ArNetworking) robot; with no subcommand, open the window."),
        epilog=exits_epilog(None),
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "--version", action=VersionAction, help=_("show the versions of rtmu, its protocol and toolkit; exit")
    )
    sub = parser.add_subparsers(
        dest="subcommand", metavar="SUBCOMMAND", action=LazySubcommands, parser_class=argparse.ArgumentParser
    )
    assert isinstance(sub, LazySubcommands)
    parser.lazy = sub
    for name in subcommand_names():
        sub.add_lazy(name, f"{subcommands.__name__}.{name}")
    if not lazy:
        sub.load_all()
    gui = importlib.util.find_spec("rtmu.ui.app")
    if gui is not None:
        from .ui import app as gui_app

        gui_app.add_gui_arguments(parser)
    _integration.add_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    for name, value in SINGLE_BLAS_THREAD.items():
        os.environ.setdefault(name, value)
    logs.configure()  # developer notices off the operator's terminal (RTMU_LOG=warning shows them)
    parser = build_parser(lazy=True)
    args = parser.parse_args(argv)
    # Past --version and --help (which exit above and need no dataclass); before the modules a
    # command's handler or the window imports define theirs (a command's own module installed it).
    dataclass_code.install()
    handler = getattr(args, "handler", None)
    installing = _integration.handle(args, build_parser) if handler is None else None
    if installing is not None:
        return installing
    if handler is None:
        if importlib.util.find_spec("rtmu.ui.app") is None:
            print(_("rtmu: the operator window is not built yet; try 'rtmu --help'"), file=sys.stderr)
            return EXIT_USAGE
        from .ui import app as gui_app

        return gui_app.run_gui(args)
    try:
        code = int(handler(args) or 0)
        sys.stdout.flush()  # a block-buffered pipe fails here, not at exit (exit 120 and a warning)
        return code
    except KeyboardInterrupt:
        # Ctrl-C after the command's own event loop had ended (its finally blocks, a drive's stop,
        # have run): exit as every interrupted command does, not killed by the signal mid-teardown.
        return 128 + signal.SIGINT
    except BrokenPipeError:
        # Whoever read our output went away (`rtmu mapinfo … | head`): no traceback for that. The
        # handler's own finally blocks (a drive's stop) have run; nothing more will be printed.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 128 + signal.SIGPIPE
