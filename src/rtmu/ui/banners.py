"""Non-modal banners over the stage: one per topic, updated in place, gone after a timeout.

A topic ("link", "speed", "camera" …) owns at most one banner: a new message
on the same topic replaces the text of the banner already shown instead of
stacking a second one, which is how a lost link shows ONE banner counting its
reconnect attempts. Text is always set with ``Gtk.Label.set_text`` (plain text:
strings from the server are never parsed as markup).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from . import accessible  # noqa: E402

MAX_BANNERS = 4
MARGIN_TOP = 8
"""Pixels between the top of the pages and the first banner (more under the navigation pill)."""
MIN_BESIDE = 300
"""The least width (px) that banners beside a motion pill get; with less they go under it."""
GAP = 8
"""Pixels between a motion pill and the banners beside it."""
HISTORY = 50
MAX_CHARS = 300
ICONS = {
    "info": "dialog-information-symbolic",
    "warning": "dialog-warning-symbolic",
    "error": "dialog-error-symbolic",
}


@dataclass
class _Banner:
    revealer: Gtk.Revealer
    box: Gtk.Box
    icon: Gtk.Image
    label: Gtk.Label
    bar: Gtk.LevelBar
    level: str = "info"
    timer: int = 0


class BannerStack(Gtk.Box):
    """A column of banners, meant to sit at the top of a ``Gtk.Overlay``."""

    def __init__(self) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        self.add_css_class("banner-stack")
        self.set_halign(Gtk.Align.CENTER)
        self.set_valign(Gtk.Align.START)
        self.set_margin_top(MARGIN_TOP)
        self.set_can_target(True)
        self._banners: dict[str, _Banner] = {}
        self._order: list[str] = []
        self.history: deque[tuple[str, str, str]] = deque(maxlen=HISTORY)
        """The last (topic, level, text) shown, newest last: what the operator was told."""

    # -- public ------------------------------------------------------------------------------
    def tell(
        self,
        topic: str,
        level: str,
        text: str,
        *,
        timeout: float | None = 4.0,
        fraction: float | None = None,
    ) -> None:
        """Show ``text`` for ``topic`` (replacing its banner's text); ``timeout`` None = until dismissed.

        ``fraction`` (0…1) adds a level bar, e.g. the speed setting.
        """
        banner = self._banners.get(topic)
        if banner is None:
            banner = self._make(topic)
        text = _one_paragraph(text)
        if not self.history or self.history[-1] != (topic, level, text):
            self.history.append((topic, level, text))
        banner.label.set_text(text)
        banner.label.set_tooltip_text(text)
        if banner.level != level:
            banner.box.remove_css_class(banner.level)
            banner.box.add_css_class(level)
            banner.level = level
        banner.icon.set_from_icon_name(ICONS.get(level, ICONS["info"]))
        banner.bar.set_visible(fraction is not None)
        if fraction is not None:
            banner.bar.set_value(max(0.0, min(1.0, fraction)))
        if banner.timer:
            GLib.source_remove(banner.timer)
            banner.timer = 0
        if timeout is not None:
            banner.timer = GLib.timeout_add(int(timeout * 1000), self._expire, topic)
        banner.revealer.set_reveal_child(True)

    def dismiss(self, topic: str) -> None:
        banner = self._banners.pop(topic, None)
        if banner is None:
            return
        self._order.remove(topic)
        if banner.timer:
            GLib.source_remove(banner.timer)
            banner.timer = 0
        self.remove(banner.revealer)

    def dismiss_all(self) -> None:
        for topic in list(self._banners):
            self.dismiss(topic)

    def text(self, topic: str) -> str | None:
        """The text shown for ``topic`` (None when no banner) — for tests and screen readers alike."""
        banner = self._banners.get(topic)
        return None if banner is None else banner.label.get_text()

    def topics(self) -> list[str]:
        return list(self._order)

    def keep_clear_of(
        self,
        *pills: Gtk.Widget,
        avoid: tuple[float, float, float, float] | None = None,
        bottom: int = 0,
    ) -> None:
        """Keep the column off the motion pills (the map's, the camera page's): a banner never hides
        what the robot is doing. Where the centred column would cover a pill it moves beside it, on
        the same row, when there is :data:`MIN_BESIDE` px of room (800×480 and up); only then under
        it (a phone), which covers more of the map — unless the column would cover ``avoid`` there (the
        robot as drawn, in the parent's terms) and ``bottom`` offers a place that ends that far above
        the bottom (above a phone's D-pad) and is clear of it. Called by the window's timer; the margins are
        computed from the column's natural width, not its last place, so they hold steady, and only
        change when they must (no relayout otherwise)."""
        top, start, end, low = MARGIN_TOP, 0, 0, 0
        parent = self.get_parent()
        width = parent.get_width() if parent is not None else 0
        if parent is not None and width > 0 and self._order:
            natural = self.measure(Gtk.Orientation.HORIZONTAL, -1)[1]
            natural = min(natural - self.get_margin_start() - self.get_margin_end(), width)
            left, right = (width - natural) / 2, (width + natural) / 2
            for pill in pills:
                ok, box = pill.compute_bounds(parent) if pill.get_mapped() else (False, None)
                if not ok or box is None:
                    continue
                x0, x1 = box.get_x(), box.get_x() + box.get_width()
                if right <= x0 - GAP or x1 + GAP <= left:
                    continue  # the centred column is clear of it already
                room_right, room_left = width - x1 - GAP, x0 - GAP
                if room_right >= MIN_BESIDE and room_right >= room_left:
                    start = round(x1 + GAP)
                elif room_left >= MIN_BESIDE:
                    end = round(width - x0 + GAP)
                else:
                    top = max(top, round(box.get_y() + box.get_height()) + MARGIN_TOP // 2)
            height = self.measure(Gtk.Orientation.VERTICAL, natural)[1]
            height -= self.get_margin_top() + self.get_margin_bottom()
            if avoid is not None and bottom > 0 and top > MARGIN_TOP:
                under = (left, top, right, top + height)
                floor = parent.get_height() - bottom
                low_place = (left, floor - height, right, floor)
                if _overlap(under, avoid) and not _overlap(low_place, avoid) and floor - height > top:
                    top, low = MARGIN_TOP, bottom
        place = (top, start, end, low)
        if (
            self.get_margin_top(),
            self.get_margin_start(),
            self.get_margin_end(),
            self.get_margin_bottom(),
        ) != place:
            self.set_margin_top(top)
            self.set_margin_start(start)
            self.set_margin_end(end)
            self.set_margin_bottom(low)
            self.set_valign(Gtk.Align.END if low else Gtk.Align.START)

    # -- internals ---------------------------------------------------------------------------
    def _make(self, topic: str) -> _Banner:
        while len(self._order) >= MAX_BANNERS:
            self.dismiss(self._order[0])
        box = Gtk.Box(orientation=Gtk.Orientation.HORIZONTAL, spacing=10)
        box.add_css_class("banner")
        box.add_css_class("info")
        icon = Gtk.Image.new_from_icon_name(ICONS["info"])
        label = Gtk.Label(xalign=0.0, wrap=True, max_width_chars=48)
        label.set_use_markup(False)
        label.set_selectable(False)
        bar = Gtk.LevelBar(min_value=0.0, max_value=1.0, visible=False)
        bar.set_size_request(140, 10)
        bar.set_valign(Gtk.Align.CENTER)
        close = Gtk.Button.new_from_icon_name("window-close-symbolic")
        close.add_css_class("flat")
        close.add_css_class("circular")
        close.set_focusable(False)
        close.set_tooltip_text(_("Dismiss"))
        accessible.name(close, _("Dismiss"))
        close.connect("clicked", lambda _b: self.dismiss(topic))
        for child in (icon, label, bar, close):
            box.append(child)
        label.set_hexpand(True)
        revealer = Gtk.Revealer(
            transition_type=Gtk.RevealerTransitionType.SLIDE_DOWN, transition_duration=150
        )
        revealer.set_child(box)
        self.append(revealer)
        banner = _Banner(revealer, box, icon, label, bar)
        self._banners[topic] = banner
        self._order.append(topic)
        return banner

    def _expire(self, topic: str) -> bool:
        banner = self._banners.get(topic)
        if banner is not None:
            banner.timer = 0
            self.dismiss(topic)
        return False


def _overlap(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _one_paragraph(text: str) -> str:
    """Bounded, without control characters other than spaces (server text can be anything)."""
    clean = "".join(ch if ch.isprintable() or ch in _NO_BREAKS else " " for ch in text).strip()
    return clean if len(clean) <= MAX_CHARS else clean[: MAX_CHARS - 1] + "…"


_NO_BREAKS = "\u00a0\u2060"
"""No-break space and word joiner: harmless, and they keep "rtmu --demo" on one line."""
