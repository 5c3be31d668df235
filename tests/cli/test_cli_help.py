"""Every ``--help`` prints and exits 0: argparse formats help strings with ``%``, so a bare ``%`` crashes.

The subcommands are read from the real parser, so a new subcommand is covered without touching this file.
"""

from __future__ import annotations

import argparse

import pytest

from rtmu.cli import build_parser, main


def _subcommand_names() -> list[str]:
    parser = build_parser()
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    assert len(actions) == 1, "rtmu should have exactly one set of subcommands"
    return sorted(actions[0].choices)


SUBCOMMANDS = _subcommand_names()


def test_subcommands_are_discovered() -> None:
    assert {"drive", "status", "sim", "decode"} <= set(SUBCOMMANDS)


def _help_of(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: rtmu")
    return out


def test_top_level_help(capsys: pytest.CaptureFixture[str]) -> None:
    out = _help_of(["--help"], capsys)
    for name in SUBCOMMANDS:
        assert name in out


@pytest.mark.parametrize("name", SUBCOMMANDS)
def test_subcommand_help(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    out = _help_of([name, "--help"], capsys)
    assert f"usage: rtmu {name}" in out
