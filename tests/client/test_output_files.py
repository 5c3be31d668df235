"""Files the operator names: checked before connecting, never lost, written in the format asked for.

``map --out``, ``image --out``, ``video --out`` and ``record --out`` against a port where nothing
listens must fail on the path itself (exit 2, a plain line) — proof that they looked before
connecting; against the simulator they keep an existing file unless ``--force`` and then write
it whole; ``image`` writes what the file name asks for.
"""

from __future__ import annotations

import socket
from pathlib import Path

import pytest
from PIL import Image

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from simulators import simulator

REPO = Path(__file__).resolve().parents[2]
ARENA = project_map("arena.map")


sim = simulator(scope="module", map_path=ARENA)


def nowhere() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"127.0.0.1:{s.getsockname()[1]}"


@pytest.mark.parametrize("command", ["map", "image", "record"])
@pytest.mark.parametrize("case", ["a directory", "no such folder", "exists"])
def test_a_bad_output_path_fails_before_connecting(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, case: str
) -> None:
    ending = {"map": "x.map", "image": "x.jpg", "record": "x.mcap"}[command]
    if case == "a directory":
        target = tmp_path / ending
        target.mkdir()
    elif case == "no such folder":
        target = tmp_path / "missing" / ending
    else:
        target = tmp_path / ending
        target.write_bytes(b"keep me")
    argv = {"map": ["map"], "image": ["image"], "record": ["record", "--seconds", "1"]}[command]
    assert main([*argv, nowhere(), "--out", str(target), "--timeout", "2"]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Errno" not in err and "refused" not in err, err
    expected = {"a directory": "is a directory", "no such folder": "does not exist", "exists": "--force"}
    assert expected[case] in err
    if case == "exists":
        assert target.read_bytes() == b"keep me"


def test_video_checks_its_folder_before_connecting(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a_file = tmp_path / "frames"
    a_file.write_bytes(b"")
    assert main(["video", nowhere(), "--out", str(a_file), "--timeout", "2"]) == EXIT_USAGE
    assert "is a file, not a folder" in capsys.readouterr().err
    earlier = tmp_path / "earlier"
    earlier.mkdir()
    (earlier / "frame_000001.jpg").write_bytes(b"an earlier run")
    assert main(["video", nowhere(), "--out", str(earlier), "--timeout", "2"]) == EXIT_USAGE
    assert "--force" in capsys.readouterr().err
    assert (earlier / "frame_000001.jpg").read_bytes() == b"an earlier run"


def test_map_keeps_an_existing_file_unless_forced_then_writes_it_whole(
    sim: SimThread, tmp_path: Path
) -> None:
    out = tmp_path / "arena.map"
    out.write_text("an older map\n")
    assert (
        main(["map", f"127.0.0.1:{sim.port}", "--out", str(out), "--timeout", cli_timeout(5)]) == EXIT_USAGE
    )
    assert out.read_text() == "an older map\n"
    assert (
        main(["map", f"127.0.0.1:{sim.port}", "--out", str(out), "--force", "--timeout", cli_timeout(5)])
        == EXIT_OK
    )
    assert out.read_text().startswith("2D-Map")
    assert [p.name for p in tmp_path.iterdir()] == ["arena.map"], "no temporary file left behind"


@pytest.mark.parametrize(("name", "fmt"), [("cam.jpg", "JPEG"), ("cam.png", "PNG"), ("cam.bmp", "BMP")])
def test_image_writes_the_format_its_name_asks_for(
    sim: SimThread, tmp_path: Path, name: str, fmt: str
) -> None:
    out = tmp_path / name
    assert main(["image", f"127.0.0.1:{sim.port}", "--out", str(out), "--timeout", cli_timeout(5)]) == EXIT_OK
    with Image.open(out) as img:
        assert img.format == fmt and img.size == (320, 240)


def test_image_refuses_a_name_it_cannot_write(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for name in ("cam.xyz", "cam"):
        assert main(["image", nowhere(), "--out", str(tmp_path / name), "--timeout", "2"]) == EXIT_USAGE
        assert "name the picture FILE.jpg" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv",
    [
        ["image", "--quality", "-5"],
        ["image", "--quality", "101"],
        ["video", "--fps", "100"],
        ["video", "--fps", "0"],
        ["record", "--fps", "-5"],
        ["bridge", "--foxglove", "--fps", "31"],
        ["bridge", "--foxglove", "--camera-hz", "-5"],
    ],
)
def test_out_of_range_camera_values_are_refused_with_the_limits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str]
) -> None:
    out = {"image": ["--out", str(tmp_path / "x.jpg")], "record": ["--out", str(tmp_path / "x.mcap")]}
    with pytest.raises(SystemExit) as exc:
        main([argv[0], nowhere(), *argv[1:], *out.get(argv[0], [])])
    assert exc.value.code == EXIT_USAGE
    err = capsys.readouterr().err
    assert "out of range: use" in err, err


def test_a_quality_in_range_reaches_the_camera(sim: SimThread, tmp_path: Path) -> None:
    out = tmp_path / "q.jpg"
    code = main(
        ["image", f"127.0.0.1:{sim.port}", "--out", str(out), "--quality", "30", "--timeout", cli_timeout(5)]
    )
    assert code == EXIT_OK
    code = main(["image", f"127.0.0.1:{sim.port}", "--out", str(out), "--camera", "Nope", "--force"])
    assert code == EXIT_UNSUPPORTED


@pytest.mark.parametrize(
    ("argv", "limits"),
    [
        (["replay", "x.mcap", "--conn", "0"], "use 1…1000000"),
        (["status", "127.0.0.1:9", "--count", "-1"], "use 0…1000000000"),
        (["video", "127.0.0.1:9", "--fps", "100"], "use 0.5…30"),
    ],
)
def test_a_refusal_writes_its_limits_as_the_operator_types_them(
    capsys: pytest.CaptureFixture[str], argv: list[str], limits: str
) -> None:
    """A limit reads as a plain number: "use 1…1000000", never "use 1…1e+06"."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == EXIT_USAGE
    err = capsys.readouterr().err
    assert limits in err and "e+" not in err, err
