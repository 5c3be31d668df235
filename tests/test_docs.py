"""The documentation builds with warnings as errors, and every picture in it is a GUI test's.

Sphinx (MyST Markdown) builds ``docs/`` as CI would; a broken link, a missing page or image, or a
bad directive fails the build. The pictures in ``docs/screenshots`` are taken by the GUI tests
named in ``tests/gui/doc_screenshots.py`` (``./rtmu-dev screenshots`` takes them again): every
picture the docs, the README and the AppStream metainfo show must be one of them.
"""

from __future__ import annotations

import argparse
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


def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def plain_text(html: str) -> str:
    """What a reader sees of some HTML: no tags, entities and typographic quotes undone, spaces as one."""
    inline = re.sub(r"</?(?:span|code|em|strong|a)\b[^>]*>", "", html)
    text = unescape(re.sub(r"<[^>]+>", " ", inline)).translate(str.maketrans("‘’“”", "''\"\""))
    return " ".join(text.split()) + " "


def pages() -> list[Path]:
    return [ROOT / "README.md", *sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.parts)]


def test_the_docs_build_without_a_warning(tmp_path: Path) -> None:
    done = sphinx(DOCS, tmp_path / "html")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "WARNING" not in done.stderr, done.stderr
    html = (tmp_path / "html" / "cli.html").read_text()
    assert "rtmu sim" in html and "--install-desktop" in html  # the reference read from the parser
    from rtmu.base.exit_codes import EXIT_CODES
    from rtmu.cli import build_parser

    for name, sub in subcommands(build_parser()).items():  # every subcommand, and files' and scan's actions
        assert f'id="cli-{name}"' in html, f"the CLI reference has no rtmu {name}"
        for action in subcommands(sub):
            assert f'id="cli-{name}-{action}"' in html, f"the CLI reference has no rtmu {name} {action}"
    table = plain_text(html[html.index('id="exit-codes"') : html.index('id="reference"')])
    for code, meaning in EXIT_CODES.items():  # the one table, generated from rtmu.base.exit_codes
        assert f" {code} {meaning} " in table, f"the exit-code table does not say {code} {meaning}"


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


FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)
SPAN = re.compile(r"`([^`\n]+)`")
OPTION = re.compile(r"(?<![\w-])(--?[a-zA-Z][\w-]*)")


def shown_command_lines(text: str) -> list[str]:
    """Every ``rtmu …`` the page shows: lines of its code blocks (comments cut) and inline code."""
    lines = [line.split(" # ")[0] for block in FENCE.findall(text) for line in block.splitlines()]
    lines += SPAN.findall(FENCE.sub("", text))
    out = []
    for line in lines:
        for part in line.split(" | "):
            words = part.strip().split()
            if words and words[0] == "rtmu":
                out.append(part.strip())
    return out


def options_of(parser: argparse.ArgumentParser) -> set[str]:
    """The visible options of ``parser`` and of its own sub-actions (``files ls``, ``scan stop`` …)."""
    found: set[str] = set()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for nested in action.choices.values():
                found |= options_of(nested)
        elif action.help is not argparse.SUPPRESS:
            found |= set(action.option_strings)
    return found


def test_no_page_shows_a_command_or_option_rtmu_help_does_not_have() -> None:
    from rtmu.cli import build_parser

    parser = build_parser()
    commands = subcommands(parser)
    wrong = []
    for page in pages():
        for line in shown_command_lines(page.read_text()):
            words = line.split()
            name = words[1] if len(words) > 1 else ""
            if re.fullmatch(r"[a-z]+", name) and name not in commands:
                wrong.append(f"{page.relative_to(ROOT)}: `{line}`: no subcommand {name!r}")
                continue
            known = options_of(commands[name]) if name in commands else options_of(parser)
            for option in OPTION.findall(" ".join(words[1:])):
                if option not in known:
                    wrong.append(f"{page.relative_to(ROOT)}: `{line}`: {option} is not in its --help")
    assert not wrong, "\n".join(wrong)
