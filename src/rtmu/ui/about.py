"""The About dialog: RTMU's own icon (from the package, installed or not) and its licence in plain words.

GTK's ready-made MIT text reads "See the The MIT License (MIT)", and a logo named only by icon name
is a broken image wherever the desktop files are not installed (a wheel, a checkout): the icon is
loaded from the package's own SVG, and the licence is said in RTMU's words.
"""

from __future__ import annotations

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, GLib, Gtk  # noqa: E402

from ..package_data import APP_ID, DESKTOP_DIR  # noqa: E402

LICENSE_TEXT = (
    "RTMU is free software under the MIT License: use, copy, change and share it, keeping the "
    "copyright notice. It comes with absolutely no warranty; the LICENSE file has the full text."
)
COMMENTS = (
    "Robot Teleoperation, Mobile User interface: drive an ARIA (ArNetworking) robot "
    "from a tablet or a laptop."
)


def app_logo() -> Gdk.Texture | None:
    """RTMU's icon from the package (None when this system cannot read SVG: the dialog shows none)."""
    try:
        return Gdk.Texture.new_from_filename(str(DESKTOP_DIR / f"{APP_ID}.svg"))
    except GLib.Error:
        return None


def about_dialog(parent: Gtk.Window, version: str) -> Gtk.AboutDialog:
    about = Gtk.AboutDialog(
        transient_for=parent,
        modal=True,
        program_name="RTMU",
        version=version,
        comments=COMMENTS,
        license_type=Gtk.License.CUSTOM,
        license=LICENSE_TEXT,
        wrap_license=True,
    )
    logo = app_logo()
    if logo is not None:
        about.set_logo(logo)
    return about
