"""``.. rtmu-exit-codes::`` — the command line's exit codes, read from ``rtmu.base.exit_codes``.

The pages cannot drift from the program: the table is :data:`rtmu.base.exit_codes.EXIT_CODES`, the
same one ``rtmu --help`` prints (``table_text``), in the same order. ``:codes: 20-39`` shows only
those codes (comma-separated codes and ranges), for a page about one command's own.
"""

from __future__ import annotations

import re
from typing import ClassVar

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective


def chosen_codes(spec: str | None) -> tuple[int, ...] | None:
    """``"20-39,5"`` → the codes of the table in those ranges (None: all of them)."""
    if not spec:
        return None
    from rtmu.base.exit_codes import EXIT_CODES

    wanted: set[int] = set()
    for part in spec.split(","):
        low, _, high = part.strip().partition("-")
        wanted |= set(range(int(low), int(high or low) + 1))
    codes = tuple(code for code in EXIT_CODES if code in wanted)
    if not codes:
        raise ValueError(f"no exit code in {spec!r}")
    return codes


OPTION = re.compile(r"(--[a-z][\w-]*)")


def _cell(text: str, literal: bool = False) -> nodes.entry:
    """A table cell; options in it (``--force``) as code, so typography never turns ``--`` into a dash."""
    if literal:
        return nodes.entry("", nodes.paragraph("", "", nodes.literal(text=text)))
    parts = OPTION.split(text)
    inner = [nodes.literal(text=part) if i % 2 else nodes.Text(part) for i, part in enumerate(parts) if part]
    return nodes.entry("", nodes.paragraph("", "", *inner))


class ExitCodeTable(SphinxDirective):
    option_spec: ClassVar[dict[str, object]] = {"codes": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        from rtmu.base.exit_codes import EXIT_CODES

        try:
            codes = chosen_codes(self.options.get("codes"))
        except ValueError as exc:
            raise self.error(str(exc)) from None
        group = nodes.tgroup(cols=2)
        group += [nodes.colspec(colwidth=1), nodes.colspec(colwidth=9)]
        head = nodes.thead("", nodes.row("", _cell("code"), _cell("meaning")))
        body = nodes.tbody()
        for code in sorted(EXIT_CODES if codes is None else codes):
            body += nodes.row("", _cell(str(code), literal=True), _cell(EXIT_CODES[code]))
        group += [head, body]
        return [nodes.table("", group)]


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("rtmu-exit-codes", ExitCodeTable)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
