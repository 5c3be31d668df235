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


def test_live_video_drops_bad_frames_with_a_note_and_plays_on(screenshots: Path) -> None:
    import io
    import itertools

    from PIL import Image

    def jpeg(shade: int) -> bytes:
        out = io.BytesIO()
        Image.new("RGB", (320, 240), (shade, 90, 160)).save(out, "JPEG")
        return out.getvalue()

    good = [jpeg(40 * i) for i in range(5)]
    huge = (
        good[4][: good[4].index(b"\xff\xc0") + 5]
        + b"\xea\x60\xea\x60"
        + good[4][good[4].index(b"\xff\xc0") + 9 :]
    )
    frames = itertools.cycle(
        [good[0], REPLIES["not-a-picture"], good[1], good[2][: len(good[2]) // 2], good[3], huge, good[4]]
    )
    server = TestServer()
    server.handlers["getPictureCam1"] = lambda side, args: [
        FieldWriter().ubyte2(320).ubyte2(240).bytes() + next(frames)
    ]
    with ServerThread(server) as running:
        gui = Gui.start(screenshots, "live-hostile", "127.0.0.1", running.port)
        try:
            window = gui.window
            gui.key("Escape")
            pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
            gui.click(window.live.live_button)
            pump(
                lambda: window.camera.image is not None and window.camera.image.video is not None,
                8,
                "a frame",
            )
            first = window.camera.image.sequence  # type: ignore[union-attr]
            pump(lambda: window.camera.image.sequence >= first + 6, 15, "good frames to keep coming")  # type: ignore[union-attr]
            pump(lambda: "dropped" in window.live.caption.get_text(), 5, "the note about dropped frames")
            caption = window.live.caption.get_text()
            assert re.search(r"not a JPEG|cut short|60000x60000", caption), caption
            assert window.camera.texture is not None
            gui.shot("live-with-bad-frames")
            gui.key("Escape")
            pump(lambda: window.stack.get_visible_child_name() == "map", 3, "the window still answers")
        finally:
            gui.close()
