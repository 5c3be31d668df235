"""The layer contract of ``src/rtmu``: who may import whom, no import cycles, a lazy client package.

Read from the source (``import_graph``), every import counted — inside functions and
under ``TYPE_CHECKING`` too. docs/architecture.md draws the same layers.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from .import_graph import cycles, import_graph

SRC = Path(__file__).resolve().parents[2] / "src"

LAYERS: dict[str, tuple[str, ...]] = {
    "base": ("rtmu", "rtmu.base", "rtmu.package_data"),
    "codec": ("rtmu.protocol",),
    "maps": ("rtmu.mapfile",),
    "values": ("rtmu.values", "rtmu.mapedit"),
    "capture": ("rtmu.capture",),
    "about": ("rtmu.versions",),
    "guardian": ("rtmu.guardian",),
    "client": ("rtmu.client",),
    "simulator": ("rtmu.sim",),
    "recorder": ("rtmu.recorder",),
    "ui-state": ("rtmu.model",),
    "settings": ("rtmu.settings",),
    "control": ("rtmu.control",),
    "fleet": ("rtmu.fleet",),
    "view": ("rtmu.ui",),
    "entry": ("rtmu.cli", "rtmu.__main__", "rtmu.subcommands"),
}
"""Layer → the modules (and packages) in it."""

MAY_IMPORT: dict[str, frozenset[str]] = {
    "base": frozenset(),
    "codec": frozenset(),
    "maps": frozenset(),
    "values": frozenset({"maps", "base"}),
    "capture": frozenset({"codec"}),
    # What --version (and later the About window) says: the protocol's facts and the libraries' versions.
    "about": frozenset({"codec", "base"}),
    # The stop process: its halt and its login go through the codec on a plain socket. It never imports
    # the client it guards against (nor asyncio, numpy or GTK: it starts light). From base it takes the
    # one rule for how late a stream may be (base.link_timing), shared with the client's link health;
    # from values the one Target its parent connected with (its login is the parent's, field for field).
    "guardian": frozenset({"values", "codec", "base"}),
    # The network side knows the values it publishes, never the UI thread's state above it.
    "client": frozenset({"guardian", "values", "codec", "maps", "base"}),
    "simulator": frozenset({"codec", "maps", "base"}),
    # The flight recorder taps the client's links and values; the raw channel's layout is capture's.
    "recorder": frozenset({"client", "values", "capture", "codec", "base"}),
    "ui-state": frozenset({"values"}),
    "settings": frozenset({"base"}),
    "control": frozenset({"client", "ui-state", "values", "settings", "base"}),
    "fleet": frozenset(
        {"control", "client", "guardian", "recorder", "ui-state", "values", "settings", "base"}
    ),
    # The window may start the bundled simulator (--demo) and play a recording back (rtmu replay: the
    # recorder's clock and feeder); its About window says what --version says; it never reaches the
    # command line.
    "view": frozenset(
        {
            "fleet",
            "control",
            "client",
            "guardian",
            "recorder",
            "ui-state",
            "values",
            "settings",
            "simulator",
            "codec",
            "about",
            "base",
        }
    ),
    "entry": frozenset(LAYERS),
}
"""Layer → the layers it may import (besides itself): exactly what it imports today, as
docs/architecture.md draws it (``test_layer_doc``). Only the entry layer imports ``rtmu.cli``."""


def layer_of(module: str) -> str:
    best = ""
    found = None
    for layer, prefixes in LAYERS.items():
        for prefix in prefixes:
            inside = module == prefix or (prefix != "rtmu" and module.startswith(prefix + "."))
            if inside and len(prefix) > len(best):
                best, found = prefix, layer
    if found is None:
        raise AssertionError(f"{module} is in no layer: add it to LAYERS (and to docs/architecture.md)")
    return found


def violations(graph: dict[str, set[str]]) -> list[str]:
    """Every import that crosses the contract, as 'a (layer) imports b (layer)'."""
    out = []
    for module, targets in sorted(graph.items()):
        here = layer_of(module)
        for target in sorted(targets):
            there = layer_of(target)
            if there != here and there not in MAY_IMPORT[here]:
                out.append(f"{module} ({here}) imports {target} ({there})")
    return out


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    return import_graph(SRC, "rtmu")


def test_every_import_keeps_the_layers(graph: dict[str, set[str]]) -> None:
    assert violations(graph) == []


def test_there_are_no_import_cycles(graph: dict[str, set[str]]) -> None:
    assert cycles(graph) == []


def test_the_client_package_imports_nothing_eagerly(graph: dict[str, set[str]]) -> None:
    """Importing ``rtmu.client.lease`` (the controller does) must not load sockets and sessions."""
    assert graph["rtmu.client"] == set()


@pytest.mark.parametrize(
    ("module", "forbidden"),
    [
        ("rtmu.client.session", "rtmu.model.observables"),  # the client reaching for UI-thread state
        ("rtmu.client.errors", "rtmu.cli"),  # exit codes taken from the command line
        ("rtmu.protocol.decoder", "rtmu.client.connection"),  # the codec reaching up
        ("rtmu.sim.server", "rtmu.ui.window"),
        ("rtmu.guardian.child", "rtmu.client.connection"),  # the guardian leaning on what it guards against
    ],
)
def test_the_contract_catches_a_forbidden_import(
    graph: dict[str, set[str]], module: str, forbidden: str
) -> None:
    broken = {m: set(t) for m, t in graph.items()}
    broken[module].add(forbidden)
    assert violations(broken) == [
        f"{module} ({layer_of(module)}) imports {forbidden} ({layer_of(forbidden)})"
    ]


def test_the_cycle_check_catches_a_back_edge(graph: dict[str, set[str]]) -> None:
    broken = {m: set(t) for m, t in graph.items()}
    broken["rtmu.control.commands"].add("rtmu.control.ports")  # the ports import the commands
    assert ["rtmu.control.commands", "rtmu.control.ports"] in cycles(broken)
