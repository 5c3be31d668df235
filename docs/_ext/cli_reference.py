"""``.. rtmu-cli-reference::`` — every ``rtmu`` command's ``--help``, read from the parser the command uses.

The reference cannot drift from the program: it is ``rtmu.cli.build_parser()`` formatted by argparse,
exactly what ``rtmu --help``, ``rtmu SUBCOMMAND --help`` and, for ``files`` and ``scan``,
``rtmu SUBCOMMAND HOST ACTION --help`` print (at 100 columns).
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
            for action, nested in subparsers(sub).items():  # rtmu files ls, rtmu scan stop …
                target = nodes.target("", "", ids=[f"cli-{name}-{action}"])
                heading = nodes.rubric(text=f"rtmu {name} {action}")
                out += [target, heading, nodes.literal_block(text=nested.format_help())]
        return out


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("rtmu-cli-reference", CliReference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
