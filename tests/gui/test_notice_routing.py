"""Notices reach the window by their kind, never by their words.

A message the server raises for the operator that happens to mention the camera
stays a server message: it gets its own banner and does not fail a picture request
that is under way. A real camera notice, through the same path, does.
"""

from __future__ import annotations

from rtmu.base.notices import Kind, Notice
from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump

SERVER_TEXT = "The camera picture on the dock is dirty: please clean it"


sim = simulator(map_path=OFFICE_MAP, seed=1)


def raise_from_network(gui: Gui, notice: Notice) -> None:
    """Send ``notice`` the way the network thread does: posted by the runner, through the controller."""
    session = gui.app.session
    assert session is not None
    session.runner.submit(lambda: session.runner._notice(notice)).result(5)


def test_a_server_text_about_the_camera_is_not_a_camera_notice(gui: Gui) -> None:
    window = gui.window
    window.camera.requesting()  # a picture is on its way
    raise_from_network(gui, Notice.warning(Kind.SERVER, SERVER_TEXT))
    pump(lambda: window.banners.text(f"notice:{SERVER_TEXT}") == SERVER_TEXT, 3, "the server's banner")
    gui.shot("server-text")
    assert window.banners.text("camera") is None, "the server's text was taken for a camera notice"
    assert window.camera.waiting and not window.camera.error, "the picture request was failed by it"

    raise_from_network(gui, Notice.error(Kind.CAMERA, "no picture: the camera is off"))
    pump(lambda: window.banners.text("camera") is not None, 3, "the camera banner")
    assert not window.camera.waiting and "camera is off" in window.camera.error
