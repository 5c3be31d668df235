"""The server's configuration page: sections, editors fit to each type, one Save, the server's answers.

A window of its own (menu: Server ▸ Configuration…), so typing in it never reaches the main
window's drive keys. Everything it shows comes from the server and is set as plain text, never as
markup; a name (section, parameter) is one line, its control characters shown escaped (a CR in a
section's name is ``\r``, not a line break). A section shows :data:`PAGE_SIZE` parameters at a
time, so a configuration of tens of thousands of parameters costs a page of widgets, not one per
parameter.

What the operator typed and what the server answered live in a GTK-free
:class:`~rtmu.ui.config_edits.ConfigEdits` (kept across sections, pages, the priority filter and
refreshes); this window shows it. When another client changes the configuration (``configUpdated``)
the page fetches it again, updates what the operator has not touched and says what changed — and
which of the operator's own unsaved edits the other client changed under them. Closing it (Escape,
the title bar) with unsaved edits asks first (``ui.discard_question``). Requests go as
intents (``FetchConfig``, ``SetConfig``) through the window's ``request``: the selected robot's.
A robot whose configuration RTMU cannot edit yet (an Omron LD robot's ``getConfigValues``) gets the
plain sentence of which API it has, and a button to read it raw in the console (``console_page``).
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import math
from collections.abc import Callable, Collection
from typing import Any

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _, error_words  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..client.config_feed import MAX_TEXT, ConfigSection, ForeignConfig, ServerConfig  # noqa: E402
from ..protocol.payloads.config import ConfigParam, ParamType, Priority, SetConfigReply  # noqa: E402
from ..values.intents import FetchConfig, Intent  # noqa: E402
from . import accessible  # noqa: E402
from .config_care_view import ConfigCare  # noqa: E402
from .config_edits import ConfigEdits, Key  # noqa: E402
from .discard_question import DiscardQuestion  # noqa: E402
from .state_words import failure_words  # noqa: E402

Request = Callable[[Intent], "concurrent.futures.Future[Any]"]
"""The window's ``request``: an intent to the selected robot, its answer as a Future."""
Follow = Callable[[Callable[[], None] | None], None]

PAGE_SIZE = 60
"""Parameters shown at once (a section with more gets Previous / Next)."""
MAX_SECTIONS_LISTED = 1000
SPIN_LIMIT = 1e12
"""Unlimited numbers (ARIA's INT_MIN/INT_MAX, ±INF) are edited within ± this."""
PRIORITY_LABELS = (N_("Basic"), N_("Intermediate"), N_("Advanced"), N_("Expert"), N_("Factory"))


class ConfigPage(Gtk.Window):
    """See the module notes. ``request(intent)`` returns a Future completed on the network thread;
    ``follow(listener)`` has the page hear another client's changes (None: no longer)."""

    def __init__(
        self,
        parent: Gtk.Window | None,
        request: Request,
        follow: Follow,
        offers: Callable[[], Collection[str]] = frozenset,
        open_console: Callable[[str], None] | None = None,
    ) -> None:
        super().__init__(
            title=_("Server configuration"), transient_for=parent, modal=False, destroy_with_parent=True
        )
        self.set_default_size(760, 440)
        self._request, self._follow, self._offers = request, follow, offers
        self._open_console = open_console
        """Opens the console filtered to a text (a configuration RTMU cannot edit is read there)."""
        self.state = ConfigEdits()
        """What the operator typed and what the server said (GTK-free)."""
        self.section = 0
        self.page = 0
        self.show_up_to = int(Priority.EXPERT)
        self.rows: dict[Key, tuple[ConfigParam, Gtk.Widget, Gtk.Label]] = {}
        """The parameters on screen now: their description, editor and answer label."""
        self.fetching = False
        self._again = ""
        self.saving = False
        self.closed = False
        self._discarding = False
        self._build()
        self._follow(self.remote_changed)
        self.connect("close-request", self._closing)
        self.refresh()

    @property
    def config(self) -> ServerConfig | None:
        return self.state.config

    @property
    def edits(self) -> dict[Key, str]:
        return self.state.edits

    @property
    def fetches(self) -> int:
        return self.state.fetches

    # -- layout -----------------------------------------------------------------------------------
    def _build(self) -> None:
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(8)
        bar = Gtk.Box(spacing=8)
        bar.append(Gtk.Label(label=_("Show up to")))
        self.priority = Gtk.DropDown.new_from_strings([_(p) for p in PRIORITY_LABELS])
        accessible.name(self.priority, _("Show up to"))
        self.priority.set_selected(self.show_up_to)
        self.priority.connect("notify::selected", self._priority_chosen)
        bar.append(self.priority)
        self.status = Gtk.Label(
            label=_("Loading…"), xalign=0.0, hexpand=True, ellipsize=Pango.EllipsizeMode.END
        )
        bar.append(self.status)
        self.reload_button = Gtk.Button(label=_("Reload"))
        self.reload_button.connect("clicked", lambda _b: self.refresh())
        bar.append(self.reload_button)
        self.save_button = Gtk.Button(label=_("Save"))
        self.save_button.add_css_class("suggested-action")
        self.save_button.set_sensitive(False)
        self.save_button.connect("clicked", lambda _b: self.save())
        bar.append(self.save_button)
        box.append(bar)
        self.care = ConfigCare(self, self._request, self._offers, self._tell)
        """Factory values, reset to default, export and import (``config_care_view``)."""
        care_bar = Gtk.Box(spacing=8, halign=Gtk.Align.END)
        care_bar.append(self.care.buttons)
        box.append(care_bar)
        self.banner = Gtk.Label(xalign=0.0, wrap=True)
        self.banner.add_css_class("config-banner")
        self.banner.set_visible(False)
        box.append(self.banner)
        self.discard = DiscardQuestion(self._discard_and_close)
        box.append(self.discard)
        self.console_button = Gtk.Button(
            label=_("Read it in the console…"), halign=Gtk.Align.START, visible=False
        )
        self.console_button.connect("clicked", lambda _b: self._console())
        box.append(self.console_button)
        paned = Gtk.Paned(orientation=Gtk.Orientation.HORIZONTAL, vexpand=True)
        self.sections = Gtk.ListBox()
        self.sections.connect("row-selected", self._section_chosen)
        left = Gtk.ScrolledWindow(hscrollbar_policy=Gtk.PolicyType.NEVER)
        left.set_child(self.sections)
        left.set_size_request(170, -1)
        paned.set_start_child(left)
        paned.set_shrink_start_child(False)
        right = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=4)
        self.comment = Gtk.Label(xalign=0.0, wrap=True)
        self.comment.add_css_class("dim-label")
        right.append(self.comment)
        self.grid = Gtk.Grid(column_spacing=12, row_spacing=6)
        self.scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        self.scroller.set_child(self.grid)
        right.append(self.scroller)
        pager = Gtk.Box(spacing=8)
        self.prev_button = Gtk.Button(label=_("Previous"))
        self.prev_button.connect("clicked", lambda _b: self._turn(-1))
        self.next_button = Gtk.Button(label=_("Next"))
        self.next_button.connect("clicked", lambda _b: self._turn(1))
        self.page_label = Gtk.Label(hexpand=True)
        pager.append(self.prev_button)
        pager.append(self.page_label)
        pager.append(self.next_button)
        right.append(pager)
        paned.set_end_child(right)
        box.append(paned)
        self.set_child(box)
        keys = Gtk.EventControllerKey()
        keys.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)  # Escape closes, even from an editor
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)

    def _tell(self, text: str, error: bool) -> None:
        """A line under the bar: an export or import done, or why not (red)."""
        self.banner.set_text(text)
        (self.banner.add_css_class if error else self.banner.remove_css_class)("error")
        self.banner.set_visible(True)

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            if self.discard.asking:  # Escape answers the question the safe way: keep editing
                self.discard.dismiss()
            else:
                self.close()
            return True
        return False  # every other key stays in this window: it never reaches the drive keys

    def _closing(self, _w: Gtk.Window) -> bool:
        focus = self.get_focus()
        spin = focus.get_ancestor(Gtk.SpinButton) if focus is not None else None
        if isinstance(spin, Gtk.SpinButton):
            spin.update()  # what it holds now decides whether there is an edit to lose
        if self.state.edits and not self._discarding:  # never lose an edit without asking
            self.discard.ask(len(self.state.edits))
            return True
        self.closed = True
        self._follow(None)
        return False

    def _discard_and_close(self) -> None:
        self._discarding = True
        self.close()

    def _console(self) -> None:
        """The console, filtered to the robot's configuration data (read raw: the layouts are not public)."""
        if self._open_console is not None:
            self._open_console("config")

    # -- fetching ---------------------------------------------------------------------------------
    def refresh(self, note: str = "") -> None:
        """Ask the server for the whole configuration; unsaved edits are kept. One fetch at a time:
        asked again meanwhile, it fetches once more when the answer is in."""
        if self.fetching:
            self._again = self._again or note or "again"
            return
        self.fetching = True
        self.status.set_text(_("Loading…"))
        self.reload_button.set_sensitive(False)
        previous = self.config
        self._request(FetchConfig()).add_done_callback(
            lambda f: GLib.idle_add(self._fetched, f, previous, note)
        )

    def _refresh_later(self, note: str) -> bool:
        if not self.closed:
            self.refresh(note)
        return False

    def _fetched(
        self, future: concurrent.futures.Future[Any], previous: ServerConfig | None, note: str
    ) -> bool:
        self.fetching = False
        if self.closed:
            return False
        self.reload_button.set_sensitive(True)
        if self._again:
            again, self._again = self._again, ""
            GLib.idle_add(self._refresh_later, "remote" if again == "remote" else "")
        error = None if future.cancelled() else future.exception()
        if isinstance(error, ForeignConfig):  # an answer, not a failure: its whole sentence, wrapped
            self.status.set_text(_("No configuration RTMU can edit"))
            where = _(". In this window, Server ▸ Console… reads it raw.") if self._open_console else ""
            self.banner.set_text(f"{error_words(error).rstrip('.')}{where}")
            self.banner.set_visible(True)
            self.console_button.set_visible(self._open_console is not None)
            return False
        if future.cancelled() or error is not None:
            self.status.set_text(
                _("Could not load the configuration: {value}").format(value=failure_words(error))
            )
            return False
        config: ServerConfig = future.result()
        self.care.update()
        self.state.fetched(config)  # another client set what was being typed: nothing to save
        if previous is not None and note:
            self.banner.set_text(self.state.changes_note(previous, config))
            self.banner.set_visible(True)
        if self.fetches == 1:
            self.show_up_to = int(Priority.of(config.last_editable))
            self.priority.set_selected(self.show_up_to)
        self._fill_sections()
        self._update_status()
        return False

    def remote_changed(self) -> None:
        """``configUpdated`` (UI thread): fetch again and say what changed."""
        if not self.closed:
            self.refresh(note="remote")

    # -- sections and rows ------------------------------------------------------------------------
    def _fill_sections(self) -> None:
        config = self.config
        assert config is not None
        keep = self.section
        while (row := self.sections.get_row_at_index(0)) is not None:
            self.sections.remove(row)
        for s in config.sections[:MAX_SECTIONS_LISTED]:
            label = Gtk.Label(label=visible(s.name), xalign=0.0, ellipsize=Pango.EllipsizeMode.END)
            label.set_tooltip_text(s.comment or None)
            self.sections.append(label)
        count = min(len(config.sections), MAX_SECTIONS_LISTED)
        if count:
            self.section = min(keep, count - 1)
            self.sections.select_row(self.sections.get_row_at_index(self.section))
        self._show_section()

    def _section_chosen(self, _box: Gtk.ListBox, row: Gtk.ListBoxRow | None) -> None:
        if row is not None and row.get_index() != self.section:
            self.section, self.page = row.get_index(), 0
            self._show_section()

    def _priority_chosen(self, *_a: object) -> None:
        self.show_up_to = int(self.priority.get_selected())
        self.page = 0
        if self.config is not None:
            self._show_section()

    def _turn(self, step: int) -> None:
        self.page = max(0, self.page + step)
        self._show_section()

    def current(self) -> ConfigSection | None:
        config = self.config
        if config is None or not config.sections:
            return None
        return config.sections[min(self.section, len(config.sections) - 1)]

    def shown_params(self) -> list[ConfigParam]:
        """The current section's parameters the priority filter lets through (separators included)."""
        s = self.current()
        return [] if s is None else [p for p in s.params if p.priority <= self.show_up_to]

    def show_rows(self) -> None:
        """Draw the current section's rows again (the factory values arrived: reset buttons)."""
        if self.config is not None and not self.closed:
            self._show_section()

    def _show_section(self) -> None:
        section = self.current()
        while (child := self.grid.get_first_child()) is not None:
            self.grid.remove(child)
        self.rows = {}
        if section is None:
            self.comment.set_text(_("This server's configuration is empty."))
            return
        self.comment.set_text(section.comment)
        params = self.shown_params()
        pages = max(1, math.ceil(len(params) / PAGE_SIZE))
        self.page = min(self.page, pages - 1)
        first = self.page * PAGE_SIZE
        for i, p in enumerate(params[first : first + PAGE_SIZE]):
            self._add_row(section, p, i)
        hidden = len(section.params) - len(params)
        info = (
            _("{value}–{min} of {len}").format(
                value=first + 1, min=min(first + PAGE_SIZE, len(params)), len=len(params)
            )
            if params
            else "nothing"
        )
        if hidden:
            info += _(" ({hidden} above {lower} hidden)").format(
                hidden=hidden, lower=_(PRIORITY_LABELS[self.show_up_to]).lower()
            )
        self.page_label.set_text(info)
        self.prev_button.set_sensitive(self.page > 0)
        self.next_button.set_sensitive(self.page < pages - 1)
        self.scroller.get_vadjustment().set_value(0)

    def _add_row(self, section: ConfigSection, p: ConfigParam, row: int) -> None:
        if p.kind is ParamType.SEPARATOR:
            self.grid.attach(Gtk.Separator(), 0, row, 3, 1)
            return
        config = self.config
        assert config is not None
        key = (section.name, p.name)
        left = Gtk.Box(orientation=Gtk.Orientation.VERTICAL)
        name = Gtk.Label(label=visible(p.name), xalign=0.0, wrap=True, max_width_chars=28)
        left.append(name)
        if p.description:
            about = Gtk.Label(label=p.description, xalign=0.0, wrap=True, max_width_chars=40)
            about.add_css_class("dim-label")
            about.add_css_class("caption")
            left.append(about)
        left.set_hexpand(True)
        self.grid.attach(left, 0, row, 1, 1)
        editor = self._editor(p, key, config.editable(p))
        accessible.name(editor, visible(p.name))  # the parameter's name from the server, as shown
        self.grid.attach(editor, 1, row, 1, 1)
        answer = Gtk.Label(xalign=0.0, wrap=True, max_width_chars=30)
        self.grid.attach(answer, 2, row, 1, 1)
        reset = self.care.reset_button(section.name, p, config.editable(p))
        if reset is not None:
            self.grid.attach(reset, 3, row, 1, 1)
        self.rows[key] = (p, editor, answer)
        self._show_answer(key)

    def _editor(self, p: ConfigParam, key: Key, editable: bool) -> Gtk.Widget:
        text = self.state.edits.get(key, p.value_text())
        widget: Gtk.Widget
        if p.kind is ParamType.BOOL:
            switch = Gtk.Switch(active=text.lower() in ("true", "1", "yes", "on"), halign=Gtk.Align.START)
            switch.connect(
                "notify::active", lambda s, _p: self._edited(key, "true" if s.get_active() else "false")
            )
            widget = switch
        elif p.kind in (ParamType.INT, ParamType.DOUBLE):
            lo = (
                -SPIN_LIMIT
                if p.minimum is None or not math.isfinite(p.minimum)
                else max(p.minimum, -SPIN_LIMIT)
            )
            hi = (
                SPIN_LIMIT
                if p.maximum is None or not math.isfinite(p.maximum)
                else min(p.maximum, SPIN_LIMIT)
            )
            digits = 0 if p.kind is ParamType.INT else (p.precision if 0 <= p.precision <= 6 else 3)
            step = 1.0 if p.kind is ParamType.INT else 10.0**-digits
            spin = Gtk.SpinButton.new_with_range(lo, max(lo, hi), step)
            spin.set_digits(digits)
            # Out of its limits, the held value comes back (and the row says what was not taken),
            # never the limit in its place without a word.
            spin.set_update_policy(Gtk.SpinButtonUpdatePolicy.IF_VALID)
            with contextlib.suppress(ValueError):
                spin.set_value(float(text))
            spin.connect("changed", lambda s: self._edited(key, s.get_text()))
            widget = spin
        elif p.kind is ParamType.STRING and p.choices:
            choices = list(p.choices) + ([text] if text not in p.choices else [])
            drop = Gtk.DropDown.new_from_strings(choices)
            drop.set_selected(choices.index(text))
            drop.connect("notify::selected", lambda d, _p: self._edited(key, choices[d.get_selected()]))
            widget = drop
        elif p.kind is ParamType.STRING:
            entry = Gtk.Entry(text=text, width_chars=16)
            entry.set_max_length(MAX_TEXT)
            entry.connect("changed", lambda e: self._edited(key, e.get_text()))
            widget = entry
        else:
            widget = Gtk.Label(
                label=_("list of {len} (read-only here)").format(len=len(p.children)), xalign=0.0
            )
        if not editable:
            widget.set_sensitive(False)
            widget.set_tooltip_text(_("Read-only: above the priority this server lets you edit"))
        widget.set_valign(Gtk.Align.CENTER)
        return widget

    # -- edits, validation, answers ---------------------------------------------------------------
    def _edited(self, key: Key, text: str) -> None:
        found = self.rows.get(key)
        if found is not None and self.state.edit(key, found[0], text):
            self._show_answer(key)
            self._update_status()

    def invalid_edits(self) -> dict[Key, str]:
        """Edits that are certainly wrong: key → why."""
        return self.state.invalid()

    def _show_answer(self, key: Key) -> None:
        found = self.rows.get(key)
        if found is None:
            return
        param, _editor, label = found
        for css in ("config-error", "config-ok", "config-edited"):
            label.remove_css_class(css)
        note = self.state.note(key, param)
        label.set_text(note.text)
        if note.style:
            label.add_css_class(f"config-{note.style}")

    def _update_status(self) -> None:
        if self.state.config is None:
            return
        self.save_button.set_sensitive(self.state.can_save(self.saving))
        self.status.set_text(self.state.status())
        if not self.state.edits:
            self.discard.dismiss()  # saved (or typed back) meanwhile: nothing left to lose

    def save(self) -> None:
        """Send every edit in one ``setConfig``; the answer is shown next to each parameter."""
        found = None if self.saving else self.state.save_intent()
        if found is None:
            return
        sent, intent = found
        self.saving = True
        self._update_status()
        self.status.set_text(_("Saving…"))
        self._request(intent).add_done_callback(lambda f: GLib.idle_add(self._saved, f, sent))

    def _saved(self, future: concurrent.futures.Future[Any], sent: dict[Key, str]) -> bool:
        if self.closed:
            return False
        self.saving = False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self.state.save_failed(sent, failure_words(error))
            for key in sent:
                self._show_answer(key)
            self._update_status()
            return False
        answer: SetConfigReply = future.result()
        whole = self.state.saved(sent, answer)
        if whole:
            self.banner.set_text(whole)
            self.banner.set_visible(True)
        self.refresh()
        return False
