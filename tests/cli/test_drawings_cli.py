"""``rtmu drawings``: the simulator's ARIA drawings, and a hostile server's, as lines and JSON."""

from __future__ import annotations

import json

import pytest

from client.drawing_servers import MARKUP, MAX_POINTS_SENT, hostile_drawing_server
from client.servers import SPECS, ServerThread, TestServer
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_UNSUPPORTED
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from simulators import simulator

ARENA = project_map("arena.map")


sim = simulator(scope="module", map_path=ARENA)


def test_the_simulators_sonar_and_laser_with_a_sample_each(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    target = f"127.0.0.1:{sim.port}"
    assert main(["drawings", target, "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
    assert set(rows) == {"sim_lms2xx_1Current", "sonarCurrent"}
    laser, sonar = rows["sim_lms2xx_1Current"], rows["sonarCurrent"]
    assert (sonar["shape"], sonar["primary_color"], sonar["size"], sonar["layer"]) == (
        "polyArrows",
        "#33ccff",
        200,
        70,
    )
    assert (laser["shape"], laser["primary_color"], laser["size"], laser["layer"]) == (
        "polyDots",
        "#0000ff",
        80,
        75,
    )
    assert laser["refresh_ms"] == 200 and laser["visibility"] == "DefaultOn" and laser["drawn"]
    assert 0 < len(laser["points"]) <= 181 and len(sonar["points"]) <= 16
    assert all(len(p) == 2 for p in laser["points"]) and laser["error"] == ""
    assert main(["drawings", target, "--timeout", cli_timeout(5)]) == EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2
    assert lines[0].startswith(
        "sim_lms2xx_1Current  polyDots  #0000ff  size 80  layer 75  every 200 ms  DefaultOn  "
    )
    assert lines[0].endswith(f"{len(laser['points'])} points") or lines[0].endswith(" points")


def test_a_hostile_servers_drawings_are_listed_and_none_breaks_the_others(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with ServerThread(hostile_drawing_server()) as server:
        target = f"127.0.0.1:{server.port}"
        assert main(["drawings", target, "--json", "--timeout", "3"]) == EXIT_OK
        rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
        assert rows[MARKUP]["points"] == [[600, 2000], [1400, 2000]]  # the exact name, markup and all
        assert rows["blob"]["drawn"] is False
        assert rows["huge"]["points"] is None and "point count claims 1000000" in rows["huge"]["error"]
        assert len(rows["max"]["points"]) == len(MAX_POINTS_SENT)
        assert main(["drawings", target, "--timeout", "3"]) == EXIT_OK
        out = capsys.readouterr().out
        assert "blob  polyHexagons" in out and "(shape not known to RTMU: not drawn)" in out
        assert "huge  polyDots" in out and "no sample: the server sent a malformed 'huge' drawing" in out
        assert MARKUP in out


def test_a_server_without_drawings_exits_4(capsys: pytest.CaptureFixture[str]) -> None:
    with ServerThread(TestServer([r for r in SPECS if r[0] == "updateNumbers"])) as server:
        assert main(["drawings", f"127.0.0.1:{server.port}", "--timeout", "3"]) == EXIT_UNSUPPORTED
    assert "lists no drawings" in capsys.readouterr().err


def test_control_characters_in_a_name_are_escaped_on_the_terminal(capsys: pytest.CaptureFixture[str]) -> None:
    from rtmu.protocol.payloads.drawings import Drawing, DrawingListPacket, DrawingPoints

    evil = "evil\x1b[2J\r"
    specs = [*SPECS, ("getDrawingList", "", "none", "", "SensorInfo", "RETURN_UNTIL_EMPTY")]
    specs.append((evil, "", "none", "", "SensorInfo", "RETURN_SINGLE"))
    server = TestServer(specs)
    listing = [DrawingListPacket(Drawing(evil, "polyDots", 0, 1, 70, 200, 0, "DefaultOn")).encode(), b""]
    server.handlers["getDrawingList"] = lambda s, a: listing
    server.handlers[evil] = lambda s, a: [DrawingPoints().encode()]
    with ServerThread(server) as running:
        assert main(["drawings", f"127.0.0.1:{running.port}", "--timeout", "3"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\r" not in out and "evil\\x1b[2J\\r" in out
