"""The console page: every data the robot lists, with its descriptions, called once with typed arguments.

An LD robot lists about a thousand data and RTMU has code for about a hundred; a field engineer needs
the rest now. The page reads the server's whole data list (:class:`~rtmu.values.intents.ConsoleList`)
and shows each data's name, command group and whether a call changes something; a filter narrows it
(name, description or group). The data picked shows everything the server said about it (description,
argument and return descriptions, flags) and RTMU's reading of its argument layout. Call sends it once
(:class:`~rtmu.values.intents.ConsoleCall`) with the arguments typed in (split like a shell line; the
types as the description says, or as typed in the types field) and shows the reply as ``rtmu call``
prints it (:mod:`~rtmu.client.console_text`): how it ended, each packet's bytes, its field split, and
RTMU's own type where it has one.

Anything that is not a plain read asks first (``confirm_bar``: the reason the console saw in the
data's name or description is shown), and the network side refuses it again without that yes;
``ratioDrive`` is never the console's. Bounded for a hostile server: at most :data:`MAX_ROWS` rows
are built (the filter finds the rest), texts are shortened, a reply is at most what the model keeps
(16 packets × 200 fields) and :data:`MAX_LINES` lines. Its own window, transient for the main one:
typing here never drives, and Space still stops.

Follow asks for the data picked every N ms (:class:`~rtmu.values.intents.ConsoleFollow`, as
``rtmu call --every``) and shows each reply as it comes, with their count: the page asks for the next
batch only when it has shown one (:class:`~rtmu.values.intents.ConsoleNext`), so a fast stream never
piles up. Only a plain read can be followed; picking another data, another robot or closing the page
ends the following.
"""

from __future__ import annotations

import concurrent.futures
import shlex
import time
from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _, error_words, ngettext  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..client.console import ConsoleEntry, ConsoleReply  # noqa: E402
from ..client.console_effect import HELD_MOTION  # noqa: E402
from ..client.console_layout import describe  # noqa: E402
from ..client.console_text import effect_words, outcome_line, packet_lines, short  # noqa: E402
from ..values.intents import ConsoleCall, ConsoleFollow, ConsoleList, ConsoleNext, Intent  # noqa: E402
from . import accessible  # noqa: E402
from .confirm_bar import ConfirmBar  # noqa: E402
from .state_words import failure_words  # noqa: E402

Request = Callable[[Intent], "concurrent.futures.Future[Any]"]
MAX_ROWS = 300
"""Rows built at most; the filter reaches the others (a thousand rows make GTK slow on a tablet)."""
MAX_LINES = 4000
MAX_LINE_CHARS = 400


def matches(entry: ConsoleEntry, text: str) -> bool:
    """The filter: ``text`` in the data's name, description or command group (any case)."""
    if not text:
        return True
    d = entry.data
    needle = text.lower()
    return needle in d.name.lower() or needle in d.description.lower() or needle in d.command_group.lower()


def entry_details(entry: ConsoleEntry) -> str:
    """Everything the server said about one data, and RTMU's reading of it, as plain lines."""
    d = entry.data
    return "\n".join(
        (
            _("{visible} (number {number}, group {visible2})").format(
                visible=visible(short(d.name, 120)),
                number=d.number,
                visible2=visible(short(d.command_group, 60)),
            ),
            visible(short(d.description, 600)) or _("(no description)"),
            _("Arguments: {value}").format(value=visible(short(d.argument_description, 300)) or _("none")),
            _("  read as: {visible}").format(visible=visible(short(describe(entry.arguments), 300))),
            _("Returns: {value}").format(value=visible(short(d.return_description, 300)) or _("none")),
            _("Flags: {visible}").format(visible=visible(short(d.flags, 120))),
            _("Effect: {visible}").format(visible=visible(short(effect_words(entry), 200))),
        )
    )


def waited(reply: ConsoleReply) -> float:
    """How long the call waited, rounded (what "no reply within … s" says)."""
    return round(reply.seconds, 1)


def reply_text(reply: ConsoleReply) -> str:
    """The reply as ``rtmu call`` prints it, bounded in lines and in characters a line."""
    lines = [outcome_line(reply, waited(reply)), *packet_lines(reply)]
    if len(lines) > MAX_LINES:
        lines = [*lines[:MAX_LINES], _("… {value} more lines not shown").format(value=len(lines) - MAX_LINES)]
    return "\n".join(
        line if len(line) <= MAX_LINE_CHARS else line[: MAX_LINE_CHARS - 1] + "…" for line in lines
    )


class ConsolePage(Gtk.Window):
    """See the module notes. ``request(intent)`` returns a Future completed on the network thread."""

    def __init__(self, parent: Gtk.Window | None, request: Request) -> None:
        super().__init__(title=_("Console"), transient_for=parent, modal=False, destroy_with_parent=True)
        self.set_default_size(900, 520)
        self._request = request
        self.entries: list[ConsoleEntry] = []
        self.shown: list[ConsoleEntry] = []
        """The entries the list's rows show now (at most :data:`MAX_ROWS`)."""
        self.current: ConsoleEntry | None = None
        self._built_for: tuple[str, int] | None = None
        self._loads = 0
        self._robot = 0
        """Counts switches of robot, so a reply from the robot selected before is not shown."""
        self._stale = False
        """The list being read belongs to the robot selected before (read again when it is in)."""
        """Data lists read (the rows are rebuilt for a new one)."""
        self.loading = False
        self.calling = False
        self.closed = False
        self.replies = 0
        """Replies shown (for tests)."""
        self.following: str | None = None
        """The data followed now (its replies shown as they come), or None."""
        self.followed = 0
        """Replies of the data followed now."""
        self._build()
        self.connect("close-request", self._closing)
        self.reload()

    # -- layout -------------------------------------------------------------------------------------
    def _build(self) -> None:
        left = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        self.search = Gtk.SearchEntry(placeholder_text=_("Filter: name, description or group"))
        self.search.connect("search-changed", lambda _e: self.refilter())
        accessible.name(self.search, _("Filter the data"))
        self.count = Gtk.Label(xalign=0.0)
        self.count.add_css_class("dim-label")
        self.rows = Gtk.ListBox(selection_mode=Gtk.SelectionMode.SINGLE)
        self.rows.connect("row-selected", self._selected)
        scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_child(self.rows)
        left_parts: tuple[Gtk.Widget, ...] = (self.search, self.count, scroller)
        for widget in left_parts:
            left.append(widget)
        right = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        self.details = Gtk.Label(xalign=0.0, wrap=True, selectable=True, label=_("Pick a data on the left."))
        self.details.set_max_width_chars(70)
        args = Gtk.Box(spacing=6)
        self.arguments = Gtk.Entry(hexpand=True, placeholder_text=_("Arguments, separated by spaces"))
        self.arguments.connect("activate", lambda _e: self.call())
        accessible.name(self.arguments, _("Arguments"))
        self.types = Gtk.Entry(width_chars=14, placeholder_text=_("Types (byte4,…)"))
        accessible.name(self.types, _("Argument types"))
        self.types.set_tooltip_text(
            _("Only where the description names no types: byte, byte2, byte4, double, string")
        )
        self.call_button = Gtk.Button(label=_("Call once"), sensitive=False)
        self.call_button.add_css_class("suggested-action")
        self.call_button.connect("clicked", lambda _b: self.call())
        arg_parts: tuple[Gtk.Widget, ...] = (self.arguments, self.types, self.call_button)
        for widget in arg_parts:
            args.append(widget)
        follow = Gtk.Box(spacing=6)
        self.follow_button = Gtk.ToggleButton(label=_("Follow"), sensitive=False)
        self.follow_button.set_tooltip_text(
            _("Ask again at this interval and show each reply (plain reads only)")
        )
        self.follow_button.connect("toggled", lambda _b: self._follow_toggled())
        self.interval = Gtk.SpinButton.new_with_range(100, 60_000, 100)
        self.interval.set_value(1000)
        accessible.name(self.interval, _("Follow interval in milliseconds"))
        every = Gtk.Label(label=_("every"))
        unit = Gtk.Label(label=_("ms"))
        self.follow_status = Gtk.Label(xalign=0.0, hexpand=True)
        self.follow_status.add_css_class("dim-label")
        self.follow_status.set_ellipsize(Pango.EllipsizeMode.END)  # never widens the page
        follow_parts: tuple[Gtk.Widget, ...] = (
            self.follow_button,
            every,
            self.interval,
            unit,
            self.follow_status,
        )
        for widget in follow_parts:
            follow.append(widget)
        self.status = Gtk.Label(xalign=0.0, wrap=True)
        self.confirm = ConfirmBar()
        self.reply = Gtk.TextView(editable=False, monospace=True, wrap_mode=Gtk.WrapMode.CHAR, vexpand=True)
        accessible.name(self.reply, _("Reply"))
        reply_scroller = Gtk.ScrolledWindow(vexpand=True)
        reply_scroller.set_child(self.reply)
        right_parts: tuple[Gtk.Widget, ...] = (
            self.details, args, follow, self.status, self.confirm, reply_scroller,
        )  # fmt: skip
        for widget in right_parts:
            right.append(widget)
        paned = Gtk.Paned(orientation=Gtk.Orientation.HORIZONTAL, position=330)
        paned.set_start_child(left)
        paned.set_end_child(right)
        for side in ("start", "end", "top", "bottom"):
            getattr(paned, f"set_margin_{side}")(8)
        self.set_child(paned)

    # -- the list ------------------------------------------------------------------------------------
    def robot_switched(self) -> None:
        """Another robot is selected: forget the list, the pick and any question, and read its list."""
        self.confirm.cancel()
        self.stop_following()
        self.entries, self.shown, self.current = [], [], None
        self._built_for = None
        self.refilter()
        self.details.set_text(_("Pick a data on the left."))
        self.call_button.set_sensitive(False)
        self.reply.get_buffer().set_text("")
        self.status.set_text(_("Another robot is selected: its data list is read."))
        self._stale = self.loading  # a list on its way is the robot's before: read again when it is in
        self._robot += 1  # a reply on its way is the robot's before: not shown as this one's
        self.reload()

    def reload(self) -> None:
        """Read the server's data list again (the selected robot's, this login's)."""
        if self.loading:
            return
        self.loading = True
        self.count.set_text(_("Reading the data list…"))
        future = self._request(ConsoleList())
        future.add_done_callback(lambda f: GLib.idle_add(self._loaded, f))

    def _loaded(self, future: concurrent.futures.Future[Any]) -> bool:
        self.loading = False
        if self.closed:
            return False
        if self._stale:
            self._stale = False
            self.reload()
            return False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self.count.set_text(
                _("No data list: {visible}").format(visible=visible(short(failure_words(error), 200)))
            )
            return False
        self.entries = list(future.result())
        self._loads += 1
        self.refilter()
        return False

    def refilter(self) -> None:
        """Rebuild the rows for the filter (at most :data:`MAX_ROWS`); not again for the same filter
        and list (the search entry repeats its signal after a text set from code)."""
        text = self.search.get_text().strip()
        if self._built_for == (text, self._loads):
            return
        self._built_for = (text, self._loads)
        found = [e for e in self.entries if matches(e, text)]
        self.shown = found[:MAX_ROWS]
        while (child := self.rows.get_first_child()) is not None:  # GTK 4.8 has no remove_all
            self.rows.remove(child)
        for entry in self.shown:
            self.rows.append(self._row(entry))
        more = (
            _("; the first {MAX_ROWS} shown, narrow the filter").format(MAX_ROWS=MAX_ROWS)
            if len(found) > MAX_ROWS
            else ""
        )
        self.count.set_text(
            _("{len} of {len2} data{more}").format(len=len(found), len2=len(self.entries), more=more)
        )

    @staticmethod
    def _row(entry: ConsoleEntry) -> Gtk.Widget:
        d = entry.data
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL)
        name = Gtk.Label(xalign=0.0, label=visible(short(d.name, 80)))
        kind = _("changes something") if entry.changes else _("read")
        info = Gtk.Label(xalign=0.0, label=f"{visible(short(d.command_group, 40))} · {kind}")
        info.add_css_class("dim-label")
        box.append(name)
        box.append(info)
        return box

    def _selected(self, _list: Gtk.ListBox, row: Gtk.ListBoxRow | None) -> None:
        self.confirm.cancel()
        picked = row.get_index() if row is not None else -1
        if self.following is not None and not (
            0 <= picked < len(self.shown) and self.shown[picked].name == self.following
        ):
            self.stop_following()
        if row is None or not 0 <= row.get_index() < len(self.shown):
            self.current = None
            self.call_button.set_sensitive(False)
            self.follow_button.set_sensitive(False)
            return
        self.current = entry = self.shown[row.get_index()]
        self.details.set_text(entry_details(entry))
        held = entry.name in HELD_MOTION
        self.call_button.set_sensitive(not held)
        self.follow_button.set_sensitive(not held and not entry.changes)
        self.call_button.set_label(_("Call once…") if entry.changes else _("Call once"))
        self.status.set_text(
            _("{name} is never sent from the console: held motion comes only from a held drive").format(
                name=entry.name
            )
            if held
            else ""
        )

    def select(self, name: str) -> bool:
        """Pick the shown row of data ``name`` (True when it is shown)."""
        for index, entry in enumerate(self.shown):
            if entry.name == name:
                self.rows.select_row(self.rows.get_row_at_index(index))
                return True
        return False

    # -- calling -------------------------------------------------------------------------------------
    def call(self) -> None:
        """Call the data picked once; one that changes something asks first."""
        entry = self.current
        if entry is None or self.calling or entry.name in HELD_MOTION:
            return
        try:
            arguments = tuple(shlex.split(self.arguments.get_text()))
        except ValueError as exc:
            self.status.set_text(_("Arguments: {exc}").format(exc=error_words(exc)))
            return
        types = tuple(t.strip() for t in self.types.get_text().split(",") if t.strip())
        if not entry.changes:
            self._send(ConsoleCall(name=entry.name, arguments=arguments, types=types))
            return
        question = _(
            "{visible} changes something ({visible2}). RTMU will send it once{value}. Go ahead?"
        ).format(
            visible=visible(short(entry.name, 80)),
            visible2=visible(short(entry.why, 160)),
            value=" with " + " ".join(arguments) if arguments else "",
        )
        confirmed = ConsoleCall(name=entry.name, arguments=arguments, types=types, confirmed=True)
        self.confirm.ask(question, _("Yes, send it"), lambda: self._send(confirmed))

    def _send(self, intent: ConsoleCall) -> None:
        self.calling = True
        self.status.set_text(_("Calling {name}…").format(name=intent.name))
        future = self._request(intent)
        robot = self._robot
        future.add_done_callback(lambda f: GLib.idle_add(self._replied, f, robot))

    def _replied(self, future: concurrent.futures.Future[Any], robot: int) -> bool:
        self.calling = False
        if self.closed:
            return False
        if robot != self._robot:
            self.status.set_text(_("A reply came from the robot selected before: not shown here."))
            return False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self.status.set_text(
                _("Not sent or no reply: {visible}").format(visible=visible(short(failure_words(error), 300)))
            )
            return False
        reply: ConsoleReply = future.result()
        self.status.set_text(short(outcome_line(reply, waited(reply)), 300))
        self.reply.get_buffer().set_text(reply_text(reply))
        self.replies += 1
        return False

    # -- following -------------------------------------------------------------------------------------
    def _follow_toggled(self) -> None:
        on = self.follow_button.get_active()
        entry = self.current
        if not on:
            self.stop_following()
            return
        if self.following is not None or entry is None or entry.changes or entry.name in HELD_MOTION:
            return
        try:
            arguments = tuple(shlex.split(self.arguments.get_text()))
        except ValueError as exc:
            self.status.set_text(_("Arguments: {exc}").format(exc=error_words(exc)))
            self.follow_button.set_active(False)
            return
        types = tuple(t.strip() for t in self.types.get_text().split(",") if t.strip())
        interval = int(self.interval.get_value())
        self.following, self.followed = entry.name, 0
        self.interval.set_sensitive(False)
        self.follow_status.set_text(_("following {name} every {ms} ms…").format(name=entry.name, ms=interval))
        intent = ConsoleFollow(name=entry.name, interval_ms=interval, arguments=arguments, types=types)
        future = self._request(intent)
        robot = self._robot
        future.add_done_callback(lambda f: GLib.idle_add(self._follow_started, f, entry.name, robot))

    def _follow_started(self, future: concurrent.futures.Future[Any], name: str, robot: int) -> bool:
        if self.closed or self.following != name or robot != self._robot:
            return False
        error = None if future.cancelled() else future.exception()
        if error is not None or future.cancelled() or future.result() != name:
            why = visible(short(error_words(error) if error else _("the server did not take it"), 300))
            self.stop_following()
            self.follow_status.set_text(_("Not followed: {why}").format(why=why))
            return False
        self._ask_next(name, robot)
        return False

    def _ask_next(self, name: str, robot: int) -> None:
        future = self._request(ConsoleNext(name=name, wait=2.0))
        future.add_done_callback(lambda f: GLib.idle_add(self._follow_replies, f, name, robot))

    def _follow_replies(self, future: concurrent.futures.Future[Any], name: str, robot: int) -> bool:
        if self.closed or self.following != name or robot != self._robot:
            return False
        if future.cancelled() or future.exception() is not None:
            self.stop_following()
            return False
        batch: tuple[ConsoleReply, ...] = future.result()
        if batch:
            self.followed += len(batch)
            self.replies += len(batch)
            self.reply.get_buffer().set_text(reply_text(batch[-1]))
            self.follow_status.set_text(
                ngettext(
                    "{count} reply, at {time}", "{count} replies, the last at {time}", self.followed
                ).format(count=self.followed, time=time.strftime("%H:%M:%S"))
            )
        self._ask_next(name, robot)  # the next batch only now that this one is shown
        return False

    def stop_following(self) -> None:
        """End the following (if any): the network side unsubscribes."""
        name, self.following = self.following, None
        self.interval.set_sensitive(True)
        if self.follow_button.get_active():
            self.follow_button.set_active(False)
        if name is not None:
            self.follow_status.set_text(_("stopped following {name}").format(name=name))
            if not self.closed:
                self._request(ConsoleFollow(name=name, on=False))

    def _closing(self, *_a: object) -> bool:
        self.stop_following()
        self.closed = True
        return False
