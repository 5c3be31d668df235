"""``rtmu image`` decodes the picture before saving: anything that is not a sane JPEG fails (exit 3).

A hostile test server of our own answers ``getPictureCam1`` with a ``ubyte2`` width, ``ubyte2``
height and then the bytes under test, over real loopback sockets.
"""

from __future__ import annotations

import io
import re

import pytest
from PIL import Image

from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK
from rtmu.cli import main

from .servers import ServerSide, ServerThread, TestServer


def jpeg(width: int, height: int) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", (width, height), (40, 90, 160)).save(out, "JPEG")
    return out.getvalue()


def picture_server(width: int, height: int, data: bytes) -> TestServer:
    server = TestServer()
    payload = width.to_bytes(2, "little") + height.to_bytes(2, "little") + data

    def answer(side: ServerSide, args: bytes) -> None:
        side.conn.send_data("getPictureCam1", payload)
        side.writer.write(side.conn.data_to_send())

    server.handlers["getPictureCam1"] = answer
    return server


def run_image(server: TestServer, out, capsys) -> tuple[int, str]:  # type: ignore[no-untyped-def]
    with ServerThread(server) as running:
        code = main(["image", f"127.0.0.1:{running.port}", "--out", str(out), "--timeout", "3"])
    return code, capsys.readouterr().err


@pytest.mark.parametrize(
    ("width", "height", "data", "words"),
    [
        (64, 48, b"\x89PNG not a jpeg at all" * 20, "not a complete JPEG"),
        (64, 48, jpeg(32, 24), "says 64x48 but the picture is 32x24"),
        (30000, 30000, jpeg(64, 48), "over the 8192x8192 limit"),
        (64, 48, jpeg(64, 48)[:200], "not a complete JPEG"),
    ],
    ids=["not-jpeg", "lying-size", "huge-claim", "truncated"],
)
def test_a_bad_picture_is_refused_and_nothing_saved(width, height, data, words, tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "p.jpg"
    code, err = run_image(picture_server(width, height, data), out, capsys)
    assert code == EXIT_CONNECTION
    assert words in err and "nothing saved" in err
    assert not re.search(r"0x[0-9a-f]{6,}|object at|<\w+\.", err)
    assert not out.exists()


def test_a_sane_jpeg_is_saved_byte_for_byte(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    data = jpeg(64, 48)
    out = tmp_path / "p.jpg"
    code, err = run_image(picture_server(64, 48, data), out, capsys)
    assert code == EXIT_OK, err
    assert out.read_bytes() == data
    assert "64x48" in err
