"""Configuration care on the configuration page: factory values, reset to default, export and import.

Three buttons on the page's bar (:class:`ConfigCare`). "Changed from default…" opens
:class:`DefaultsWindow`: every parameter whose value is not its factory value (``getConfigDefaults``,
compared as :func:`rtmu.client.config_care.differences` compares them for ``rtmu config --defaults``),
each with "Reset to default", and each section with "Reset section"; a reset goes as one
``ResetConfig`` intent (``setConfigParam`` for one parameter where offered) and the view is read
again. A server that keeps no factory values greys the button with the reason.

"Export…" writes the configuration as ``rtmu config --export`` does (:mod:`rtmu.client.config_file`),
never leaving half a file; a file already there is replaced only once the operator said Replace (GTK
4's save chooser always asks; :meth:`ConfigCare.export_to` asks itself when called without it).
"Import…" reads such a file, checks all of it against the server's own description first (nothing is
sent when one value is wrong: every problem is listed), asks with the count, then sends it in ONE
``setConfig``.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable, Collection
from pathlib import Path
from typing import Any

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _, error_words, ngettext  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..client.config_care import DEFAULTS, Difference, FactoryValues, differences, same_value  # noqa: E402
from ..client.config_feed import ServerConfig  # noqa: E402
from ..client.config_file import ConfigFileError, export_text, plan_import, read_file, write_export  # noqa: E402
from ..protocol.payloads.config import ConfigParam  # noqa: E402
from ..values.intents import FetchConfig, FetchConfigDefaults, Intent, ResetConfig, SetConfig  # noqa: E402
from . import accessible  # noqa: E402
from .confirm import Confirm  # noqa: E402
from .state_words import failure_words  # noqa: E402

Request = Callable[[Intent], "concurrent.futures.Future[Any]"]
NO_DEFAULTS = N_(
    "this server keeps no factory values (getConfigDefaults: ARIA offers it only when started with a "
    "defaults file)"
)


def _values(count: int) -> str:
    return ngettext("{count} value", "{count} values", count).format(count=count)


def _margins(box: Gtk.Widget, px: int) -> None:
    for side in ("top", "bottom", "start", "end"):
        getattr(box, f"set_margin_{side}")(px)


def _when_done(
    future: concurrent.futures.Future[Any], then: Callable[[Any, BaseException | None], None]
) -> None:
    """``then(result, error)`` on the UI thread once ``future`` is done."""

    def idle() -> bool:
        error = future.exception() if not future.cancelled() else concurrent.futures.CancelledError()
        then(None if error is not None else future.result(), error)
        return False

    future.add_done_callback(lambda _f: GLib.idle_add(idle))


class DefaultsWindow(Gtk.Window):
    """What differs from the factory values, with a reset per parameter and per section."""

    def __init__(self, parent: Gtk.Window, request: Request, changed: Callable[[], None]) -> None:
        super().__init__(title=_("Changed from default"), transient_for=parent, destroy_with_parent=True)
        self.set_default_size(620, 380)
        self._request, self._changed = request, changed
        self.differences: list[Difference] = []
        self.loads = 0
        """Views filled (tests wait for the next one)."""
        self.reset_buttons: dict[tuple[str, str], Gtk.Button] = {}
        self.section_buttons: dict[str, Gtk.Button] = {}
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        _margins(box, 8)
        self.status = Gtk.Label(label=_("Loading…"), xalign=0.0, wrap=True)
        box.append(self.status)
        self.grid = Gtk.Grid(column_spacing=12, row_spacing=6)
        scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_child(self.grid)
        box.append(scroller)
        self.set_child(box)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.load()

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        return False

    def load(self) -> None:
        """Read the configuration and the factory values again, and show what differs."""
        config_future = self._request(FetchConfig())
        factory_future = self._request(FetchConfigDefaults())

        def both(_r: Any, _e: BaseException | None) -> None:
            if config_future.done() and factory_future.done():
                self._loaded(config_future, factory_future)

        _when_done(config_future, both)
        _when_done(factory_future, both)

    def _loaded(
        self, config_f: concurrent.futures.Future[Any], factory_f: concurrent.futures.Future[Any]
    ) -> None:
        if not self.get_visible() and self.loads:
            return
        for f in (config_f, factory_f):
            error = f.exception() if not f.cancelled() else concurrent.futures.CancelledError()
            if error is not None:
                self.status.set_text(
                    _("Could not compare with the factory values: {error}").format(error=failure_words(error))
                )
                self.status.add_css_class("error")
                return
        config: ServerConfig = config_f.result()
        factory: FactoryValues = factory_f.result()
        self.differences = differences(config, factory)
        self._fill(len(factory.values))
        self.loads += 1

    def _fill(self, known: int) -> None:
        while (child := self.grid.get_first_child()) is not None:
            self.grid.remove(child)
        self.reset_buttons, self.section_buttons = {}, {}
        self.status.remove_css_class("error")
        if not self.differences:
            self.status.set_text(
                _("Every parameter has its factory value ({known} known).").format(known=known)
            )
            return
        n = len(self.differences)
        self.status.set_text(
            ngettext(
                "{n} parameter differs from its factory value.",
                "{n} parameters differ from their factory values.",
                n,
            ).format(n=n)
        )
        row = 0
        for section in dict.fromkeys(d.section for d in self.differences):
            heading = Gtk.Label(label=visible(section), xalign=0.0, hexpand=True)
            heading.add_css_class("heading")
            self.grid.attach(heading, 0, row, 3, 1)
            mine = [d for d in self.differences if d.section == section]
            whole = Gtk.Button(label=_("Reset section"))
            whole.set_sensitive(any(d.editable for d in mine))
            whole.connect("clicked", lambda _b, m=mine: self._reset(m))
            self.grid.attach(whole, 3, row, 1, 1)
            self.section_buttons[section] = whole
            row += 1
            for d in mine:
                end = Pango.EllipsizeMode.END
                self.grid.attach(Gtk.Label(label=visible(d.name), xalign=0.0, ellipsize=end), 0, row, 1, 1)
                self.grid.attach(
                    Gtk.Label(
                        label=_("now {visible}").format(visible=visible(d.value)), xalign=0.0, ellipsize=end
                    ),
                    1,
                    row,
                    1,
                    1,
                )
                self.grid.attach(
                    Gtk.Label(
                        label=_("factory {visible}").format(visible=visible(d.default)),
                        xalign=0.0,
                        ellipsize=end,
                    ),
                    2,
                    row,
                    1,
                    1,
                )
                button = Gtk.Button(label=_("Reset to default"))
                if not d.editable:
                    button.set_sensitive(False)
                    button.set_tooltip_text(_("Read-only: above the priority this server lets you edit"))
                button.connect("clicked", lambda _b, one=d: self._reset([one]))
                self.grid.attach(button, 3, row, 1, 1)
                self.reset_buttons[(d.section, d.name)] = button
                row += 1

    def _reset(self, which: list[Difference]) -> None:
        changes: dict[str, dict[str, str]] = {}
        for d in which:
            if d.editable:
                changes.setdefault(d.section, {})[d.name] = d.default
        if not changes:
            return
        names = ", ".join(f"{s}/{n}" for s, params in changes.items() for n in params)
        self.status.set_text(_("Resetting {names}…").format(names=names))

        def answered(reply: Any, error: BaseException | None) -> None:
            if error is None and reply is not None and not reply.accepted:
                error = RuntimeError(reply.error)
            if error is not None:
                self.status.set_text(
                    _("The server did not reset {names}: {error}").format(
                        names=names, error=failure_words(error)
                    )
                )
                self.status.add_css_class("error")
                return
            self._changed()
            self.load()

        _when_done(self._request(ResetConfig(changes)), answered)


class ConfigCare:
    """The page's factory-value, export and import buttons (see the module notes)."""

    def __init__(
        self,
        page: Gtk.Window,
        request: Request,
        offers: Callable[[], Collection[str]],
        say: Callable[[str, bool], None],
    ) -> None:
        self.page, self._request, self._offers, self._say = page, request, offers, say
        self.buttons = Gtk.Box(spacing=6)
        self.defaults_button = Gtk.Button(label=_("Changed from default…"))
        self.defaults_button.connect("clicked", lambda _b: self.show_defaults())
        self.export_button = Gtk.Button(label=_("Export…"))
        self.export_button.connect("clicked", lambda _b: self._choose(export=True))
        self.import_button = Gtk.Button(label=_("Import…"))
        self.import_button.connect("clicked", lambda _b: self._choose(export=False))
        for b in (self.defaults_button, self.export_button, self.import_button):
            self.buttons.append(b)
        self.defaults: DefaultsWindow | None = None
        self.factory: FactoryValues | None = None
        """The factory values, read once the page has the configuration (where the server keeps them)."""
        self.resets: dict[tuple[str, str], Gtk.Button] = {}
        """The page's per-row reset buttons made last, by (section, parameter)."""
        self._reading = False
        self.chooser: Gtk.FileChooserDialog | None = None
        self.confirm: Confirm | None = None
        self.update()

    def update(self) -> None:
        """Grey what the server does not offer (called when the configuration is read); the factory
        values are read once, so each changed parameter on the page gets its own reset button."""
        offered = DEFAULTS in self._offers()
        self.defaults_button.set_sensitive(offered)
        if offered:
            self.defaults_button.set_has_tooltip(False)
        else:
            self.defaults_button.set_tooltip_text(_(NO_DEFAULTS))
        if offered and self.factory is None and not self._reading:
            self._reading = True

            def read(values: Any, error: BaseException | None) -> None:
                self._reading = False
                if error is None:
                    self.factory = values
                    show_rows = getattr(self.page, "show_rows", None)
                    if callable(show_rows):
                        show_rows()  # the rows gain their reset buttons (no second fetch)

            _when_done(self._request(FetchConfigDefaults()), read)

    def reset_button(self, section: str, param: ConfigParam, editable: bool) -> Gtk.Widget | None:
        """ "Reset to default" for one row of the page, when its value is not the factory value."""
        default = self.factory.get(section, param.name) if self.factory is not None else None
        if default is None or same_value(param, default):
            return None
        button = Gtk.Button(icon_name="edit-undo-symbolic", valign=Gtk.Align.CENTER)
        accessible.name(button, _("Reset to default"))
        button.set_tooltip_text(_("Reset to default ({visible})").format(visible=visible(default)))
        button.set_sensitive(editable)

        def answered(reply: Any, error: BaseException | None) -> None:
            if error is None and reply is not None and not reply.accepted:
                error = RuntimeError(reply.error)
            if error is not None:
                self._say(
                    _("{section}/{name} was not reset: {error}").format(
                        section=section, name=param.name, error=failure_words(error)
                    ),
                    True,
                )
            else:
                self._say(
                    _("{section}/{name} is back to its factory value {default}").format(
                        section=section, name=param.name, default=default
                    ),
                    False,
                )
            self._refresh_page()

        changes = {section: {param.name: default}}
        button.connect("clicked", lambda _b: _when_done(self._request(ResetConfig(changes)), answered))
        self.resets[(section, param.name)] = button
        return button

    def _config(self) -> ServerConfig | None:
        return getattr(self.page, "config", None)

    def show_defaults(self) -> None:
        if self.defaults is None or not self.defaults.get_visible():
            self.defaults = DefaultsWindow(self.page, self._request, lambda: self._refresh_page())
        self.defaults.present()

    def _refresh_page(self) -> None:
        refresh = getattr(self.page, "refresh", None)
        if callable(refresh):
            refresh()

    # -- files ------------------------------------------------------------------------------------
    def _choose(self, *, export: bool) -> None:
        if self._config() is None:
            self._say(_("Wait for the configuration to load first"), True)
            return
        action = Gtk.FileChooserAction.SAVE if export else Gtk.FileChooserAction.OPEN
        title = _("Export the configuration") if export else _("Import a configuration")
        chooser = Gtk.FileChooserDialog(title=title, transient_for=self.page, modal=True, action=action)
        chooser.add_button(_("Cancel"), Gtk.ResponseType.CANCEL)
        chooser.add_button(_("Export") if export else _("Import"), Gtk.ResponseType.ACCEPT)
        if export:
            chooser.set_current_name("robot-config.toml")
        chooser.connect("response", lambda c, r: self._chosen(c, r, export))
        self.chooser = chooser
        chooser.present()

    def _chosen(self, chooser: Gtk.FileChooserDialog, response: int, export: bool) -> None:
        chosen = chooser.get_file() if response == Gtk.ResponseType.ACCEPT else None
        chooser.destroy()
        self.chooser = None
        path = chosen.get_path() if chosen is not None else None
        if path and export:
            self.export_to(Path(path), replace_asked=True)  # GTK 4's save chooser asks before replacing
        elif path:
            self.import_from(Path(path))

    def export_to(self, path: Path, *, replace_asked: bool = False) -> None:
        """Write the configuration to ``path``, asking first when a file is already there (unless the
        operator has already said Replace, as GTK 4's save chooser always asks)."""
        if (path.exists() or path.is_symlink()) and not replace_asked:
            self.confirm = Confirm(
                self.page,
                _("“{name}” already exists in {parent}. Replace it?").format(
                    name=path.name, parent=path.parent
                ),
                _("Replace"),
                lambda: self._write(path, force=True),
            )
            self.confirm.present()
            return
        self._write(path, force=replace_asked)

    def _write(self, path: Path, *, force: bool) -> None:
        config = self._config()
        if config is None:
            return
        try:
            write_export(path, export_text(config), force=force)
        except ConfigFileError as exc:
            self._say(_("Not exported: {exc}").format(exc=error_words(exc)), True)
            return
        self._say(
            _("Exported {param_count} parameters to {path}").format(
                param_count=config.param_count, path=path
            ),
            False,
        )

    def import_from(self, path: Path) -> None:
        """Check ``path`` against the server's configuration; ask, then send it in one ``setConfig``."""
        config = self._config()
        if config is None:
            return
        try:
            plan = plan_import(config, read_file(path))
        except ConfigFileError as exc:
            self._say(_("Not imported: {exc}").format(exc=error_words(exc)), True)
            return
        if plan.problems:
            shown = "; ".join(plan.problems[:5]) + (
                _(" (and {value} more)").format(value=len(plan.problems) - 5)
                if len(plan.problems) > 5
                else ""
            )
            self._say(_("Not imported, nothing was sent: {shown}").format(shown=shown), True)
            return
        count = sum(len(v) for v in plan.changes.values())
        if not count:
            self._say(
                _("Nothing to import: the robot already holds every value in {name}").format(name=path.name),
                False,
            )
            return
        send = lambda: self._send(plan.changes, path)  # noqa: E731
        self.confirm = Confirm(
            self.page,
            _("Import {values} from “{name}”?").format(values=_values(count), name=path.name),
            _("Import"),
            send,
            detail=_("{unchanged} more are already as the file says. The server takes all or none.").format(
                unchanged=plan.unchanged
            ),
            destructive=False,
        )
        self.confirm.present()

    def _send(self, changes: dict[str, dict[str, str]], path: Path) -> None:
        def answered(reply: Any, error: BaseException | None) -> None:
            if error is None and reply is not None and not reply.accepted:
                error = RuntimeError(reply.error)
            if error is not None:
                self._say(
                    _("The server refused the import of {name}: {error}").format(
                        name=path.name, error=failure_words(error)
                    ),
                    True,
                )
            else:
                count = sum(len(v) for v in changes.values())
                self._say(
                    _("Imported {values} from {name}").format(values=_values(count), name=path.name), False
                )
            self._refresh_page()

        _when_done(self._request(SetConfig(changes)), answered)
