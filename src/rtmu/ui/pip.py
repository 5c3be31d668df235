"""The live picture over the map (picture-in-picture): drag it to move, drag its corner to resize, × hides it.

It grows the camera inset (:class:`rtmu.ui.camera.CameraInset`: the picture's age,
greyed while the link is lost, a click opens the camera page) with three
gestures. A move or resize claims its drag, so it never counts as a click, and
the picture always stays inside the map.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Graphene", "1.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Graphene, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from .camera import INSET_MIN_WIDTH, CameraInset  # noqa: E402

MAX_WIDTH = 640
MARGIN = 10


class PictureInPicture(CameraInset):
    """The camera inset, movable (drag), resizable (corner grip) and hideable (× calls ``on_hide``)."""

    def __init__(
        self,
        on_open: Callable[[], None],
        *,
        on_hide: Callable[[], None],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(on_open, clock=clock)
        self.add_css_class("pip")
        self.user_width: int | None = None
        """Width the operator chose by resizing (None: follow the map's width)."""
        self.moved = False
        overlay = self.get_first_child()
        assert isinstance(overlay, Gtk.Overlay)

        close = Gtk.Button(label="×", halign=Gtk.Align.END, valign=Gtk.Align.START)
        close.add_css_class("pip-close")
        close.set_focusable(False)
        close.set_tooltip_text(_("Hide the picture (View ▸ Camera inset on the map brings it back)"))
        close.connect("clicked", lambda _b: on_hide())
        overlay.add_overlay(close)
        self.close_button = close

        grip = Gtk.Label(label="◢", halign=Gtk.Align.END, valign=Gtk.Align.END)
        grip.add_css_class("pip-grip")
        grip.set_tooltip_text(_("Drag to resize"))
        overlay.add_overlay(grip)
        self.grip = grip
        self.age_label.set_margin_end(18)  # clear of the grip

        # The drag lives on the map (the parent), whose coordinates stay put while the picture moves
        # under the pointer: offsets measured on the picture itself would shrink as it follows.
        self._drag = Gtk.GestureDrag()
        self._drag.connect("drag-begin", self._drag_begin)
        self._drag.connect("drag-update", self._drag_update)
        self._drag_parent: Gtk.Widget | None = None
        self.connect("notify::parent", lambda *_a: self._adopt_parent())
        self._mode = ""
        self._origin = (0.0, 0.0)
        self._start_width = 0

    # -- drag: move, or resize from the grip ------------------------------------------------------
    def _adopt_parent(self) -> None:
        if self._drag_parent is not None:
            self._drag_parent.remove_controller(self._drag)
        self._drag_parent = self.get_parent()
        if self._drag_parent is not None:
            self._drag_parent.add_controller(self._drag)

    def _drag_begin(self, gesture: Gtk.GestureDrag, x: float, y: float) -> None:
        parent = self._drag_parent
        self._mode = ""
        if parent is None or not self.get_visible():
            gesture.set_state(Gtk.EventSequenceState.DENIED)
            return
        ok, box = self.compute_bounds(parent)
        ok_grip, grip = self.grip.compute_bounds(parent)
        if ok_grip and grip.contains_point(_point(x, y)):
            self._mode = "resize"
            self._start_width = self.picture._size[0]
            gesture.set_state(Gtk.EventSequenceState.CLAIMED)  # neither a move nor a click
        elif ok and box.contains_point(_point(x, y)):
            self._mode = "move"
            self._origin = (box.get_x(), box.get_y())
        else:
            gesture.set_state(Gtk.EventSequenceState.DENIED)  # the map's own drag (panning)

    def _drag_update(self, gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        if self._mode == "resize":
            self.resize_to(int(self._start_width + dx))
        elif self._mode == "move":
            if not self.moved and abs(dx) + abs(dy) < 6:
                return
            gesture.set_state(Gtk.EventSequenceState.CLAIMED)  # a move is not a click
            self.move_to(self._origin[0] + dx, self._origin[1] + dy)

    def move_to(self, x: float, y: float) -> None:
        """Put the picture's top-left corner at (x, y) in the map, kept inside it."""
        parent = self.get_parent()
        w, h = self.get_width(), self.get_height()
        pw = parent.get_width() if parent is not None else 0
        ph = parent.get_height() if parent is not None else 0
        x = min(max(0.0, x), max(0, pw - w))
        y = min(max(0.0, y), max(0, ph - h))
        self.moved = True
        self.set_halign(Gtk.Align.START)
        self.set_valign(Gtk.Align.START)
        self.set_margin_start(int(x))
        self.set_margin_top(int(y))
        self.set_margin_end(0)
        self.set_margin_bottom(0)

    def place(self, *, corner_free: bool) -> None:
        if not getattr(self, "moved", False):  # once moved by hand, the picture stays where it was put
            super().place(corner_free=corner_free)

    # -- resize ----------------------------------------------------------------------------------
    def resize_to(self, width: int) -> None:
        """The operator's width (4:3), kept between the inset's smallest and :data:`MAX_WIDTH`."""
        width = min(max(INSET_MIN_WIDTH, width), MAX_WIDTH)
        self.user_width = width
        self.picture.set_size(width, width * 3 // 4)

    def texture_for(self, picture: Gdk.Texture, thumbnail: Gdk.Texture) -> Gdk.Texture:
        """The thumbnail while it is big enough (scaling a full frame every paint costs the GTK thread)."""
        return thumbnail if self.picture._size[0] <= thumbnail.get_width() else picture

    def fit_to(self, map_width: int) -> None:
        if getattr(self, "user_width", None) is None:
            super().fit_to(map_width)


def _point(x: float, y: float) -> Graphene.Point:
    return Graphene.Point().init(x, y)
