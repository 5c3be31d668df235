"""Server popups as non-modal cards over the map: plain text, the server's buttons, never the focus.

The cards follow ``RobotModel.popups`` (:class:`rtmu.values.state.PopupsState`): the newest
:data:`MAX_CARDS` are shown over the map's right side, above the zoom buttons and clear of the
banners at the top, the newest lowest, with "+K more" above them for the rest (and for those a
flood made the client drop). STOP is in the header bar (or the full-screen bar), never under them.
Every text goes through ``Gtk.Label.set_text``: a server's ``<b>`` or ``&`` is shown as written,
never parsed. Nothing here can take the keyboard: cards, labels and buttons are not focusable, so
a drive key held while a card appears keeps driving, and Space still stops.
A burst of changes costs one rebuild per main-loop turn, and only cards that are new are built.
ARIA's ``popupCreate`` carries no timeout, so a card counts how long it has been open; the server
closes it when its own timeout ends.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..model.observables import Observable, PopupsState  # noqa: E402
from ..values.state import PopupInfo  # noqa: E402

MAX_CARDS = 3
"""Cards on screen at once; the rest are counted in the "+K more" line."""
CARD_WIDTH = 340
ICONS = {
    0: "",
    1: "dialog-information-symbolic",
    2: "dialog-warning-symbolic",
    3: "dialog-error-symbolic",
    4: "dialog-question-symbolic",
}


def plain_label(text: str, css: str, *, wrap: bool = False) -> Gtk.Label:
    label = Gtk.Label(xalign=0.0)
    label.set_use_markup(False)
    label.set_text(text)
    label.add_css_class(css)
    label.set_focusable(False)
    label.set_selectable(False)
    if wrap:
        label.set_wrap(True)
        label.set_wrap_mode(Pango.WrapMode.WORD_CHAR)
        label.set_max_width_chars(44)
        label.set_lines(3)  # three cards stay clear of the banners on an 800×480 screen
        label.set_ellipsize(Pango.EllipsizeMode.END)
    else:
        label.set_ellipsize(Pango.EllipsizeMode.END)
    return label


def age_text(seconds: float) -> str:
    s = max(0, int(seconds))
    return (
        _("open {s} s").format(s=s)
        if s < 60
        else _("open {value} min {value2:02d} s").format(value=s // 60, value2=s % 60)
    )


@dataclass
class Card:
    """One card's widgets (kept while its popup stays open)."""

    info: PopupInfo
    box: Gtk.Box
    age: Gtk.Label
    buttons: list[Gtk.Button]


class PopupStack(Gtk.Box):
    """The cards, for a ``Gtk.Overlay`` over the map. ``answer(popup_id, button)`` sends the click."""

    def __init__(
        self,
        popups: Observable[PopupsState],
        answer: Callable[[int, int], None],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        self.set_halign(Gtk.Align.END)
        self.set_valign(Gtk.Align.END)
        self.set_margin_bottom(62)  # above the zoom buttons
        self.set_margin_end(10)
        self.set_focusable(False)
        self.set_can_focus(False)
        self.set_size_request(CARD_WIDTH, -1)
        self._popups = popups
        self._answer = answer
        self._clock = clock
        self.cards: dict[int, Card] = {}
        self.more = plain_label("", "popup-more")
        self.more.set_halign(Gtk.Align.END)
        self.more.set_visible(False)
        self.append(self.more)
        self.rebuilds = 0
        """How many times the cards were rebuilt (a flood must not rebuild per popup)."""
        self._pending = 0
        self._timer = 0
        self._unobserve = popups.observe(lambda _old, _new: self._schedule())
        self._rebuild()

    def close(self) -> None:
        self._unobserve()
        for source in (self._pending, self._timer):
            if source:
                GLib.source_remove(source)
        self._pending = self._timer = 0

    # -- following the model -------------------------------------------------------------------
    def _schedule(self) -> None:
        if not self._pending:
            self._pending = GLib.idle_add(self._rebuild_idle)

    def _rebuild_idle(self) -> bool:
        self._pending = 0
        self._rebuild()
        return False

    def _rebuild(self) -> None:
        self.rebuilds += 1
        state = self._popups.value
        shown = list(state.open[-MAX_CARDS:])  # oldest first: the newest is the lowest card
        wanted = {p.popup_id for p in shown}
        for pid in [pid for pid in self.cards if pid not in wanted]:
            self.remove(self.cards.pop(pid).box)
        hidden = len(state.open) - len(shown) + state.dropped
        self.more.set_text(_("+{hidden} more").format(hidden=hidden))
        self.more.set_visible(hidden > 0)
        self.reorder_child_after(self.more, None)
        previous: Gtk.Widget | None = self.more
        for info in shown:
            card = self.cards.get(info.popup_id)
            if card is None or card.info != info:
                if card is not None:
                    self.remove(card.box)
                card = self.cards[info.popup_id] = self._card(info)
                self.insert_child_after(card.box, previous)
            else:
                self.reorder_child_after(card.box, previous)
            previous = card.box
        self.set_visible(bool(shown) or hidden > 0)
        self._tick()
        if self.cards and not self._timer:
            self._timer = GLib.timeout_add(1000, self._tick_timer)

    def _tick_timer(self) -> bool:
        if not self.cards:
            self._timer = 0
            return False
        self._tick()
        return True

    def _tick(self) -> None:
        now = self._clock()
        for card in self.cards.values():
            card.age.set_text(age_text(now - card.info.opened_at))

    # -- one card ------------------------------------------------------------------------------
    def _card(self, info: PopupInfo) -> Card:
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=4)
        box.add_css_class("popup-card")
        if info.icon in (2, 3):
            box.add_css_class("warning" if info.icon == 2 else "critical")
        box.set_focusable(False)
        box.set_size_request(CARD_WIDTH, -1)
        head = Gtk.Box(spacing=6)
        icon = ICONS.get(info.icon, "")
        if icon:
            head.append(Gtk.Image(icon_name=icon))
        title = plain_label(info.title, "popup-title")
        title.set_hexpand(True)
        head.append(title)
        age = plain_label("", "popup-age")
        head.append(age)
        box.append(head)
        if info.message:
            box.append(plain_label(info.message, "popup-message", wrap=True))
        row = Gtk.Box(spacing=6, halign=Gtk.Align.END)
        buttons: list[Gtk.Button] = []
        for number, text in enumerate(info.buttons):
            if not text:
                continue
            button = Gtk.Button()
            button.set_child(plain_label(text, "popup-button-label"))
            button.set_focusable(False)
            button.set_focus_on_click(False)
            if number == info.default_button:
                button.add_css_class("suggested-action")
            button.connect("clicked", self._clicked, info.popup_id, number)
            row.append(button)
            buttons.append(button)
        if buttons:
            box.append(row)
        return Card(info, box, age, buttons)

    def _clicked(self, _button: Gtk.Button, popup_id: int, number: int) -> None:
        card = self.cards.get(popup_id)
        if card is not None:
            for b in card.buttons:  # answered: the server's popupClose takes the card away
                b.set_sensitive(False)
        self._answer(popup_id, number)

    # -- for tests and the window --------------------------------------------------------------
    def shown_ids(self) -> list[int]:
        return [pid for pid in self.cards]

    def widget_count(self) -> int:
        """Widgets under the stack: bounded by MAX_CARDS whatever the server sends."""
        count, stack = 0, [self.get_first_child()]
        while stack:
            w = stack.pop()
            while w is not None:
                count += 1
                stack.append(w.get_first_child())
                w = w.get_next_sibling()
        return count
