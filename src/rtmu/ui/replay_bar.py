"""The replay controls under the map: REPLAY, play/pause, ±1 s steps, speed x0.25–x8, a timeline, the time.

Only moves a :class:`~rtmu.recorder.replay.ReplayClock`; a seek to before what has been
shown asks ``rebuild`` for a fresh replay from the start (the session is rebuilt from
the bytes). Nothing here can take the keyboard: the drive keys must keep reaching the
window, where they say "replay".
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from ..base.i18n import _, number  # noqa: E402
from ..recorder.replay import SPEEDS, ReplayClock  # noqa: E402
from . import accessible  # noqa: E402

STEP_NS = 1_000_000_000
REFRESH_MS = 100
SCRUB_SETTLE_MS = 150
"""A drag on the timeline seeks once it rests this long (a backward seek rebuilds the session)."""


def clock_text(ns: int) -> str:
    seconds = max(0.0, ns / 1e9)
    return f"{int(seconds // 60)}:{number(seconds % 60, 1).zfill(4)}"


class ReplayBar(Gtk.Box):
    """``ReplayBar(clock, seek, name)``: ``seek(at_ns)`` moves the replay (and rebuilds when it must)."""

    def __init__(self, clock: ReplayClock, seek: Callable[[int], None], name: str) -> None:
        super().__init__(orientation=Gtk.Orientation.HORIZONTAL, spacing=6)
        self.add_css_class("replay-bar")
        self.set_margin_start(6)
        self.set_margin_end(6)
        self.set_margin_top(3)
        self.set_margin_bottom(3)
        self.clock = clock
        self._seek = seek
        self._pending: int | None = None
        self._settle: int | None = None
        badge = Gtk.Label(label=_("REPLAY"))
        badge.add_css_class("replay-badge")
        badge.set_tooltip_text(
            _("A recording is shown ({name}): nothing is sent to any robot").format(name=name)
        )
        self.append(badge)
        self.back = self._button("media-skip-backward-symbolic", _("Back 1 s"), lambda: self.step(-STEP_NS))
        self.play_button = self._button("media-playback-pause-symbolic", _("Play / pause"), self.toggle)
        self.forward = self._button(
            "media-skip-forward-symbolic", _("Forward 1 s"), lambda: self.step(STEP_NS)
        )
        self.speed = Gtk.DropDown.new_from_strings([f"x{s:g}" for s in SPEEDS])
        self.speed.set_focusable(False)
        self.speed.set_selected(SPEEDS.index(1.0))
        self.speed.set_tooltip_text(_("Replay speed"))
        accessible.name(self.speed, _("Replay speed"))
        self.speed.connect("notify::selected", self._speed_chosen)
        self.append(self.speed)
        seconds = max(0.1, (clock.end_ns - clock.start_ns) / 1e9)
        self.timeline = Gtk.Scale.new_with_range(Gtk.Orientation.HORIZONTAL, 0.0, seconds, 0.1)
        self.timeline.set_draw_value(False)
        self.timeline.set_hexpand(True)
        self.timeline.set_focusable(False)
        self.timeline.set_tooltip_text(_("Scrub through the recording"))
        accessible.name(self.timeline, _("Recording position"))
        self.timeline.connect("change-value", self._scrubbed)
        self.append(self.timeline)
        self.time_label = Gtk.Label(label="")
        self.time_label.add_css_class("numeric")
        self.append(self.time_label)
        self._timer = GLib.timeout_add(REFRESH_MS, self._refresh)
        self.connect("unrealize", lambda _w: self._stop_timer())
        self._refresh()

    def _button(self, icon: str, tip: str, fn: Callable[[], None]) -> Gtk.Button:
        button = Gtk.Button(icon_name=icon)
        button.set_focusable(False)
        button.set_tooltip_text(tip)
        accessible.name(button, accessible.spoken(tip))
        button.connect("clicked", lambda _b: fn())
        self.append(button)
        return button

    # -- actions -----------------------------------------------------------------------------------
    def toggle(self) -> None:
        if self.clock.playing:
            self.clock.pause()
        else:
            if self.clock.finished:
                self.seek(self.clock.start_ns)
            self.clock.play()
        self._refresh()

    def step(self, delta_ns: int) -> None:
        """One second back or on, paused: to look at a moment closely."""
        self.clock.pause()
        self.seek(self.clock.now_ns() + delta_ns)

    def seek(self, at_ns: int) -> None:
        self._seek(min(max(at_ns, self.clock.start_ns), self.clock.end_ns))
        self._refresh()

    def set_speed(self, speed: float) -> None:
        self.speed.set_selected(SPEEDS.index(speed))

    def _speed_chosen(self, dropdown: Gtk.DropDown, _pspec: object) -> None:
        self.clock.set_speed(SPEEDS[dropdown.get_selected()])

    def _scrubbed(self, _scale: Gtk.Scale, _scroll: object, value: float) -> bool:
        self._pending = self.clock.start_ns + round(value * 1e9)
        if self._settle is not None:
            GLib.source_remove(self._settle)
        self._settle = GLib.timeout_add(SCRUB_SETTLE_MS, self._apply_scrub)
        return False

    def _apply_scrub(self) -> bool:
        self._settle = None
        if self._pending is not None:
            self.seek(self._pending)
            self._pending = None
        return False

    # -- display -----------------------------------------------------------------------------------
    def _refresh(self) -> bool:
        now = self.clock.now_ns()
        if self._settle is None:
            self.timeline.set_value((now - self.clock.start_ns) / 1e9)
        icon = "media-playback-pause-symbolic" if self.clock.playing else "media-playback-start-symbolic"
        self.play_button.set_icon_name(icon)
        total = self.clock.end_ns - self.clock.start_ns
        self.time_label.set_text(f"{clock_text(now - self.clock.start_ns)} / {clock_text(total)}")
        return True

    def _stop_timer(self) -> None:
        if self._timer:
            GLib.source_remove(self._timer)
            self._timer = 0
