"""A server that answers the camera request with something that is not a picture: the real window
shows a plain-words reason (no Python object names or addresses), stays usable, and the map comes back."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from rtmu.protocol.fields import FieldWriter

from .harness import Gui, pump

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from client.servers import ServerThread, TestServer

JPEG_START, JPEG_END = b"\xff\xd8", b"\xff\xd9"
REPLIES = {
    "not-a-picture": b"<html>this is not a picture</html>" * 20 + JPEG_END,
    "cut-short": JPEG_START + b"\xff\xe0\x00\x10JFIF\x00" + b"\x00" * 40 + JPEG_END,
}


@pytest.mark.parametrize("kind", list(REPLIES))
def test_a_non_picture_is_reported_in_plain_words(screenshots: Path, kind: str) -> None:
    server = TestServer()
    body = REPLIES[kind]
    server.handlers["getPictureCam1"] = lambda side, args: [
        FieldWriter().ubyte2(640).ubyte2(480).bytes() + body
    ]
    with ServerThread(server) as running:
        gui = Gui.start(screenshots, f"camera-{kind}", "127.0.0.1", running.port)
        try:
            window = gui.window
            gui.key("Escape")
            pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
            pump(lambda: bool(window.camera.error), 8, "the picture to fail")
            gui.shot(f"camera-error-{kind}")
            text = window.camera.error
            assert text.startswith("The picture could not be shown:"), text
            assert not re.search(r"0x[0-9a-fA-F]{6,}|object at|<\w+[.\w]*>|Traceback|Error\b", text), text
            assert window.camera.texture is None
            gui.key("Escape")  # the window still answers: back to the map
            pump(lambda: window.stack.get_visible_child_name() == "map", 3, "the map page")
        finally:
            gui.close()
