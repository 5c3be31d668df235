"""What a GUI test leaves behind is removed before the next one starts, even when it fails.

Why: one failing test must fail alone. A test that dies while a drive key is held, or before it
closed its window or killed its ``rtmu`` process, would otherwise leave a key down on the shared X
server, a window holding the focus and a robot client (and its guardian) running — and every later
test would inherit them.

Processes are found by an environment mark, ``RTMU_GUI_OWNER``, that each test sets in
``os.environ`` before it runs: every process it starts inherits it, also grandchildren that have been
orphaned (a guardian whose window was killed), so nothing is missed and nothing of another test is
touched.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

OWNER = "RTMU_GUI_OWNER"
HELD_KEYS = [
    *("Up", "Down", "Left", "Right", "KP_Up", "KP_Down", "KP_Left", "KP_Right", "KP_8", "KP_2"),
    *("KP_4", "KP_6", "space", "Escape", "w", "a", "s", "d", "q", "e", "x", "z"),
    *("Shift_L", "Shift_R", "Control_L", "Control_R", "Alt_L", "Alt_R", "Super_L"),
]
"""Every key a test may hold (drive keys, their keypad twins, modifiers)."""
GRACE = 4.0
"""How long processes that are already ending (a guardian reaped 3 s after goodbye) may take."""


def marked(mark: str) -> list[int]:
    """The live processes (not zombies) that carry ``RTMU_GUI_OWNER=mark`` in their environment."""
    needle = f"\0{OWNER}={mark}\0".encode()
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            if needle not in b"\0" + (entry / "environ").read_bytes() + b"\0":
                continue
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:  # gone meanwhile, or not ours to read
            continue
        if state != "Z":
            found.append(int(entry.name))
    return found


def command_line(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
    except OSError:
        return f"pid {pid}"


def reap_children() -> None:
    """Collect exited children nobody waits for, so they do not linger as zombies."""
    while True:
        try:
            pid, _status = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return


def end_processes(mark: str, grace: float = GRACE) -> list[str]:
    """Wait ``grace`` for the marked processes to end on their own, then kill the rest (SIGCONT first:
    a SIGSTOPped process cannot die of SIGTERM). Returns the command lines of those it had to kill."""
    deadline = time.monotonic() + grace
    while (left := marked(mark)) and time.monotonic() < deadline:
        time.sleep(0.05)
    killed = [command_line(pid) for pid in left]
    for pid in left:
        for signum in (signal.SIGCONT, signal.SIGKILL):
            try:
                os.kill(pid, signum)
            except ProcessLookupError:
                break
    deadline = time.monotonic() + 5
    while marked(mark) and time.monotonic() < deadline:
        time.sleep(0.05)
    return killed


def release_input(display: str | None = None) -> None:
    """Key up every key a test may hold and lift the mouse buttons: XTest keeps what a dead test
    pressed down until someone releases it."""
    env = dict(os.environ, DISPLAY=display) if display else None
    commands = [["xdotool", "keyup", *HELD_KEYS]] + [["xdotool", "mouseup", b] for b in ("1", "2", "3")]
    for argv in commands:
        try:
            subprocess.run(argv, env=env, capture_output=True, timeout=15, check=False)
        except subprocess.TimeoutExpired:  # an X server that does not answer: the next test says so itself
            sys.stderr.write(f"rtmu gui isolation: {' '.join(argv[:2])} got no answer from the X server\n")
            return


def close_all(closers: dict[int, Callable[[], None]]) -> int:
    """Run the teardown of every in-process app a test left open; how many there were."""
    count = 0
    while closers:
        _key, close = closers.popitem()
        count += 1
        with contextlib.suppress(Exception):  # a broken app must not stop the reset of the next one
            close()
    return count


def destroy_windows() -> list[str]:
    """Destroy every toplevel window this process still has once a test's apps are closed; the titles
    of those still on screen. A dialog left mapped stays above the next test's window on the shared X
    screen (no window manager) and takes its clicks: every later click test would fail."""
    if "gi.repository.Gtk" not in sys.modules:  # this process never opened a window
        return []
    from gi.repository import Gtk

    from rtmu.ui.dialog_chain import close_popovers

    shown = []
    for window in list(Gtk.Window.list_toplevels()):
        if isinstance(window, Gtk.Window):
            close_popovers(window)  # an open popover's grab would outlive its window (X11)
            if window.get_mapped():
                shown.append(window.get_title() or type(window).__name__)
            window.destroy()
    return shown
