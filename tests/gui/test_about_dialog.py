"""About names RTMU's licence once, in plain words, and shows RTMU's own icon (issue 21: "See the The
MIT License" and a broken-image logo). Opened by its menu action; its pixels are kept."""

from __future__ import annotations

import gi

from simulators import simulator

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402

from .harness import OFFICE_MAP, Gui, pump  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def test_about_has_its_logo_and_says_its_licence_once(gui: Gui) -> None:
    gui.window.activate_action("win.about", None)

    def about() -> Gtk.AboutDialog | None:
        return next((w for w in Gtk.Window.list_toplevels() if isinstance(w, Gtk.AboutDialog)), None)

    pump(lambda: about() is not None and about().get_mapped(), 5, "the About dialog")  # type: ignore[union-attr]
    dialog = about()
    assert dialog is not None
    assert isinstance(dialog.get_logo(), Gdk.Texture), "no logo of its own (a broken image)"
    assert dialog.get_license_type() is Gtk.License.CUSTOM
    text = dialog.get_license() or ""
    assert "MIT License" in text and "the The" not in text
    gui.render(dialog, gui.shots / f"{gui.name}-dialog.png")
    dialog.close()
