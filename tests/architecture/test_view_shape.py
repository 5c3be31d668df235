"""The view's shape (issue 25): one stylesheet, small modules, a window that only composes.

Read from the source, so a module that starts loading CSS of its own, or a window that grows back
into a catch-all, fails here before review.
"""

from __future__ import annotations

from pathlib import Path

UI = Path(__file__).resolve().parents[2] / "src" / "rtmu" / "ui"


def test_one_stylesheet_installed_by_one_function() -> None:
    loaders = sorted(p.name for p in UI.glob("*.py") if "CssProvider" in p.read_text(encoding="utf-8"))
    assert loaders == ["style.py"], f"CSS loaded outside ui/style.py: {loaders}"
