"""The connection settings dialog: profile, host, port, user, password, remember; Save / Cancel.

Every field is checked as it is typed (:func:`validate`, pure) and a problem is
shown in an inline message under the field; Save stays insensitive until the
form is valid. Picking another profile in the list loads its fields; typing a
new name saves a new profile. A profile named after its address follows a changed host or port.
The dialog never connects and never writes files
itself: ``on_save(profile, password)`` hands the result to the window.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import replace

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..settings.store import DEFAULT_PORT, Profile, address_name  # noqa: E402
from . import accessible  # noqa: E402
from .layout import screen_size  # noqa: E402

_HOST = re.compile(r"^[A-Za-z0-9]([A-Za-z0-9.\-]*[A-Za-z0-9])?$")
_IPV6 = re.compile(r"^[0-9A-Fa-f:.]+$")


def validate(name: str, host: str, port: str, user: str, remember: bool) -> dict[str, str]:
    """Field name → message for every field that is wrong ({} when the form can be saved)."""
    errors: dict[str, str] = {}
    name, host, port, user = name.strip(), host.strip(), port.strip(), user.strip()
    if not name:
        errors["name"] = _("Give the profile a name.")
    elif len(name) > 200 or not name.isprintable():
        errors["name"] = _("Use up to 200 printable characters.")
    if not host:
        errors["host"] = _("Enter the robot server's host name or address.")
    elif len(host) > 255 or not (_HOST.match(host) or (":" in host and _IPV6.match(host))):
        errors["host"] = _("Not a host name or IP address (letters, digits, dots and dashes).")
    if not port:
        errors["port"] = _("Enter a port (ARIA servers use {DEFAULT_PORT}).").format(
            DEFAULT_PORT=DEFAULT_PORT
        )
    elif not port.isdigit() or not 1 <= int(port) <= 65535:
        errors["port"] = _("The port is a number from 1 to 65535.")
    if len(user) > 200:
        errors["user"] = _("The user name is too long.")
    if remember and not user:
        errors["remember"] = _("A password is remembered only together with a user name.")
    return errors


class ConnectionDialog(Gtk.Window):
    """Modal over the main window. ``on_save(profile, password_or_None)``; password None = unchanged."""

    def __init__(
        self,
        parent: Gtk.Window,
        profiles: Mapping[str, Profile],
        current: Profile,
        *,
        on_save: Callable[[Profile, str | None], None],
        keyring_available: bool,
    ) -> None:
        super().__init__(title=_("Connection settings"), modal=True, transient_for=parent)
        screen = screen_size()  # a 360 px phone: the dialog takes its width, no more
        self.set_default_size(440 if screen is None else min(440, screen[0] - 16), -1)
        self.set_resizable(False)
        self.add_css_class("connection-dialog")
        self._profiles = dict(profiles)
        self._on_save = on_save
        self._loading = False
        self._base = current

        grid = Gtk.Grid(row_spacing=2, column_spacing=12)
        grid.set_margin_top(16)
        grid.set_margin_bottom(8)
        grid.set_margin_start(16)
        grid.set_margin_end(16)
        self.profile = Gtk.ComboBoxText.new_with_entry()
        for name in self._profiles:
            self.profile.append(name, name)
        self.profile_entry: Gtk.Entry = self.profile.get_child()  # type: ignore[assignment]
        accessible.name(self.profile_entry, _("Profile name"))
        accessible.name_inner_toggle(self.profile, _("Profiles"))
        self.host = Gtk.Entry(placeholder_text=_("robot.local or 192.168.1.10"), hexpand=True)
        self.port = Gtk.Entry(placeholder_text=str(DEFAULT_PORT), input_purpose=Gtk.InputPurpose.DIGITS)
        self.user = Gtk.Entry(placeholder_text=_("(none)"))
        self.password = Gtk.PasswordEntry(show_peek_icon=True, hexpand=True)
        self.password.set_property("placeholder-text", _("(unchanged)"))
        self.remember = Gtk.CheckButton(label=_("Remember the password in the keyring"))
        if not keyring_available:
            self.remember.set_label(_("Remember the password (this session only: no keyring)"))
        self.reconnect = Gtk.CheckButton(label=_("Reconnect automatically when the link is lost"))
        for check in (self.remember, self.reconnect):  # long sentences wrap on a phone
            label = check.get_last_child()
            if isinstance(label, Gtk.Label):
                label.set_wrap(True)
                label.set_max_width_chars(30)
        self.protocol = Gtk.Entry(placeholder_text=_("(the one the server asks for)"), max_length=200)
        self.protocol.set_tooltip_text(
            _(
                "Protocol string sent at login. Leave empty: RTMU answers with the string the server "
                "advertises (Omron LD robots: 6MTX)."
            )
        )
        self.errors: dict[str, Gtk.Label] = {}
        rows = (
            ("name", _("Profile"), self.profile),
            ("host", _("Host"), self.host),
            ("port", _("Port"), self.port),
            ("user", _("User"), self.user),
            ("password", _("Password"), self.password),
            ("remember", "", self.remember),
            ("reconnect", "", self.reconnect),
            ("protocol", _("Protocol"), self.protocol),
        )
        for i, (key, caption, widget) in enumerate(rows):
            if caption:
                label = Gtk.Label(label=caption, xalign=1.0)
                label.add_css_class("dim-label")
                grid.attach(label, 0, 2 * i, 1, 1)
            grid.attach(widget, 1, 2 * i, 1, 1)
            if caption:  # the caption beside it is not tied to it: the entry says its own name
                accessible.name(widget, caption)
            message = Gtk.Label(xalign=0.0, wrap=True, max_width_chars=40, visible=False)
            message.add_css_class("field-error")
            message.set_use_markup(False)
            grid.attach(message, 1, 2 * i + 1, 1, 1)
            self.errors[key] = message

        buttons = Gtk.Box(spacing=8, halign=Gtk.Align.END)
        buttons.set_margin_top(8)
        buttons.set_margin_bottom(16)
        buttons.set_margin_end(16)
        cancel = accessible.mnemonic_button(_("_Cancel"))
        cancel.connect("clicked", lambda _b: self.close())
        self.save = accessible.mnemonic_button(_("_Save"))
        self.save.add_css_class("suggested-action")
        self.save.connect("clicked", self._save)
        buttons.append(cancel)
        buttons.append(self.save)
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL)
        box.append(grid)
        box.append(buttons)
        self.set_child(box)
        self.set_default_widget(self.save)

        self._load(current)
        self.profile.connect("changed", self._profile_changed)
        for entry in (self.host, self.port, self.user):
            entry.connect("changed", lambda _e: self._address_changed())
        for entry in (self.profile_entry, self.host, self.port, self.user):
            entry.connect("changed", lambda _e: self.check())
            entry.set_activates_default(True)
        self.password.set_property("activates-default", True)
        self.remember.connect("toggled", lambda _b: self.check())
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.check()

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        from gi.repository import Gdk

        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        return False

    def _load(self, profile: Profile) -> None:
        self._loading = True
        self._base = profile
        self._address_name = address_name(profile.host, str(profile.port), profile.user)
        self.profile_entry.set_text(profile.name)
        self.host.set_text(profile.host)
        self.port.set_text(str(profile.port))
        self.user.set_text(profile.user)
        self.password.set_text("")
        self.remember.set_active(profile.remember_password)
        self.reconnect.set_active(profile.auto_reconnect)
        self.protocol.set_text(profile.protocol)
        self._loading = False

    def _address_changed(self) -> None:
        """A profile named after its address ("127.0.0.1:7391", as RTMU names one) follows the user, host
        and port typed; a name the operator chose stays."""
        now = address_name(self.host.get_text(), self.port.get_text(), self.user.get_text())
        if not self._loading and self.profile_entry.get_text() == self._address_name:
            self._loading = True  # the new name is no pick of another profile
            self.profile_entry.set_text(now)
            self._loading = False
        self._address_name = now

    def _profile_changed(self, combo: Gtk.ComboBoxText) -> None:
        name = combo.get_active_id()
        if name and name in self._profiles and not self._loading:
            self._load(self._profiles[name])
        self.check()

    def form(self) -> dict[str, str]:
        return {
            "name": self.profile_entry.get_text(),
            "host": self.host.get_text(),
            "port": self.port.get_text(),
            "user": self.user.get_text(),
        }

    def check(self) -> dict[str, str]:
        """Validate, show inline messages, enable Save only when valid; returns the errors."""
        f = self.form()
        errors = validate(f["name"], f["host"], f["port"], f["user"], self.remember.get_active())
        for key, label in self.errors.items():
            text = errors.get(key, "")
            label.set_text(text)
            label.set_visible(bool(text))
        for key, widget in (("name", self.profile_entry), ("host", self.host), ("port", self.port)):
            if key in errors:
                widget.add_css_class("error")
            else:
                widget.remove_css_class("error")
        self.save.set_sensitive(not errors)
        return errors

    def _save(self, _b: Gtk.Button | None = None) -> None:
        if self.check():
            return
        f = self.form()
        name = f["name"].strip()
        base = self._profiles.get(name, self._base)
        profile = replace(
            base,
            name=name,
            host=f["host"].strip(),
            port=int(f["port"].strip()),
            user=f["user"].strip(),
            remember_password=self.remember.get_active(),
            auto_reconnect=self.reconnect.get_active(),
            protocol=self.protocol.get_text().strip(),
        )
        password = self.password.get_text()
        self._on_save(profile, password or None)
        self.close()


class PasswordPrompt(Gtk.Window):
    """Asks for a profile's password at connect time; ``answer(None)`` when cancelled."""

    def __init__(self, parent: Gtk.Window, profile: Profile, answer: Callable[[str | None], None]) -> None:
        super().__init__(title=_("Password"), modal=True, transient_for=parent)
        self.set_resizable(False)
        self._answer: Callable[[str | None], None] | None = answer
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=10)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(16)
        prompt = Gtk.Label(xalign=0.0, wrap=True, max_width_chars=40)
        prompt.set_text(
            _("Password for {user} on {host}:{port}").format(
                user=profile.user, host=profile.host, port=profile.port
            )
        )
        box.append(prompt)
        self.entry = Gtk.PasswordEntry(show_peek_icon=True)
        self.entry.set_property("activates-default", True)
        box.append(self.entry)
        buttons = Gtk.Box(spacing=8, halign=Gtk.Align.END)
        cancel = accessible.mnemonic_button(_("_Cancel"))
        cancel.connect("clicked", lambda _b: self.close())
        ok = accessible.mnemonic_button(_("C_onnect"))
        ok.add_css_class("suggested-action")
        ok.connect("clicked", self._ok)
        buttons.append(cancel)
        buttons.append(ok)
        box.append(buttons)
        self.set_child(box)
        self.set_default_widget(ok)
        self.connect("close-request", self._closing)

    def _ok(self, _b: Gtk.Button) -> None:
        answer, self._answer = self._answer, None
        self.close()
        if answer is not None:
            answer(self.entry.get_text())

    def _closing(self, _w: Gtk.Window) -> bool:
        answer, self._answer = self._answer, None
        if answer is not None:
            answer(None)
        return False
