"""``.. rtmu-cli-reference::`` — every ``rtmu`` command's ``--help``, read from the parser the command uses;
``.. rtmu-exit-codes::`` — the one table of exit codes (``rtmu.base.exit_codes.table_text``).

The reference cannot drift from the program: it is ``rtmu.cli.build_parser()`` formatted by argparse,
exactly what ``rtmu --help`` and ``rtmu SUBCOMMAND --help`` print (at 100 columns).
"""

from __future__ import annotations

import argparse
import os

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective


def subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(sorted(action.choices.items()))
    return {}


class CliReference(SphinxDirective):
    def run(self) -> list[nodes.Node]:
        from rtmu.cli import build_parser

        os.environ["COLUMNS"] = "100"  # argparse wraps help to the terminal's width
        parser = build_parser()
        out: list[nodes.Node] = [nodes.rubric(text="rtmu"), nodes.literal_block(text=parser.format_help())]
        for name, sub in subparsers(parser).items():
            target = nodes.target("", "", ids=[f"cli-{name}"])
            out += [target, nodes.rubric(text=f"rtmu {name}"), nodes.literal_block(text=sub.format_help())]
        return out


class ExitCodes(SphinxDirective):
    """``.. rtmu-exit-codes::`` — the one table of exit codes, as ``rtmu --help`` prints it."""

    def run(self) -> list[nodes.Node]:
        from rtmu.base.exit_codes import table_text

        return [nodes.literal_block(text=table_text(indent=""))]


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("rtmu-cli-reference", CliReference)
    app.add_directive("rtmu-exit-codes", ExitCodes)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
