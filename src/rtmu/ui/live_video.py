"""Live video controls on the camera page: Live, Pause, Save frame, the rate and quality, and the figures.

The request loop runs on the network thread (``client.video_session``); frames
arrive as the model's camera part and are decoded on the window's JPEG thread.
This widget only adds buttons to the camera page's bar and a caption over its
picture (frames/s, kB/s, age, and why the rate was lowered), and saves the
frame on screen. Server text never reaches markup: every label is plain text.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import CameraImage  # noqa: E402
from ..values.intents import StopVideo  # noqa: E402
from . import accessible  # noqa: E402
from .camera import CameraView  # noqa: E402

FPS_CHOICES = (2, 5, 10, 15, 20, 30)
DEFAULT_FPS = 15
QUALITY_CHOICES = (N_("Server's"), "30", "50", "75", "90")


def frames_dir() -> Path:
    """Where saved frames go: ``rtmu`` in the XDG pictures folder (``user-dirs.dirs``), which is
    ``~/Pictures`` where the desktop never set one (as the README says; GLib gives no folder then)."""
    pictures = GLib.get_user_special_dir(GLib.UserDirectory.DIRECTORY_PICTURES)
    return Path(pictures or Path(GLib.get_home_dir()) / "Pictures") / "rtmu"


class LiveVideoControls:
    """Adds live video to a :class:`CameraView`; ``start``, ``stop`` and ``pause`` reach the link."""

    def __init__(
        self,
        camera: CameraView,
        *,
        start: Callable[[float, int | None], object],
        stop: Callable[[], object],
        pause: Callable[[bool], object],
        tell: Callable[[str, str], None],
    ) -> None:
        self.camera = camera
        self._start, self._stop, self._pause, self._tell = start, stop, pause, tell
        self.image: CameraImage | None = None
        self.saved: list[Path] = []
        self.folder: Path | None = None
        """Where Save writes (None: :func:`frames_dir`)."""
        self._after_paint: Callable[[], None] | None = None
        self._paint_handler = 0

        self.caption = Gtk.Label(halign=Gtk.Align.START, valign=Gtk.Align.START)
        self.caption.add_css_class("video-caption")
        self.caption.set_use_markup(False)
        self.caption.set_ellipsize(Pango.EllipsizeMode.END)  # a dropped frame's reason can be long
        self.caption.set_max_width_chars(90)
        self.caption.set_can_target(False)
        self.caption.set_margin_start(8)
        self.caption.set_margin_top(8)
        self.caption.set_visible(False)
        camera.overlay.add_overlay(self.caption)

        # Icons, and the rate and quality in a popover: the bar must still fit a 560 px window.
        self.live_button = Gtk.ToggleButton(icon_name="camera-video-symbolic")
        self.live_button.set_tooltip_text(_("Live video: a new frame as soon as one arrives"))
        self.pause_button = Gtk.ToggleButton(icon_name="media-playback-pause-symbolic")
        self.pause_button.set_tooltip_text(_("Pause the video"))
        self.pause_button.set_sensitive(False)
        self.save_button = Gtk.Button(icon_name="document-save-symbolic")
        self.save_button.set_tooltip_text(_("Save the frame on screen (JPEG)"))
        self.save_button.set_sensitive(False)
        self._fps_choice = FPS_CHOICES.index(DEFAULT_FPS)
        self._quality_choice = 0
        self.fps: Gtk.DropDown | None = None
        """The rate's and quality's drop-downs, made the first time the gear opens (``_settings_popup``):
        each carries a list and popover of its own, a sixth of the window's widgets at every launch."""
        self.quality: Gtk.DropDown | None = None
        self.settings_button = Gtk.MenuButton(icon_name="emblem-system-symbolic", popover=Gtk.Popover())
        self.settings_button.set_create_popup_func(self._settings_popup)
        self.settings_button.set_tooltip_text(_("Video frame rate and JPEG quality"))
        for w in (self.live_button, self.pause_button, self.save_button, self.settings_button):
            w.set_focusable(False)  # the arrow keys keep driving
        accessible.name(self.live_button, _("Live video"))
        accessible.name(self.pause_button, _("Pause video"))
        accessible.name(self.save_button, _("Save frame"))
        accessible.name_menu_button(self.settings_button, _("Video settings"))
        self.live_button.connect("toggled", self._live_toggled)
        self.pause_button.connect("toggled", lambda b: self._paused(b.get_active()))
        self.save_button.connect("clicked", lambda _b: self.save())
        anchor: Gtk.Widget = camera.info
        for w in (self.live_button, self.pause_button, self.save_button, self.settings_button):
            camera.bar.insert_child_after(w, anchor)
            anchor = w

    # -- settings ---------------------------------------------------------------------------------
    @property
    def live(self) -> bool:
        return self.live_button.get_active()

    def target_fps(self) -> float:
        return float(FPS_CHOICES[min(self._fps_choice, len(FPS_CHOICES) - 1)])

    def target_quality(self) -> int | None:
        choice = QUALITY_CHOICES[min(self._quality_choice, len(QUALITY_CHOICES) - 1)]
        return int(choice) if choice.isdigit() else None

    def _settings_popup(self, button: Gtk.MenuButton) -> None:
        """GTK asks before the gear's popover shows: its drop-downs are made once, the first time."""
        popover = button.get_popover()
        if self.fps is not None or popover is None:
            return
        self.fps = Gtk.DropDown.new_from_strings([_("{n} fps").format(n=n) for n in FPS_CHOICES])
        self.fps.set_selected(self._fps_choice)
        self.fps.set_tooltip_text(_("Frames per second at most"))
        self.quality = Gtk.DropDown.new_from_strings([f"Q {q}" for q in QUALITY_CHOICES])
        self.quality.set_selected(self._quality_choice)
        self.quality.set_tooltip_text(_("JPEG quality to ask the server for"))
        accessible.name(self.fps, _("Frame rate"))
        accessible.name(self.quality, _("JPEG quality"))
        self.fps.connect("notify::selected", lambda d, _p: self._chosen(fps=d.get_selected()))
        self.quality.connect("notify::selected", lambda d, _p: self._chosen(quality=d.get_selected()))
        settings = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        settings.append(self.fps)
        settings.append(self.quality)
        popover.set_child(settings)

    def _chosen(self, *, fps: int | None = None, quality: int | None = None) -> None:
        if fps is not None:
            self._fps_choice = fps
        if quality is not None:
            self._quality_choice = quality
        self._settings_changed()

    def set_live(self, on: bool) -> None:
        self.live_button.set_active(on)

    def toggle(self, available: bool, reason: str) -> str:
        """The Live key (V): on where the server has a camera, off always; why not, "" when done."""
        if not self.live and not available:
            return reason or _("no camera")
        self.set_live(not self.live)
        return ""

    def _paused(self, paused: bool) -> None:
        """A paused frame's caption no longer counts its age: the bar's line does again."""
        self.camera.age_shown_elsewhere = self.live and not paused
        self._pause(paused)

    def _live_toggled(self, button: Gtk.ToggleButton) -> None:
        on = button.get_active()
        self.camera.age_shown_elsewhere = on  # the caption gives the frame's age: the bar gives none
        self.pause_button.set_sensitive(on)
        if not on:
            self.pause_button.set_active(False)
            self.caption.set_visible(False)
            self._stop()
        else:
            self._start(self.target_fps(), self.target_quality())

    def follow_selection(self, old: RobotSession, new: RobotSession) -> None:
        """Another robot is shown: its camera plays (the old one's video stops), at the same settings."""
        if self.live:
            old.controller.ask(StopVideo())
            self._start(self.target_fps(), self.target_quality())

    def _settings_changed(self) -> None:
        if self.live:
            self._start(self.target_fps(), self.target_quality())

    # -- frames -----------------------------------------------------------------------------------
    def shown(self, image: CameraImage) -> None:
        """A frame is on screen: keep it for Save, show its figures."""
        self.image = image
        self.save_button.set_sensitive(True)
        status = image.video
        # Only while the page is on screen: a label changing on a hidden page still re-lays out the window.
        if status is not None and self.live and self.camera.get_mapped():
            if image.stamp_ns is not None:  # its age now, on screen (the feed's is at arrival)
                status = replace(status, age_ms=max(time.time_ns() - image.stamp_ns, 0) / 1e6)
            text = status.caption()
            if self.pause_button.get_active():
                text += _(" · paused")
            self.caption.set_text(text)
            self.caption.set_visible(True)

    def when_painted(self, done: Callable[[], None], on_screen: bool) -> None:
        """Call ``done`` once the window has painted the frame just set (its frame clock's after-paint),
        or at once when no widget on screen shows it.

        The video loop asks for the next frame on ``done``: asked at hand-over, the next frame would
        arrive while this one is still waiting for its paint and queue behind it (the window's
        latency); asked after the paint, it arrives while the GTK thread is free. A newer frame's
        ``done`` replaces an older one's (it covers every frame before it).
        """
        root = self.camera.get_root()  # the window's clock (a hidden page may be unrealized)
        clock = root.get_frame_clock() if isinstance(root, Gtk.Widget) else None
        if not on_screen or clock is None:
            done()
            return
        self._after_paint = done
        if not self._paint_handler:
            self._paint_handler = clock.connect("after-paint", self._painted)

    def _painted(self, clock: Gdk.FrameClock) -> None:
        done, self._after_paint = self._after_paint, None
        clock.disconnect(self._paint_handler)
        self._paint_handler = 0
        if done is not None:
            done()

    def connection_lost(self) -> None:
        """No robot: no picture to save, and Live stays off until asked for again."""
        self.image = None
        self.save_button.set_sensitive(False)
        self.live_button.set_active(False)

    def save(self) -> Path | None:
        """Write the frame on screen (its exact JPEG bytes) to :func:`frames_dir`; say where."""
        image = self.image
        if image is None:
            return None
        folder = self.folder or frames_dir()
        stamp = time.strftime("%Y%m%dT%H%M%S", time.gmtime())
        path = folder / f"rtmu-frame-{stamp}-{image.sequence % 1_000_000:06d}.jpg"
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path.write_bytes(image.jpeg)
        except OSError as exc:
            self._tell("error", _("Could not save the frame: {value}").format(value=exc.strerror or exc))
            return None
        self.saved.append(path)
        self._tell("info", _("Frame saved: {path}").format(path=path))
        return path
