"""The split view: the map and the live picture side by side, or stacked when the window is narrow.

A third view beside the map and the camera page: it holds the window's map page
as its first pane and a picture pane (the same textures as the camera page, with
the video's figures) as its second, shown only while split. It turns to a
stacked layout when the window is taller than wide (a phone held upright).
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..model.observables import CameraImage  # noqa: E402


class _SizedBoxLayout(Gtk.BoxLayout):
    """A box layout that tells its widget each size it allocates.

    A ``Gtk.Box`` allocates through its layout manager, so a box's own ``do_size_allocate`` is never
    called: the size has to be caught here.
    """

    def __init__(self, on_size: Callable[[int, int], None]) -> None:
        super().__init__()
        self._on_size = on_size

    def do_allocate(self, widget: Gtk.Widget, width: int, height: int, baseline: int) -> None:
        self._on_size(width, height)
        Gtk.BoxLayout.do_allocate(self, widget, width, height, baseline)


class SplitView(Gtk.Box):
    """``map_page`` and, while :attr:`split`, the live picture beside (or under) it."""

    def __init__(self, map_page: Gtk.Widget) -> None:
        super().__init__(orientation=Gtk.Orientation.HORIZONTAL, spacing=0)
        self.set_layout_manager(_SizedBoxLayout(self._allocated))
        self.add_css_class("split-view")
        self.set_homogeneous(True)
        map_page.set_hexpand(True)
        map_page.set_vexpand(True)
        self.append(map_page)
        self.pane = Gtk.Overlay()
        self.pane.add_css_class("split-video")
        self.picture = Gtk.Picture()
        self.picture.set_can_shrink(True)
        if hasattr(self.picture, "set_content_fit"):
            self.picture.set_content_fit(Gtk.ContentFit.CONTAIN)
        self.pane.set_child(self.picture)
        self.caption = Gtk.Label(halign=Gtk.Align.START, valign=Gtk.Align.START)
        self.caption.add_css_class("video-caption")
        self.caption.set_use_markup(False)
        self.caption.set_ellipsize(Pango.EllipsizeMode.END)  # a dropped frame's reason can be long
        self.caption.set_max_width_chars(90)
        self.caption.set_can_target(False)
        self.caption.set_margin_start(8)
        self.caption.set_margin_top(8)
        self.pane.add_overlay(self.caption)
        self.placeholder = Gtk.Label(label=_("No picture yet: live video starts with the split view."))
        self.placeholder.set_wrap(True)
        self.placeholder.set_use_markup(False)
        self.pane.add_overlay(self.placeholder)
        self.pane.set_visible(False)
        self.append(self.pane)
        self._pending: Gtk.Orientation | None = None

    @property
    def split(self) -> bool:
        return self.pane.get_visible()

    def set_split(self, on: bool) -> None:
        self.pane.set_visible(on)

    def show_picture(self, texture: Gdk.Texture | None, image: CameraImage | None) -> None:
        """The newest picture (None forgets it: disconnected), with the live figures when it has them."""
        self.picture.set_paintable(texture)
        self.placeholder.set_visible(texture is None)
        status = None if image is None else image.video
        if self.split or status is None:  # a hidden pane's label must not re-lay out the window per frame
            self.caption.set_text("" if status is None else status.caption())
            self.caption.set_visible(status is not None)

    def _allocated(self, width: int, height: int) -> None:
        wanted = Gtk.Orientation.HORIZONTAL if width >= height else Gtk.Orientation.VERTICAL
        if wanted != self.get_orientation() and self._pending is None:
            self._pending = wanted  # never re-layout inside an allocation: on the next idle
            GLib.idle_add(self._turn)

    def _turn(self) -> bool:
        if self._pending is not None:
            self.set_orientation(self._pending)
            self._pending = None
        return False
