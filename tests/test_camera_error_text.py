"""The window's camera error (``decode_jpeg``'s message, shown verbatim after "The picture could
not be shown:") is plain words: no Python object names or addresses for a non-picture."""

from __future__ import annotations

import io
import re

import pytest
from PIL import Image

from rtmu.ui.camera import decode_jpeg


def _jpeg() -> bytes:
    out = io.BytesIO()
    Image.new("RGB", (64, 48)).save(out, "JPEG")
    return out.getvalue()


@pytest.mark.parametrize("data", [b"not a picture" * 10, _jpeg()[:150]], ids=["not-a-picture", "truncated"])
def test_the_error_text_names_no_python_object(data: bytes) -> None:
    with pytest.raises(ValueError) as caught:
        decode_jpeg(data)
    text = str(caught.value)
    assert not re.search(r"0x[0-9a-fA-F]{6,}|object at|<\w+[.\w]*", text), text
    assert "picture" in text
