"""The window as a screen reader reads it: its AT-SPI tree, from another process, on a bus of its own.

``rtmu`` runs as a process against the simulator with GTK's accessibility bridge on (the other GUI
tests turn it off), on the accessibility bus ``a11y_bus`` starts for this test alone; the reader
(``atspi_reader``, pyatspi as Orca uses it) walks the application's tree after turning the D-pad on
and opening Connection settings through the window's own actions. Every control must have a name
that is words, not GTK's fallback (a type name such as ``GtkButton``); the map must say where the
robot is, its mode, battery and what it is doing, and say it again when the robot has moved.
The probe window (``a11y_probe``, one unnamed icon button) proves the same check fails.

The window runs on an X server of its own (``own_screen``): on the tests' shared screen, after an About
dialog had been shown by the test process (``test_about.py`` before it in one process), the reader was
told the window's application "no longer exists" at its first action though the window lived. With a
screen of its own the test passes in any order, so the suite can run in parallel.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from rtmu.sim import SimConfig, SimThread

from .a11y_bus import accessibility_bus, missing
from .conftest import screen_of
from .harness import OFFICE_MAP
from .process import wait, xdotool

HERE = Path(__file__).parent
READER = HERE / "atspi_reader.py"
CONTROL_ROLES = {
    "push button", "toggle button", "check box", "radio button", "combo box", "text", "password text",
    "spin button", "slider", "switch", "menu item", "check menu item", "radio menu item", "entry",
    "level bar",
}  # fmt: skip
"""Roles a user operates or reads a value from. Not GTK's own scroll bars of a scrolled pane (GTK 4.8
leaves them unnamed; they move the pane the reader already reads), nor icons, which decorate a named
control; the map, a drawing, is checked on its own."""
FALLBACK = re.compile(r"^(Gtk|Adw)[A-Z]\w*$|\+")
"""GTK 4.8 names an unnamed widget by its type (``GtkButton``, ``rtmu+ui+goals_panel+GoalsPanel``)."""
OPENED = ("win.dpad", "win.settings", "win.server-config", "win.console", "win.why")
"""What the reader opens through the window's own actions before it reads: the D-pad, connection
settings, the server's configuration, the console and "why won't it move?"."""
MNEMONIC_TWICE = re.compile(r"^(\S*_\S*) (\S+)$")
"""GTK 4.8's name for a mnemonic button, ``_Cancel Cancel``: the raw label read out, then the label."""


def _skip_or_fail() -> None:
    why = missing()
    if why:
        if os.environ.get("CI", "").lower() in ("true", "1"):
            pytest.fail(f"CI=true but the accessibility test cannot run: {why}", pytrace=False)
        pytest.skip(why)


def read_tree(pid: int, env: dict[str, str], *activate: str) -> list[dict[str, Any]]:
    argv = [sys.executable, str(READER), str(pid), *(a for act in activate for a in ("--activate", act))]
    out = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    nodes: list[dict[str, Any]] = json.loads(out.stdout.splitlines()[-1])["nodes"]
    return nodes


def unnamed_controls(nodes: list[dict[str, Any]]) -> list[str]:
    """Each control without words for a name: ``role 'name' at path``."""
    bad = []
    for n in nodes:
        if n["role"] not in CONTROL_ROLES:
            continue
        twice = MNEMONIC_TWICE.match(n["name"])
        if not n["name"].strip() or FALLBACK.search(n["name"]) or (twice and "_" in twice[1]):
            bad.append(f"{n['role']} {n['name']!r} at {n['path']} ({n['description'][:60]!r})")
    return bad


def test_a_control_without_a_name_is_found(tmp_path: Path) -> None:
    """The check can fail: the probe's unnamed icon button is reported, its named one is not."""
    _skip_or_fail()
    with accessibility_bus(tmp_path / "runtime") as env:
        proc = subprocess.Popen(
            [sys.executable, str(HERE / "a11y_probe.py")], env=env, stderr=subprocess.PIPE
        )
        try:
            nodes = read_tree(proc.pid, env)
        finally:
            proc.terminate()
            proc.wait(10)
    bad = unnamed_controls(nodes)
    assert len(bad) == 1 and bad[0].startswith("push button"), bad
    assert any(n["role"] == "push button" and n["name"] == "Up" for n in nodes)


def own_screen() -> contextlib.AbstractContextManager[str]:
    """An X server for this window alone (':N'): the window is the only client on it, so what GUI tests
    before it left on the shared screen cannot reach it (after an About dialog shown in the test
    process, the reader lost the window's application on a shared screen)."""
    return screen_of("1280x1024")


@contextmanager
def window_on_its_bus(tmp_path: Path) -> Iterator[tuple[subprocess.Popen[str], dict[str, str], SimThread]]:
    """``rtmu`` as a process on an accessibility bus of its own, connected to a simulator: (process,
    the environment a reader needs, the simulator); all of it ended after."""
    _skip_or_fail()
    with (
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim,
        accessibility_bus(tmp_path / "runtime") as env,
        own_screen() as display,
    ):
        env["XDG_CONFIG_HOME"] = str(tmp_path / "config")
        env["DISPLAY"] = display
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(sim.port)],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        try:
            search = ("search", "--sync", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU")
            xdotool(*search, display=display)
            wait(
                lambda: sim.call(lambda: any(s.subscriptions for s in sim.server.sessions)), 30, "subscribed"
            )
            yield proc, env, sim
        finally:
            proc.terminate()
            proc.wait(15)


def test_every_control_has_a_name_and_the_map_says_where_the_robot_is(tmp_path: Path) -> None:
    with window_on_its_bus(tmp_path) as (proc, env, sim):
        nodes = read_tree(proc.pid, env, *OPENED)
        for _attempt in range(20):  # a busy machine: the D-pad and the dialog may come a little later
            shown = {n["name"] for n in nodes}
            if {"Forward", "Host", "Show up to", "Call once"} <= shown and any(
                n["role"] == "spin button" for n in nodes
            ):
                break
            time.sleep(1.0)
            nodes = read_tree(proc.pid, env)
        assert len(nodes) > 100, f"a tree this small is not the window's: {nodes[:3]}"
        assert not unnamed_controls(nodes), "\n".join(unnamed_controls(nodes))
        names = {(n["role"], n["name"]) for n in nodes}
        for pad in ("Forward", "Turn left", "Turn right", "Backward", "Stop"):
            assert ("push button", pad) in names, f"the D-pad's {pad} is not a named button"
        assert ("push button", "STOP") in names
        assert ("level bar", "Battery level") in names
        assert ("text", "Host") in names  # the settings dialog's fields say what they are
        (stage,) = [n for n in nodes if n["role"] == "image" and n["name"] == "Map"]
        before = stage["description"]
        for words in ("Robot at x", "heading", "mode", "battery", "volts", "standing still"):
            assert words in before, before

        # The robot moves 2 m (put there in the simulator): a screen reader hears the map's new words.
        listener = subprocess.Popen(
            [sys.executable, str(READER), str(proc.pid), "--events", "8"],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        assert listener.stdout is not None
        first = listener.stdout.readline()  # after the walk: {"listening": true}
        assert json.loads(first or "{}").get("listening"), listener.stderr.read() if listener.stderr else ""
        sim.call(lambda: setattr(sim.server.world.body, "x", sim.server.world.body.x + 2000.0))
        out, err = listener.communicate(timeout=120)
        assert listener.returncode == 0, err
        heard = json.loads(out.splitlines()[-1])["events"]
        said = [e["value"] for e in heard if e["name"] == "Map" and "description" in e["type"]]
        assert any("Robot at x" in s and s != before for s in said), heard
        assert len(said) <= 3, f"the map repeated itself: {said}"  # one material change, said once


POPOVERS = {
    "win.open-menu": ("menu item", "Connection settings…"),
    "win.goto-panel": ("list item", "Corridor End"),
    "win.layers": ("check box", "sonar"),
}
"""Each popover opened through its window action, and one control it must show by role and name.
A popover is a surface of its own that exists only while open: the first walk of the tree (above)
never sees one, so each is opened and read on its own."""


def test_every_popover_is_read_with_named_controls(tmp_path: Path) -> None:
    with window_on_its_bus(tmp_path) as (proc, env, _sim):
        for action, (role, name) in POPOVERS.items():
            nodes = read_tree(proc.pid, env, action)
            for _attempt in range(20):  # a busy machine: the popover may open a little later
                if any(n["role"] == role and n["name"].startswith(name) for n in nodes):
                    break
                time.sleep(1.0)
                nodes = read_tree(proc.pid, env)
            shown = sorted({(n["role"], n["name"]) for n in nodes if n["role"] in CONTROL_ROLES})
            assert any(n["role"] == role and n["name"].startswith(name) for n in nodes), (action, shown)
            assert not unnamed_controls(nodes), f"{action}: " + "\n".join(unnamed_controls(nodes))
            assert not [n for n in nodes if n["role"] == "list item" and not n["name"].strip()], action


def test_the_keys_window_is_read_row_by_row_each_row_saying_its_keys(tmp_path: Path) -> None:
    """Help ▸ Keyboard shortcuts read as a screen reader does: its search is named, and every row of
    the one key table is a list item whose name is its words and its keys."""
    from rtmu.ui.keys import bindings
    from rtmu.ui.keys_sheet import KeySheet

    rows = KeySheet.of(bindings()).rows
    with window_on_its_bus(tmp_path) as (proc, env, _sim):
        nodes = read_tree(proc.pid, env, "win.show-keys")
        for _attempt in range(20):  # a busy machine: the window may open a little later
            if any(n["role"] == "list item" and n["name"] == rows[0].spoken() for n in nodes):
                break
            time.sleep(1.0)
            nodes = read_tree(proc.pid, env)
        items = [
            n["name"] for n in nodes if n["role"] == "list item" and n["name"] in {r.spoken() for r in rows}
        ]
        assert sorted(items) == sorted(r.spoken() for r in rows), "a row of the table not read"
        assert "Zoom in: Ctrl++ / Ctrl+= / Ctrl+Keypad +" in items
        assert any(n["name"] == "Search the keys" for n in nodes), "the search is not named"
        assert not unnamed_controls(nodes), "\n".join(unnamed_controls(nodes))
