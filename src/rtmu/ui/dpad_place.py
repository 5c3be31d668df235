"""Where the touch D-pad goes: a bottom corner of the page on screen, clear of the rest.

The D-pad is for a thumb, so it sits in the bottom-left corner (a phone centres it above the zoom
row: ``layout``). What this module keeps true, whatever the page and its width:

* it is on the page the operator looks at — the map, or the camera page (the one widget moves
  between them, so a finger held on it is one state);
* it never sits on the zoom row: a map narrower than the two side by side (split view, a fleet's
  list beside it) lifts the D-pad above the row, and a map under :data:`COMPACT_MAP` px gets the
  compact pads, so that Fit can show the map above them;
* the Go-to-point / Set-position bar keeps clear of it (beside it, or above it on a phone);
* Fit keeps the map clear of the D-pad and of the zoom row: the map is fitted in what they leave —
  beside or above each, whichever shows the map larger (:meth:`DPadPlacement.fit_room`) — unless
  that would shrink the map below half its plain fit (``viewport.best_fit``: a split phone's small
  map); even then the zoom row keeps its room (:meth:`DPadPlacement.fit_floor`).
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from .dpad import COMPACT_PAD_PX, PAD_PX, DPad  # noqa: E402
from .viewport import Insets  # noqa: E402

GAP = 8
"""Between the D-pad and what keeps clear of it (px)."""
ABOVE_OSD = 64
"""The D-pad's bottom margin when it must sit above the zoom row (as a phone's: ``layout``)."""
CORNER = 12
"""The D-pad's bottom margin in its corner."""
COMPACT_MAP = 600
"""A map narrower than this (px: split view or a fleet's list at 800×480) gets the compact pads in its
corner, so that Fit can keep the map clear of the D-pad (above it) and still show it at a legible size."""


def _footprint(widget: Gtk.Widget) -> tuple[int, int]:
    """A widget's natural width and height with its margins (``measure`` includes them)."""
    return widget.measure(Gtk.Orientation.HORIZONTAL, -1)[1], widget.measure(Gtk.Orientation.VERTICAL, -1)[1]


def _larger(a: Insets, b: Insets) -> Insets:
    return (max(a[0], b[0]), max(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3]))


class DPadPlacement:
    """See the module notes. ``refit`` is the map stage's (Fit again when the room changed); the map
    page calls :meth:`queue` when its stage is resized."""

    def __init__(
        self,
        dpad: DPad,
        map_page: Gtk.Overlay,
        *,
        osd: Gtk.Widget,
        pose_bar: Gtk.Widget,
        refit: Callable[[], None],
    ) -> None:
        self.dpad, self.map_page, self.osd, self.pose_bar = dpad, map_page, osd, pose_bar
        self._refit = refit
        self._pose_margin = (pose_bar.get_margin_start(), pose_bar.get_margin_bottom())
        self._camera: Gtk.Overlay | None = None
        self._idle = 0
        dpad.connect("notify::halign", lambda *_a: self.queue())
        dpad.connect("notify::visible", lambda *_a: self.queue())

    # -- the page on screen ------------------------------------------------------------------
    def follow_pages(self, stack: Gtk.Stack, camera_overlay: Gtk.Overlay, camera_page: str) -> None:
        """Move the D-pad onto the camera page while it shows, back onto the map after."""
        self._camera = camera_overlay

        def changed(*_a: object) -> None:
            self._move_to(camera_overlay if stack.get_visible_child_name() == camera_page else self.map_page)

        stack.connect("notify::visible-child-name", changed)
        changed()

    def _move_to(self, overlay: Gtk.Overlay) -> None:
        parent = self.dpad.get_parent()
        if parent is overlay:
            return
        if isinstance(parent, Gtk.Overlay):
            parent.remove_overlay(self.dpad)
        overlay.add_overlay(self.dpad)
        self.queue()

    def on_map(self) -> bool:
        return self.dpad.get_parent() is self.map_page

    # -- room ----------------------------------------------------------------------------------
    def _size(self) -> tuple[int, int]:
        """The D-pad's width and height with its margins (px): ``measure`` counts a widget's margins
        already (adding them again kept 64 px too many above a lifted D-pad)."""
        return _footprint(self.dpad)

    def fit_floor(self, _width: int, _height: int) -> tuple[Insets, ...]:
        """The ways Fit always keeps clear of the zoom row: left of it or above it."""
        if not self.osd.get_visible():
            return ()
        osd_w, osd_h = _footprint(self.osd)
        return ((0, 0, osd_w + GAP, 0), (0, 0, 0, osd_h + GAP))

    def fit_room(self, width: int, height: int) -> tuple[Insets, ...]:
        """The ways Fit may keep clear of the zoom row (:meth:`fit_floor`) and of the D-pad on the map
        (beside it in its corner, or above it): every pairing, the larger inset of each edge."""
        zoom_row = self.fit_floor(width, height) or ((0, 0, 0, 0),)
        pad: tuple[Insets, ...] = ((0, 0, 0, 0),)
        if self.dpad.get_visible() and self.on_map():
            w, h = self._size()
            above = (0, 0, 0, h + GAP)
            pad = (above,) if self.dpad.get_halign() == Gtk.Align.CENTER else ((w + GAP, 0, 0, 0), above)
        return tuple(_larger(a, b) for a in zoom_row for b in pad)

    def queue(self) -> None:
        """Place again after this layout (never inside a size allocation)."""
        if not self._idle:
            self._idle = GLib.idle_add(self._place_idle)

    def _place_idle(self) -> bool:
        self._idle = 0
        self.place()
        return False

    def place(self) -> None:
        """Lift the D-pad above the zoom row where both do not fit side by side; the pick bar clear of it."""
        d = self.dpad
        shown = d.get_visible()
        corner = d.get_halign() == Gtk.Align.START
        compact = corner and self.on_map() and self.map_page.get_width() < COMPACT_MAP
        d.set_pad_size(COMPACT_PAD_PX if compact else PAD_PX)
        w, h = self._size()
        if corner and self.on_map():
            osd_w = self.osd.measure(Gtk.Orientation.HORIZONTAL, -1)[1] + self.osd.get_margin_end()
            side_by_side = self.map_page.get_width() >= w + GAP + osd_w
            d.set_margin_bottom(CORNER if side_by_side else ABOVE_OSD)
        elif corner:
            d.set_margin_bottom(CORNER)  # the camera page has no zoom row
        start, bottom = self._pose_margin
        if shown and self.on_map():
            if corner:
                start = max(start, w + GAP)  # beside the D-pad
            else:
                bottom = max(bottom, h + GAP)  # a phone: above it
        self.pose_bar.set_margin_start(start)
        self.pose_bar.set_margin_bottom(bottom)
        self._refit()

    def close(self) -> None:
        if self._idle:
            GLib.source_remove(self._idle)
            self._idle = 0
