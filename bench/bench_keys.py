"""The keys window (Help ▸ Keyboard shortcuts): what opening it and typing in its search cost.

* ``keys.open_ms`` (ms): RTMU's keys window made from the one key table (``KeySheet.of(bindings())``),
  presented and drawn once, in a fresh window each time (median of several). Baseline: GTK 4.8's own
  ``GtkShortcutsWindow`` built from builder XML listing the same rows — the window RTMU had before
  issue 27 — presented and drawn the same way, in the same run.
* ``keys.search_ms`` (ms): one search typed into the open window — the rows filtered and the list laid
  out and drawn again (median over a few searches, each cleared after).

Both run in a child process on an Xvfb of their own (skipped with a note without Xvfb).
"""

from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from xml.sax.saxutils import escape

from bench.common import Result, end_process, start_xvfb

OPENS = 7
SEARCHES = ("zoom", "ctrl", "robot", "space", "camera", "f")


def _shortcuts_xml(rows: list[tuple[str, str, tuple[str, ...]]]) -> str:
    """The baseline: GTK's shortcuts window listing ``(group, title, accels)`` rows."""
    out = ['<interface><object class="GtkShortcutsWindow" id="w"><child><object class="GtkShortcutsSection">']
    group = None
    for g, title, accels in rows:
        if g != group:
            out += ["</object></child>"] if group is not None else []
            out += [f'<child><object class="GtkShortcutsGroup"><property name="title">{escape(g)}</property>']
            group = g
        out += [
            '<child><object class="GtkShortcutsShortcut">',
            f'<property name="title">{escape(title)}</property>',
            f'<property name="accelerator">{escape(" ".join(accels[:2]))}</property>',
            "</object></child>",
        ]
    out += ["</object></child>"] if group is not None else []
    out += ["</object></child></object></interface>"]
    return "".join(out)


def _child() -> None:
    import gi

    gi.require_version("Gtk", "4.0")
    from gi.repository import GLib, Gtk

    from rtmu.ui.keys import bindings
    from rtmu.ui.keys_sheet import KeySheet
    from rtmu.ui.keys_window import KeysWindow
    from rtmu.ui.style import install_css

    Gtk.init()
    install_css()
    ctx = GLib.MainContext.default()
    parent = Gtk.Window()
    parent.present()

    def drawn(window: Gtk.Window) -> None:
        """Pump until the window is mapped and one frame of it has been painted."""
        painted: list[bool] = []
        while not window.get_mapped():
            ctx.iteration(True)
        clock = window.get_frame_clock()
        handler = clock.connect("after-paint", lambda _c: painted.append(True))
        window.queue_draw()
        while not painted:
            ctx.iteration(True)
        clock.disconnect(handler)

    def settle() -> None:
        while ctx.pending():
            ctx.iteration(False)

    table = bindings()
    rows = [(r.group, r.title, r.accels) for r in KeySheet.of(table).rows]
    xml = _shortcuts_xml(rows)
    ours: list[float] = []
    gtk: list[float] = []
    for _ in range(OPENS):
        start = time.perf_counter()
        keys = KeysWindow(parent, KeySheet.of(table))
        keys.present()
        drawn(keys)
        ours.append((time.perf_counter() - start) * 1000)
        keys.destroy()
        settle()
        start = time.perf_counter()
        builder = Gtk.Builder.new_from_string(xml, -1)
        shortcuts = builder.get_object("w")
        shortcuts.set_transient_for(parent)
        shortcuts.present()
        drawn(shortcuts)
        gtk.append((time.perf_counter() - start) * 1000)
        shortcuts.destroy()
        settle()
    keys = KeysWindow(parent, KeySheet.of(table))
    keys.present()
    drawn(keys)
    searches: list[float] = []
    for query in SEARCHES:
        start = time.perf_counter()
        keys.filter(query)
        drawn(keys)
        searches.append((time.perf_counter() - start) * 1000)
        keys.filter("")
        drawn(keys)
    print(json.dumps({"ours": ours, "gtk": gtk, "search": searches}))


def run() -> list[Result]:
    if shutil.which("Xvfb") is None:
        print("# keys: Xvfb is needed: figures skipped", file=sys.stderr)
        return []
    xvfb, display = start_xvfb()
    try:
        env = dict(os.environ, DISPLAY=display, GTK_A11Y="none")
        out = subprocess.run(
            [sys.executable, "-m", "bench.bench_keys", "--child"],
            env=env, capture_output=True, text=True, timeout=300, check=True,
        )  # fmt: skip
    finally:
        end_process(xvfb)
    f = json.loads(out.stdout.splitlines()[-1])
    ours, gtk = (", ".join(f"{v:.0f}" for v in f[k]) for k in ("ours", "gtk"))
    print(f"# keys: open {ours} ms; GTK's shortcuts window {gtk} ms", file=sys.stderr)
    return [
        Result("keys.open_ms", statistics.median(f["ours"]), "ms", statistics.median(f["gtk"])),
        Result("keys.search_ms", statistics.median(f["search"]), "ms"),
    ]


if __name__ == "__main__" and sys.argv[1:] == ["--child"]:
    _child()
