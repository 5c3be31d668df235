"""The view's shape (issue 25): one stylesheet, small modules, a window that only composes.

Read from the source, so a module that starts loading CSS of its own, or a window that grows back
into a catch-all, fails here before review.
"""

from __future__ import annotations

from pathlib import Path

UI = Path(__file__).resolve().parents[2] / "src" / "rtmu" / "ui"
WINDOW_LINES = 400
"""The window composes its parts: well under a module's 600 lines."""
MODULE_LINES = 600


def test_one_stylesheet_installed_by_one_function() -> None:
    loaders = sorted(p.name for p in UI.glob("*.py") if "CssProvider" in p.read_text(encoding="utf-8"))
    assert loaders == ["style.py"], f"CSS loaded outside ui/style.py: {loaders}"


def test_no_view_module_over_600_lines_and_the_window_well_under() -> None:
    sizes = {p.name: len(p.read_text(encoding="utf-8").splitlines()) for p in UI.glob("*.py")}
    assert {n: s for n, s in sizes.items() if s > MODULE_LINES} == {}
    assert sizes["window.py"] < WINDOW_LINES, (
        f"window.py has {sizes['window.py']} lines: it composes, nothing more"
    )


def test_no_module_anywhere_over_600_lines() -> None:
    """Small modules with one job each, in the whole package, the tests and the benchmarks alike (two
    grew past it unnoticed in one session: ``doctor`` to 696 lines and ``client/why`` to 630)."""
    root = UI.parents[2]
    sizes = {
        str(p.relative_to(root)): len(p.read_text(encoding="utf-8").splitlines())
        for folder in ("src", "tests", "bench")
        for p in (root / folder).rglob("*.py")
    }
    assert {n: s for n, s in sizes.items() if s > MODULE_LINES} == {}


def test_keys_name_actions_and_no_window_intent_goes_by_name() -> None:
    """View intents are ``win.*`` actions: a key names its action (no ``Binding.kind``), and no module
    of the view dispatches ``view_intent`` strings."""
    from rtmu.ui.keys import Binding

    assert "kind" not in Binding.__dataclass_fields__ and "action" in Binding.__dataclass_fields__
    for path in UI.glob("*.py"):
        assert "view_intent" not in path.read_text(encoding="utf-8"), f"{path.name}: an intent by name"
