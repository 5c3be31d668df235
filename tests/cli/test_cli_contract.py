"""One style of help for every subcommand, read from the real parser (a new subcommand is covered).

Every help renders without reST markup, names each value with a metavar of its own (never a dest
like ``DRIVE_TIMEOUT``), states every default, and ends with its lines of the one exit-code table;
an option name keeps one meaning across the command line (``--fps`` pictures per second,
``--port`` a robot server's port, ``--profile`` the window's saved profile).
"""

from __future__ import annotations

import argparse
import importlib
import re

import pytest

from rtmu.base import exit_codes
from rtmu.cli import build_parser
from rtmu.client.diagnosis import Step

PARSER = build_parser()
SUBPARSERS = next(a for a in PARSER._actions if isinstance(a, argparse._SubParsersAction))
COMMANDS: dict[str, argparse.ArgumentParser] = {"rtmu": PARSER, **SUBPARSERS.choices}
REST = re.compile(r"``|:(mod|class|func|meth|data|attr|ref|obj):`|\*\*\w|^\s*\.\. ", re.MULTILINE)


def visible_options(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    return [a for a in parser._actions if a.option_strings and a.help is not argparse.SUPPRESS]


def takes_a_value(action: argparse.Action) -> bool:
    return action.nargs != 0 and not isinstance(action, argparse._VersionAction)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_help_is_plain_text(name: str) -> None:
    text = COMMANDS[name].format_help()
    found = REST.search(text)
    assert found is None, (
        f"rtmu {name} --help shows reST markup: {text[max(0, found.start() - 40) : found.end() + 40]!r}"
    )


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_value_has_a_metavar_and_every_default_is_shown(name: str) -> None:
    for action in visible_options(COMMANDS[name]):
        if not takes_a_value(action):
            continue
        option = action.option_strings[-1]
        assert action.metavar is not None or action.choices, f"rtmu {name} {option}: no metavar of its own"
        default = action.default
        if default not in (None, False, "", argparse.SUPPRESS) and not isinstance(default, bool):
            assert "default" in (action.help or "").lower(), (
                f"rtmu {name} {option}: default {default!r} not said"
            )


@pytest.mark.parametrize("name", sorted(SUBPARSERS.choices))
def test_every_help_ends_with_its_exit_codes_from_the_one_table(name: str) -> None:
    module = importlib.import_module(f"rtmu.subcommands.{name}")
    codes = getattr(module, "EXITS", exit_codes.NETWORK)
    assert set(codes) <= set(exit_codes.EXIT_CODES), f"{name} exits with a code the table does not have"
    text = COMMANDS[name].format_help()
    assert "Exit codes (one table for every rtmu command):" in text
    listed = {int(m.group(1)) for m in re.finditer(r"^\s+(\d+)  ", text.split("Exit codes")[-1], re.M)}
    assert listed == set(codes)


def test_the_top_help_lists_the_whole_table_and_doctor_steps_are_its_codes() -> None:
    text = PARSER.format_help()
    for code in exit_codes.EXIT_CODES:
        assert re.search(rf"^\s+{code}  ", text, re.M), code
    doctor = {Step.RESOLVE, Step.TCP, Step.INTRODUCTION, Step.LOGIN, Step.DATA_LIST, Step.STATUS}
    assert {s.value for s in doctor} == set(
        range(exit_codes.EXIT_DOCTOR_RESOLVE, exit_codes.EXIT_DOCTOR_STATUS + 1)
    )


def where_visible(option: str) -> set[str]:
    return {
        name for name, p in COMMANDS.items() if any(option in a.option_strings for a in visible_options(p))
    }


def test_one_meaning_per_option_name_and_one_name_per_meaning() -> None:
    assert where_visible("--fps") == {"video", "record", "bridge"}, "pictures per second asked for"
    assert where_visible("--camera-hz") == {"sim"}, "only the simulated camera's own rate"
    assert where_visible("--port") == {"rtmu", "sim"}, "a robot server's port (bridge: --ws-port)"
    assert where_visible("--profile") == {"rtmu"}, "the window's saved profile (sim: --kind)"
    assert where_visible("--quality") == {"image", "video"}
    for name in ("record", "bridge"):  # the old spellings still work for scripts
        args = PARSER.parse_args(
            [name, "h", "--camera-hz", "2", *(["--foxglove"] if name == "bridge" else ["--out", "x"])]
        )
        assert args.fps == 2.0
    assert PARSER.parse_args(["bridge", "h", "--foxglove", "--port", "9000"]).ws_port == 9000
    assert PARSER.parse_args(["sim", "--profile", "aram"]).kind == "aram"
