"""A window with one icon-only button and no name for it: the accessibility check must find it.

Run by ``test_a11y_tree`` as a process of its own (with its accessibility bus): the proof that
the check the window passes can fail.
"""

from __future__ import annotations

import sys

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402


def main() -> int:
    app = Gtk.Application(application_id="io.github.rtmu.A11yProbe")

    def activate(_app: Gtk.Application) -> None:
        window = Gtk.ApplicationWindow(application=app, title="probe")
        box = Gtk.Box()
        named = Gtk.Button(icon_name="go-up-symbolic")
        named.update_property([Gtk.AccessibleProperty.LABEL], ["Up"])
        box.append(named)
        box.append(Gtk.Button(icon_name="go-down-symbolic"))  # the control without a name
        window.set_child(box)
        window.present()

    app.connect("activate", activate)
    return app.run([])


if __name__ == "__main__":
    sys.exit(main())
