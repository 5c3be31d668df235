"""The baseline of ``bench_window``: a bare GTK 4 window of the operator window's size, doing nothing.

``python -m bench.bare_window`` prints ``first frame`` once its first frame is painted, then sits
idle until SIGTERM: what launch time, memory and idle CPU cost before any application code.
"""

from __future__ import annotations

import signal
import sys

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402


def main() -> int:
    app = Gtk.Application(application_id="org.rtmu.BenchBareWindow")

    def activate(_app: Gtk.Application) -> None:
        window = Gtk.ApplicationWindow(application=app, title="bare")
        window.set_default_size(1024, 700)
        area = Gtk.DrawingArea(hexpand=True, vexpand=True)
        window.set_child(area)
        painted = [False]

        def after_paint(_clock: object) -> None:
            if not painted[0]:
                painted[0] = True
                print("first frame", flush=True)

        window.present()
        clock = window.get_frame_clock()
        if clock is not None:
            clock.connect("after-paint", after_paint)
        else:  # not realized yet: the first map of the surface paints it
            window.connect("map", lambda w: w.get_frame_clock().connect("after-paint", after_paint))

    app.connect("activate", activate)
    GLib.unix_signal_add(GLib.PRIORITY_DEFAULT, signal.SIGTERM, app.quit)
    return app.run([sys.argv[0]])


if __name__ == "__main__":
    raise SystemExit(main())
