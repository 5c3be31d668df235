"""The documentation builds with warnings as errors, and every picture in it is a GUI test's.

Sphinx (MyST Markdown) builds ``docs/`` as CI would; a broken link, a missing page or image, or a
bad directive fails the build. The pictures in ``docs/screenshots`` are taken by the GUI tests
named in ``tests/gui/doc_screenshots.py`` (``./rtmu-dev screenshots`` takes them again): every
picture the docs, the README and the AppStream metainfo show must be one of them.
"""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from html import unescape
from pathlib import Path

import pytest

from gui.doc_screenshots import DOC_SHOTS
from rtmu.base.exit_codes import table_text
from rtmu.package_data import APP_ID, DESKTOP_DIR

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SHOTS = DOCS / "screenshots"
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s#]+)(?:#[^)]*)?\)")


def sphinx(source: Path, out: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(source), str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )


def pages() -> list[Path]:
    return [ROOT / "README.md", *sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.parts)]


def test_the_docs_build_without_a_warning(tmp_path: Path) -> None:
    done = sphinx(DOCS, tmp_path / "html")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "WARNING" not in done.stderr, done.stderr
    html = (tmp_path / "html" / "cli.html").read_text()
    assert "rtmu sim" in html and "--install-desktop" in html  # the reference read from the parser
    shown = unescape(html)
    for line in table_text(indent="").splitlines():  # the one table, as rtmu --help prints it
        assert line.strip() in shown, f"docs/cli.md lacks the exit-code line {line.strip()!r}"


def test_a_broken_link_fails_the_build(tmp_path: Path) -> None:
    copy = shutil.copytree(DOCS, tmp_path / "docs", ignore=shutil.ignore_patterns("_build"))
    with (copy / "index.md").open("a") as index:
        index.write("\nSee [a page that is not there](nowhere.md).\n")
    assert sphinx(copy, tmp_path / "html").returncode != 0


def test_every_picture_shown_is_a_gui_tests_and_every_one_is_shown() -> None:
    shown: set[str] = set()
    for page in pages():
        for target in IMAGE.findall(page.read_text()):
            path = (page.parent / target).resolve()
            assert path.is_file(), f"{page.relative_to(ROOT)}: no picture {target}"
            assert path.parent == SHOTS, f"{page.relative_to(ROOT)}: {target} is not in docs/screenshots"
            shown.add(path.stem)
    metainfo = ET.parse(DESKTOP_DIR / f"{APP_ID}.metainfo.xml").getroot()
    for image in metainfo.findall("screenshots/screenshot/image"):
        name = (image.text or "").rsplit("/docs/screenshots/", 1)[-1]
        assert (SHOTS / name).is_file(), f"metainfo: {image.text} is not in docs/screenshots"
        shown.add(Path(name).stem)
    assert shown <= DOC_SHOTS.keys(), (
        f"not taken by a GUI test (tests/gui/doc_screenshots.py): {shown - DOC_SHOTS.keys()}"
    )
    files = {p.stem for p in SHOTS.glob("*.png")}
    assert files == DOC_SHOTS.keys(), f"docs/screenshots vs doc_screenshots.py: {files ^ DOC_SHOTS.keys()}"
    assert files <= shown, f"pictures no page shows: {files - shown}"


@pytest.mark.parametrize("name", sorted(DOC_SHOTS))
def test_each_picture_names_a_test_that_takes_it(name: str) -> None:
    node, label = DOC_SHOTS[name]
    path, _, function = node.partition("::")
    tree = ast.parse((ROOT / path).read_text())
    tests = {f.name: f for f in ast.walk(tree) if isinstance(f, ast.FunctionDef)}
    assert function in tests, f"{node}: no such test"
    source = ast.get_source_segment((ROOT / path).read_text(), tests[function]) or ""
    assert f'"{label.rpartition("/")[2]}"' in source, f"{node} saves no picture labelled {label!r}"


def test_relative_links_lead_to_files() -> None:
    for page in pages():
        for target in LINK.findall(page.read_text()):
            if "://" in target or target.startswith("mailto:"):
                continue
            assert (page.parent / target).exists(), f"{page.relative_to(ROOT)}: broken link {target}"
