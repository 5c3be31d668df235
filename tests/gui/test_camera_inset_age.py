"""The map's camera inset never passes an old picture for the robot's view (issue 21).

A picture older than ``INSET_OLD_AFTER`` is greyed and called old; a new one is fresh again; a lost
link says so. The inset is built alone (a real GTK widget and texture) with a clock the test moves.
"""

from __future__ import annotations

import gi

gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib  # noqa: E402

from rtmu.ui.camera import INSET_OLD_AFTER, CameraInset  # noqa: E402


def _texture() -> Gdk.Texture:
    pixels = GLib.Bytes.new(bytes([90, 120, 160, 255] * 16 * 12))
    return Gdk.MemoryTexture.new(16, 12, Gdk.MemoryFormat.R8G8B8A8, pixels, 16 * 4)


def test_an_old_picture_is_greyed_and_called_old() -> None:
    now = [100.0]
    inset = CameraInset(lambda: None, clock=lambda: now[0])
    inset.show_texture(_texture(), received_at=100.0)
    now[0] = 101.0
    inset.tick()
    assert not inset.has_css_class("stale") and inset.age_label.get_text() == "1 s"  # whole seconds
    now[0] = 100.0 + INSET_OLD_AFTER + 240.0  # minutes later, the robot driving on
    inset.tick()
    assert inset.has_css_class("stale"), "an old picture looks fresh"
    assert inset.age_label.get_text().startswith("old picture · 4 min"), inset.age_label.get_text()
    inset.show_texture(_texture(), received_at=now[0])  # a new picture: fresh again
    assert not inset.has_css_class("stale") and not inset.age_label.get_text().startswith("old")
    inset.set_live(False)
    assert inset.has_css_class("stale") and inset.age_label.get_text().endswith("link lost")
    inset.set_live(True)
    assert not inset.has_css_class("stale")
