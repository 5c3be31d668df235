"""Help ▸ About: what RTMU is, its logo, its licence in plain words, and the debug information support
asks for — versions, the robot's protocol strings and introduction tag, the last ``rtmu doctor`` —
copied to the clipboard in one click.

GTK's own MIT licence line reads "See the The MIT License (MIT) for details" (the licence's name
already starts with "The"), so the licence is given as RTMU's own sentence. The logo is the package's
SVG, loaded from the file: a checkout or a wheel has no icon installed in the theme, and GTK showed
a broken-image icon for the name.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib, Gtk  # noqa: E402

from .. import __version__  # noqa: E402
from ..base.i18n import N_, _  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..model.observables import ConnectionState  # noqa: E402
from ..package_data import APP_ID, DESKTOP_DIR  # noqa: E402
from ..settings.last_doctor import load_last_doctor  # noqa: E402
from ..versions import version_lines  # noqa: E402
from . import accessible  # noqa: E402

LICENSE_TEXT = N_(
    "RTMU is free software under the MIT License: use, copy, change and share it, keeping the "
    "copyright notice. It comes with absolutely no warranty; the LICENSE file has the full text."
)
COMMENTS = N_(
    "Robot Teleoperation, Mobile User interface: drive an ARIA (ArNetworking) robot "
    "from a tablet or a laptop."
)
WEBSITE = "https://github.com/rtmu/rtmu"


def robot_lines(conn: ConnectionState, profile: str) -> list[str]:
    """The robot shown, as support needs it; the server's words escaped (they are untrusted)."""
    where = f"{conn.host}:{conn.port}" if conn.host else "(none)"
    lines = [f"robot: {where} (profile {visible(profile) or '-'}), {conn.phase.value}"]
    if conn.server_tag or conn.server_protocol:
        lines.append(f"server introduction tag: {visible(conn.server_tag) or '-'}")
        lines.append(f"protocol string the server asked for: {visible(conn.server_protocol) or '(none)'}")
        lines.append(f"protocol string sent: {visible(conn.sent_protocol) or '(none)'}")
        lines.append(f"data the server offers: {len(conn.offers)}")
    else:
        lines.append("server: not connected on this run, no introduction yet")
    if conn.error:
        lines.append(f"last error: {visible(conn.error)}")
    return lines


def debug_information(
    conn: ConnectionState, profile: str, last_doctor: Callable[[], str] = load_last_doctor
) -> str:
    """The whole text the Copy button copies (and the dialog's System page shows)."""
    return "\n".join(
        [*version_lines(), "", *robot_lines(conn, profile), "", "last rtmu doctor:", last_doctor()]
    )


def app_logo() -> Gdk.Texture | None:
    """RTMU's icon from the package (None when this system cannot read SVG: the dialog shows none)."""
    try:
        return Gdk.Texture.new_from_filename(str(DESKTOP_DIR / f"{APP_ID}.svg"))
    except GLib.Error:
        return None  # no SVG loader (gdk-pixbuf without librsvg): no logo rather than a broken one


def about_dialog(parent: Gtk.Window, conn: ConnectionState, profile: str) -> Gtk.AboutDialog:
    """The About dialog, with a "Copy debug information" button in its header bar."""
    info = debug_information(conn, profile)
    about = Gtk.AboutDialog(
        transient_for=parent,
        modal=True,
        program_name="RTMU",
        version=__version__,
        comments=_(COMMENTS),
        website=WEBSITE,
        license_type=Gtk.License.CUSTOM,
        license=_(LICENSE_TEXT),
        wrap_license=True,
        system_information=info,
    )
    paintable = app_logo()
    if paintable is not None:
        about.set_logo(paintable)
    copy = Gtk.Button(
        label=_("Copy debug information"), tooltip_text=_("Versions, the robot, the last rtmu doctor")
    )
    accessible.name(copy, _("Copy debug information"))
    copy.connect("clicked", lambda b: _copy(b, info))
    header = about.get_titlebar()
    if isinstance(header, Gtk.HeaderBar):
        header.pack_start(copy)
    about.copy_button = copy  # type: ignore[attr-defined]  # for tests
    return about


def _copy(button: Gtk.Button, text: str) -> None:
    button.get_clipboard().set(text)
    button.set_label(_("Copied"))
