"""A drawing list that asks too much is bounded and said, and nothing after it is lost.

A scripted server over loopback lists a drawing whose refresh period (2³²−1 ms) no request can
carry, then one more in layer order; another lists 300 drawings, more than RTMU keeps (256).
"""

from __future__ import annotations

import json

import pytest

from rtmu.base.exit_codes import EXIT_OK
from rtmu.cli import main
from rtmu.client.drawings_feed import MAX_REFRESH_MS
from rtmu.protocol.payloads.drawings import MAX_DRAWINGS

from .drawing_servers import AFTER, FOREVER, drawings_server, many
from .servers import ServerThread
from .test_drawings_feed import Rig


def test_a_period_over_2_31_ms_is_asked_for_as_the_longest_one_and_the_next_drawing_still_is(
    caplog: pytest.LogCaptureFixture,
) -> None:
    with ServerThread(drawings_server((FOREVER, AFTER))) as server:
        rig = Rig(server.port)
        try:
            rig.wait(lambda: rig.layer("after") is not None and rig.layer("after").points == ((1, 2),))
            rig.wait(lambda: {"forever", "after"} <= {r.name for r in server.received})
            asked = {r.name: r.kind for r in server.received}
            assert asked["forever"] == f"request {MAX_REFRESH_MS}", "the longest period a request can say"
            assert rig.layer("forever").problem == "" and rig.layer("forever").refresh_ms == MAX_REFRESH_MS
        finally:
            rig.close()
    assert "Traceback" not in caplog.text and "does not fit" not in caplog.text


def test_rtmu_drawings_with_300_drawings_prints_the_256_it_keeps_and_says_what_it_left_out(
    capsys: pytest.CaptureFixture[str],
) -> None:
    drawings = many(300)
    with ServerThread(drawings_server(drawings)) as server:
        target = f"127.0.0.1:{server.port}"
        assert main(["drawings", target, "--timeout", "3"]) == EXIT_OK
        out = capsys.readouterr()
        lines = out.out.strip().splitlines()
        assert len(lines) == MAX_DRAWINGS and lines[0].startswith("d000") and lines[-1].startswith("d255")
        assert "300 drawings" in out.err and "44 left out" in out.err
        assert main(["drawings", target, "--json", "--timeout", "3"]) == EXIT_OK
        rows = json.loads(capsys.readouterr().out)
        assert [r["name"] for r in rows] == [d.name for d in drawings[:MAX_DRAWINGS]]


def test_the_window_keeps_256_drawings_and_notes_the_rest() -> None:
    with ServerThread(drawings_server(many(300))) as server:
        rig = Rig(server.port)
        try:
            rig.wait(lambda: len(rig.model.drawings.value.layers) == MAX_DRAWINGS)
            assert "44 left out" in rig.model.drawings.value.note
        finally:
            rig.close()
