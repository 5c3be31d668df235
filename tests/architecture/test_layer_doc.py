"""docs/architecture.md's layer table is the import graph: what each layer imports, and where it lives.

The table's "imports" column must name exactly the layers each layer's modules import today (read from
the source, as :mod:`.test_layers` reads it) and exactly what the layer contract allows; its "where"
column must name every package of the layer and nothing of another. A new import across layers, a moved
package or a rule loosened without the picture (or the other way round) fails here.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from .import_graph import import_graph
from .test_layers import LAYERS, MAY_IMPORT, SRC, layer_of

DOC = Path(__file__).resolve().parents[2] / "docs" / "architecture.md"
EVERYTHING = "everything"
"""The entry layer's cell: it may import any layer (it wires them), so only that word is checked."""


def doc_rows() -> dict[str, tuple[str, str]]:
    """Layer → (its "where" cell, its "imports" cell), from the table under "## Layers"."""
    text = DOC.read_text(encoding="utf-8")
    table = text[text.index("## Layers") :]
    rows: dict[str, tuple[str, str]] = {}
    for line in table.splitlines()[1:]:
        if line.startswith("## "):
            break
        if not line.startswith("| ") or line.startswith("| layer") or line.startswith("|---"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        rows[cells[0]] = (cells[1], cells[-1])
    return rows


def named_layers(cell: str) -> set[str]:
    """The layers a cell names: 'recorder (replay, bridge), codec' → {'recorder', 'codec'}; '—' → none."""
    plain = re.sub(r"\([^)]*\)", "", cell)
    return {word.strip() for word in plain.split(",") if word.strip() not in ("", "—")}


def used_layers() -> dict[str, set[str]]:
    graph = import_graph(SRC, "rtmu")
    used: dict[str, set[str]] = {layer: set() for layer in LAYERS}
    for module, targets in graph.items():
        here = layer_of(module)
        used[here] |= {layer_of(t) for t in targets} - {here}
    return used


def test_the_table_has_a_row_per_layer() -> None:
    assert sorted(doc_rows()) == sorted(LAYERS)


@pytest.mark.parametrize("layer", [layer for layer in LAYERS if layer != "entry"])
def test_each_row_names_the_layers_it_imports_and_may_import(layer: str) -> None:
    documented = named_layers(doc_rows()[layer][1])
    assert documented == MAY_IMPORT[layer] - {layer}, f"{layer}: the table and the contract differ"
    assert documented == used_layers()[layer], f"{layer}: the table and the source's imports differ"


def test_the_entry_layer_may_import_everything() -> None:
    assert doc_rows()["entry"][1] == EVERYTHING and MAY_IMPORT["entry"] == frozenset(LAYERS)


def _path_of(prefix: str) -> str:
    """How the table writes a module or package: `protocol/`, `versions`, `cli.py`, `__init__`."""
    if prefix == "rtmu":
        return "`__init__`"
    rel = prefix.removeprefix("rtmu.").replace(".", "/")
    return f"`{rel}/`" if (SRC / "rtmu" / rel).is_dir() else f"`{rel}"


@pytest.mark.parametrize("layer", list(LAYERS))
def test_each_row_says_where_the_layer_lives(layer: str) -> None:
    where = doc_rows()[layer][0]
    for prefix in LAYERS[layer]:
        assert _path_of(prefix) in where, f"{layer}: the table does not name {prefix}"
    for path in re.findall(r"`([\w/]+(?:/|\.py))`", where):  # every folder or file the cell names
        module = "rtmu." + path.removesuffix("/").removesuffix(".py").replace("/", ".")
        assert layer_of(module) == layer, f"{layer}: the table puts {path} here; it is {layer_of(module)}'s"
