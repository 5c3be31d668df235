"""The camera page (request → "coming…" → picture scaled to fit, with its age) and the map inset.

JPEG bytes from the robot are untrusted: they are decoded with Pillow on a
worker thread (never on the GTK thread), refused above :data:`MAX_SIDE` pixels,
and only the newest picture is kept — a slow decode never queues up behind
newer ones. The texture is made on the GTK thread from plain RGB bytes.
"""

from __future__ import annotations

import io
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..base.units import quantity  # noqa: E402
from ..model.observables import CameraImage  # noqa: E402
from .toolbar import age_text  # noqa: E402

MAX_SIDE = 4096
DECODE_SIDE = 1024
"""A bigger picture is decoded at 1/2, 1/4 or 1/8 scale (JPEG's own DCT scaling, no resampling)
down to about this size: a window shows it no larger, and a 4096×4096 frame then costs 3 MB and
~20 ms instead of 50 MB and ~140 ms a frame (a 632-byte JPEG may declare that much)."""
INSET_SIZE = (176, 132)
"""The inset's largest size (and its thumbnail's)."""
INSET_MIN_WIDTH = 96
INSET_OLD_AFTER = 3.0
"""Seconds after which the inset's picture is greyed and called old: live video is 15 pictures a
second and one request answers in well under a second, so an older one is no view of now."""
COMPACT_BAR_BELOW = 620
"""Page width (px) under which the bar's "New picture" and "Back to map" become icons."""
MAX_JPEG_BYTES = 16 * 1024 * 1024
REQUEST_TIMEOUT = 7.0
"""Seconds the page waits for a requested picture before saying none came."""


@dataclass(frozen=True, slots=True)
class Decoded:
    """RGB pixels of a picture and of its thumbnail for the map inset."""

    width: int
    height: int
    rgb: bytes
    thumb_width: int
    thumb_height: int
    thumb_rgb: bytes


def decode_jpeg(data: bytes) -> Decoded:
    """The picture and its inset thumbnail; ValueError for anything that is not a sane picture."""
    from PIL import Image, UnidentifiedImageError

    if len(data) > MAX_JPEG_BYTES:
        raise ValueError(_("the picture is too large"))
    try:
        with Image.open(io.BytesIO(data)) as img:
            w, h = img.size
            if not (0 < w <= MAX_SIDE and 0 < h <= MAX_SIDE):
                raise ValueError(_("a {width}×{height} picture is out of range").format(width=w, height=h))
            img.draft("RGB", (DECODE_SIDE, DECODE_SIDE))  # a no-op for all but big JPEGs
            rgb = img.convert("RGB")
            w, h = rgb.size
            # A box reduce by a whole factor, never below the inset's size: ten times cheaper than
            # thumbnail()'s resampling (2.3 ms of a 640x480 frame's 3 ms), and GTK scales the rest.
            factor = max(1, min(w // INSET_SIZE[0], h // INSET_SIZE[1]))
            thumb = rgb.reduce(factor) if factor > 1 else rgb
            return Decoded(w, h, rgb.tobytes(), thumb.width, thumb.height, thumb.tobytes())
    except UnidentifiedImageError:
        # Pillow's own text names a Python object ("<_io.BytesIO object at 0x…>"): say it plainly.
        raise ValueError(_("the {count} bytes received are not a picture").format(count=len(data))) from None
    except Image.DecompressionBombError:
        raise ValueError(_("the picture claims too many pixels")) from None
    except OSError:
        raise ValueError(
            _("the picture is damaged or cut short ({count} bytes)").format(count=len(data))
        ) from None


HAND_OVER_PRIORITY = GLib.PRIORITY_HIGH_IDLE
"""Above GTK's layout and redraw (``GDK_PRIORITY_REDRAW`` is ``HIGH_IDLE`` + 20): a decoded frame
reaches its widgets before the paint already pending, not one frame-clock tick (up to 17 ms) after it.
Safe from floods: at most one hand-over is ever pending (the newest decoded picture)."""


class PictureDecoder:
    """Decode on one worker thread; ``deliver(image, textures_or_None, error)`` runs on the GTK thread.

    ``textures`` is (picture, thumbnail). Only the newest picture is decoded, and only the newest
    decoded one handed over: a busy GTK thread never works through a queue of stale frames.
    """

    def __init__(
        self, deliver: Callable[[CameraImage, tuple[Gdk.Texture, Gdk.Texture] | None, str], None]
    ) -> None:
        self._deliver = deliver
        self._lock = threading.Condition()
        self._next: CameraImage | None = None
        self._ready: tuple[CameraImage, Decoded | None, str] | None = None
        """The newest decoded picture not yet handed over (one idle source is pending for it)."""
        self._closed = False
        self._thread = threading.Thread(target=self._work, name="rtmu-jpeg", daemon=True)
        self._thread.start()

    def decode(self, image: CameraImage) -> None:
        with self._lock:
            self._next = image
            self._lock.notify()

    def close(self) -> None:
        with self._lock:
            self._closed = True
            self._lock.notify()

    def _work(self) -> None:
        while True:
            with self._lock:
                self._lock.wait_for(lambda: self._closed or self._next is not None)
                if self._closed:
                    return
                image, self._next = self._next, None
            assert image is not None
            try:
                result: tuple[CameraImage, Decoded | None, str] = (image, decode_jpeg(image.jpeg), "")
            except ValueError as exc:
                result = (image, None, str(exc))
            with self._lock:
                idle = self._ready is None
                self._ready = result  # an older one not yet handed over is dropped
            if idle:
                # PyGObject takes priority= (its stubs do not list it)
                GLib.idle_add(self._take_ready, priority=HAND_OVER_PRIORITY)  # type: ignore[call-arg]

    def _take_ready(self) -> bool:
        with self._lock:
            ready, self._ready = self._ready, None
        if ready is not None:
            self._hand_over(*ready)
        return False

    def _hand_over(self, image: CameraImage, decoded: Decoded | None, error: str) -> bool:
        textures = None
        if decoded is not None:
            textures = (
                _texture(decoded.width, decoded.height, decoded.rgb),
                _texture(decoded.thumb_width, decoded.thumb_height, decoded.thumb_rgb),
            )
        if not self._closed:
            self._deliver(image, textures, error)
        return False


def _texture(width: int, height: int, rgb: bytes) -> Gdk.Texture:
    return Gdk.MemoryTexture.new(width, height, Gdk.MemoryFormat.R8G8B8, GLib.Bytes.new(rgb), width * 3)


class CameraView(Gtk.Box):
    """The camera page. ``on_request`` asks for a picture; ``on_back`` returns to the map."""

    def __init__(
        self,
        *,
        on_request: Callable[[], None],
        on_back: Callable[[], None],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL, spacing=0)
        self.add_css_class("camera-page")
        self.clock = clock
        self._on_request = on_request
        self.image: CameraImage | None = None
        self.texture: Gdk.Texture | None = None
        self.requested_at: float | None = None
        self._age_elsewhere = False
        self.error = ""

        overlay = self.overlay = Gtk.Overlay()
        overlay.set_vexpand(True)
        self.picture = Gtk.Picture()
        self.picture.set_can_shrink(True)
        if hasattr(self.picture, "set_content_fit"):
            self.picture.set_content_fit(Gtk.ContentFit.CONTAIN)
        self.picture.add_css_class("camera-picture")
        overlay.set_child(self.picture)
        self.status_box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=8)
        self.status_box.add_css_class("camera-status")
        self.status_box.set_halign(Gtk.Align.CENTER)
        self.status_box.set_valign(Gtk.Align.CENTER)
        self.spinner = Gtk.Spinner()
        self.spinner.set_size_request(32, 32)
        self.status_label = Gtk.Label(wrap=True, max_width_chars=40, justify=Gtk.Justification.CENTER)
        self.status_label.set_use_markup(False)
        self.status_box.append(self.spinner)
        self.status_box.append(self.status_label)
        overlay.add_overlay(self.status_box)
        self.append(overlay)

        bar = self.bar = Gtk.Box(orientation=Gtk.Orientation.HORIZONTAL, spacing=8)
        bar.add_css_class("camera-bar")
        self.info = Gtk.Label(xalign=0.0, hexpand=True)
        self.info.set_use_markup(False)
        self.info.set_ellipsize(Pango.EllipsizeMode.END)
        self.refresh_button = Gtk.Button.new_with_label(_("New picture"))
        self.refresh_button.set_focusable(False)
        self.refresh_button.connect("clicked", lambda _b: on_request())
        back = Gtk.Button.new_with_label(_("Back to map (Esc)"))
        back.set_focusable(False)
        back.connect("clicked", lambda _b: on_back())
        self.back_button = back
        self.compact = False
        self._refresh_tip = _("New picture")
        self._words_on_buttons()
        for w in (self.info, self.refresh_button, back):
            bar.append(w)
        self.append(bar)
        self._show_status(_("No picture yet."), busy=False)

    # -- state -------------------------------------------------------------------------------
    @property
    def waiting(self) -> bool:
        return self.requested_at is not None

    @property
    def age_shown_elsewhere(self) -> bool:
        """Live video's caption over the picture says the frame's age (``ui.live_video``)."""
        return self._age_elsewhere

    @age_shown_elsewhere.setter
    def age_shown_elsewhere(self, value: bool) -> None:
        self._age_elsewhere = value
        self.tick()

    def requesting(self) -> None:
        """A picture was asked for: show that it is coming (the old one stays, dimmed)."""
        self.requested_at = self.clock()
        self.error = ""
        self.picture.add_css_class("dimmed")
        self._show_status(_("Requesting a picture…"), busy=True)
        self.tick()

    def show_picture(self, image: CameraImage, texture: Gdk.Texture | None, error: str) -> None:
        if texture is None:
            self.failed(_("The picture could not be shown: {error}").format(error=error))
            return
        self.image, self.texture = image, texture
        self.requested_at = None
        self.error = ""
        self.picture.set_paintable(texture)
        self.picture.remove_css_class("dimmed")
        self.status_box.set_visible(False)
        self.spinner.stop()
        self.tick()

    def failed(self, reason: str) -> None:
        self.requested_at = None
        self.error = reason
        self.picture.remove_css_class("dimmed")
        self._show_status(reason, busy=False)
        self.tick()

    def clear(self) -> None:
        """Disconnected: forget the picture (an old picture must not pass for the robot's view)."""
        self.image = self.texture = None
        self.picture.set_paintable(None)
        self.requested_at = None
        self._show_status(_("No picture yet."), busy=False)
        self.tick()

    def set_available(self, enabled: bool, reason: str) -> None:
        self.refresh_button.set_sensitive(enabled)
        self._refresh_tip = (
            _("New picture") if enabled else _("Camera picture: {reason}").format(reason=reason)
        )
        self.refresh_button.set_tooltip_text(self._refresh_tip)

    def _buttons(self) -> tuple[tuple[Gtk.Button, str, str, str], ...]:
        """(button, its words, its icon, its tooltip)."""
        return (
            (self.refresh_button, _("New picture"), "camera-photo-symbolic", self._refresh_tip),
            (self.back_button, _("Back to map (Esc)"), "go-previous-symbolic", _("Back to map (Esc)")),
        )

    def _words_on_buttons(self) -> None:
        for button, words, _icon, tip in self._buttons():
            button.set_label(words)
            label = button.get_child()
            if isinstance(label, Gtk.Label):  # shrinks (ellipsized) rather than widen the window
                label.set_ellipsize(Pango.EllipsizeMode.END)
            button.set_tooltip_text(tip)

    def fit_bar(self, width: int) -> None:
        """Under :data:`COMPACT_BAR_BELOW` px the two word buttons become icons (their words in the
        tooltip): on a phone the words were cut to a letter."""
        compact = 0 < width < COMPACT_BAR_BELOW
        if compact == self.compact:
            return
        self.compact = compact
        if compact:
            for button, _words, icon, tip in self._buttons():
                button.set_icon_name(icon)
                button.set_tooltip_text(tip)
        else:
            self._words_on_buttons()

    def tick(self) -> None:
        """Update the age line; give up on a request that took too long; fit the bar to the width."""
        self.fit_bar(self.get_width())
        now = self.clock()
        if self.requested_at is not None and now - self.requested_at > REQUEST_TIMEOUT:
            self.failed(
                _("No picture arrived within {timeout}.").format(timeout=quantity(REQUEST_TIMEOUT, "s"))
            )
            return
        if self.image is None:
            self.info.set_text(_("Requesting…") if self.waiting else (self.error or _("No picture")))
            return
        age = max(0.0, now - self.image.received_at)
        text = _("{width}×{height} from {source}").format(
            width=self.image.width, height=self.image.height, source=self.image.source
        )
        if not self.age_shown_elsewhere:  # live video's caption says the frame's age: one age, not two
            text += _(" · {age_text} old").format(age_text=age_text(age))
        if self.waiting:
            text += _(" · requesting a new one…")
        if text != self.info.get_text():
            self.info.set_text(text)

    def _show_status(self, text: str, *, busy: bool) -> None:
        self.status_label.set_text(text)
        self.status_box.set_visible(True)
        self.spinner.set_visible(busy)
        if busy:
            self.spinner.start()
        else:
            self.spinner.stop()


class CameraInset(Gtk.Box):
    """The last picture as a small inset on the map, with its age; a click opens the camera page.

    An old picture must never pass for the robot's view: the inset shows how old it is, turns
    grey and says "old picture" once it is older than :data:`INSET_OLD_AFTER` or while the link is
    lost (:meth:`set_live`), and the window clears it on a new connection. It sits in the
    bottom-left corner (top right while the touch D-pad is there)
    and takes about a sixth of the map's width, between :data:`INSET_MIN_WIDTH` and
    :data:`INSET_SIZE`.
    """

    def __init__(self, on_open: Callable[[], None], clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self.add_css_class("camera-inset")
        self.clock = clock
        self.received_at: float | None = None
        self.live = True
        self.picture = _SizedPicture()
        overlay = Gtk.Overlay()
        overlay.set_child(self.picture)
        self.age_label = Gtk.Label(halign=Gtk.Align.END, valign=Gtk.Align.END)
        self.age_label.add_css_class("inset-age")
        self.age_label.set_can_target(False)
        overlay.add_overlay(self.age_label)
        self.append(overlay)
        click = Gtk.GestureClick()
        click.connect("released", lambda *_a: on_open())
        self.add_controller(click)
        self.enabled = True
        self.beside = False
        """The same picture is on screen beside the map (split view): the inset would only repeat it
        over a corner of the map."""
        self.set_visible(False)
        self.place(corner_free=True)
        self.fit_to(800)

    def show_texture(self, texture: Gdk.Texture | None, received_at: float | None = None) -> None:
        """A new picture (live again), or None to forget the picture."""
        self.picture.set_paintable(texture)
        self.received_at = received_at if texture is not None else None
        if texture is not None:
            self.set_live(True)
        self._show()
        self.tick()

    def set_enabled(self, on: bool) -> None:
        self.enabled = on
        self._show()

    def set_beside(self, on: bool) -> None:
        """Split view on or off: hidden while the picture is shown beside the map."""
        self.beside = on
        self._show()

    def _show(self) -> None:
        self.set_visible(self.enabled and not self.beside and self.picture.get_paintable() is not None)

    def set_live(self, live: bool) -> None:
        """False while the link is lost: the picture is greyed, and says so."""
        self.live = live
        self.tick()

    @property
    def old(self) -> bool:
        """The picture is older than :data:`INSET_OLD_AFTER`: shown greyed and called old."""
        return self.received_at is not None and self.clock() - self.received_at > INSET_OLD_AFTER

    def tick(self) -> None:
        """Update the age, and the grey of an old picture (the window calls this on its slow timer)."""
        old = self.old
        if self.live and not old:
            self.remove_css_class("stale")
        else:
            self.add_css_class("stale")
        if self.received_at is None:
            self._show_age("", None)
            return
        age = age_text(max(0.0, self.clock() - self.received_at))
        fresh = _("old picture · {age}").format(age=age) if old else age
        self._show_age(
            fresh if self.live else _("{age} · link lost").format(age=age),
            _("Camera picture taken {age} ago (click or Esc for the camera view)").format(age=age)
            if self.live
            else _("Camera picture taken {age} ago, before the link was lost").format(age=age),
        )

    def _show_age(self, text: str, tooltip: str | None) -> None:
        """Labels and tooltips are set only when they change: each set costs GTK a relayout."""
        if text != self.age_label.get_text():
            self.age_label.set_text(text)
        if tooltip != self.get_tooltip_text():
            self.set_tooltip_text(tooltip)

    def place(self, *, corner_free: bool) -> None:
        """Bottom left (away from the banners, the zoom buttons and the note); top right if the D-pad
        is in that corner."""
        self.set_halign(Gtk.Align.START if corner_free else Gtk.Align.END)
        self.set_valign(Gtk.Align.END if corner_free else Gtk.Align.START)
        for side in ("top", "bottom", "start", "end"):
            getattr(self, f"set_margin_{side}")(10)

    def fit_to(self, map_width: int) -> None:
        """About a sixth of the map's width (so 128 px on an 800 px screen), 4:3."""
        width = max(INSET_MIN_WIDTH, min(INSET_SIZE[0], map_width // 6))
        self.picture.set_size(width, width * 3 // 4)


class _SizedPicture(Gtk.Picture):
    """A picture of exactly the size it is given (a plain ``Gtk.Picture`` asks for its texture's size)."""

    def __init__(self) -> None:
        super().__init__()
        self.set_can_shrink(True)
        if hasattr(self, "set_content_fit"):
            self.set_content_fit(Gtk.ContentFit.CONTAIN)
        self._size = INSET_SIZE

    def set_size(self, width: int, height: int) -> None:
        if (width, height) != self._size:
            self._size = (width, height)
            self.queue_resize()

    def do_measure(  # GTK passes only the enum, never its nick strings
        self, orientation: Gtk.Orientation, for_size: int
    ) -> tuple[int, int, int, int]:
        n = self._size[0] if orientation == Gtk.Orientation.HORIZONTAL else self._size[1]
        return n, n, -1, -1
