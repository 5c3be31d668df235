"""A cut-short picture that declares 8192×8192 pixels costs nothing; a real one is checked small.

The hostile picture (a real JPEG header claiming 8192×8192, a few bytes of data, its end marker:
about 600 bytes) made ``rtmu image`` decode and save 200 MB of grey with exit 0. Now it is refused
from its header (exit 3, nothing saved) and ``rtmu video`` does not play it. A true 8192×8192
picture (hand-coded: every block mid-grey, 768 kB) is still taken, checked at 1/8 scale. Peak
memory is each ``rtmu image`` process's own (``VmHWM``), against the same command on a 64×48 one.
"""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION
from rtmu.cli import main
from rtmu.client.jpeg_bounds import fill_problem, read_header
from rtmu.client.video_feed import BadFrame, check_frame

from .servers import ServerThread
from .test_image_hostile import jpeg, picture_server

SIDE = 8192
PEAK = (
    "import sys\n"
    "from rtmu.cli import main\n"
    "code = main(sys.argv[1:])\n"
    "with open('/proc/self/status') as status:\n"
    "    hwm = next(line.split()[1] for line in status if line.startswith('VmHWM:'))\n"
    "print(code, hwm, file=sys.stderr)\n"
)
LINUX = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM is Linux's")


def grey_header(side: int) -> bytes:
    """Pillow's header of a greyscale baseline JPEG (standard tables) with the frame size set to ``side``."""
    out = io.BytesIO()
    Image.new("L", (16, 16), 128).save(out, "JPEG", quality=90)
    data = out.getvalue()
    header = read_header(data)
    assert header.data_at is not None and header.frame == 0xC0
    head = bytearray(data[: header.data_at])
    sof = head.index(b"\xff\xc0")
    head[sof + 5 : sof + 9] = side.to_bytes(2, "big") * 2  # height, width
    return bytes(head)


def cut_short(side: int = SIDE) -> bytes:
    return grey_header(side) + b"\x28\xa2\x8a" * 10 + b"\xff\xd9"


def whole_grey(side: int = SIDE) -> bytes:
    """A true ``side``² picture: each block is DC "no change" (00) and end-of-block (1010), 6 bits."""
    blocks = (side // 8) ** 2
    return grey_header(side) + b"\x28\xa2\x8a" * (blocks // 4) + b"\xff\xd9"


def image_measured(port: int, out: Path) -> tuple[int, float, str]:
    args = ["image", f"127.0.0.1:{port}", "--out", str(out), "--timeout", cli_timeout(5)]
    done = subprocess.run([sys.executable, "-c", PEAK, *args], capture_output=True, text=True, timeout=120)
    code, hwm = done.stderr.split()[-2:]
    return int(code), int(hwm) / 1024, done.stderr


def test_the_header_tells_a_cut_short_picture_from_a_whole_one() -> None:
    short, whole = cut_short(), whole_grey()
    assert len(short) < 1000 and read_header(short).size == (SIDE, SIDE)
    problem = fill_problem(short)
    assert problem is not None and "cut short" in problem and "8192x8192" in problem
    assert fill_problem(whole) is None
    with Image.open(io.BytesIO(whole_grey(64))) as img:  # the hand-coded picture is a real JPEG
        img.load()
        assert img.size == (64, 64) and img.getpixel((10, 10)) == 128
    for small in (jpeg(64, 48), jpeg(320, 240), jpeg(1, 1)):
        assert fill_problem(small) is None
    arithmetic = bytearray(jpeg(64, 48))
    arithmetic[arithmetic.index(b"\xff\xc0") + 1] = 0xC9
    assert "arithmetic-coded" in (fill_problem(bytes(arithmetic)) or "")


def test_rtmu_video_does_not_play_a_cut_short_picture() -> None:
    with pytest.raises(BadFrame, match="cut short"):
        check_frame(cut_short(), SIDE, SIDE)
    check_frame(whole_grey(64), 64, 64)


def test_rtmu_video_reports_the_frames_as_dropped(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    with ServerThread(picture_server(SIDE, SIDE, cut_short())) as running:
        main(["video", f"127.0.0.1:{running.port}", "--seconds", "1.5", "--json", "--timeout", "3"])
    out = capsys.readouterr()
    summary = json.loads(out.out.strip().splitlines()[-1])
    assert summary["frames"] == 0 and "cut short" in out.err


@LINUX
def test_rtmu_image_refuses_a_cut_short_8192_picture_at_no_cost_and_saves_nothing(tmp_path: Path) -> None:
    with ServerThread(picture_server(64, 48, jpeg(64, 48))) as running:
        code, base_mb, err = image_measured(running.port, tmp_path / "small.jpg")
    assert code == 0, err
    out = tmp_path / "short.jpg"
    with ServerThread(picture_server(SIDE, SIDE, cut_short())) as running:
        code, peak_mb, err = image_measured(running.port, out)
    assert code == EXIT_CONNECTION and "cut short" in err and "nothing saved" in err, err
    assert not out.exists()
    assert peak_mb - base_mb < 16, f"refusing it cost {peak_mb - base_mb:.0f} MB"


CHECK = (
    "import io, sys\n"
    "from pathlib import Path\n"
    "from PIL import Image, ImageFile  # imported first: the figures are the work, not the libraries\n"
    "from rtmu.client.jpeg_bounds import decode_problem\n"
    "data = Path(sys.argv[1]).read_bytes()\n"
    "def hwm():\n"
    "    with open('/proc/self/status') as status:\n"
    "        return int(next(line.split()[1] for line in status if line.startswith('VmHWM:')))\n"
    "before = hwm()\n"
    "if sys.argv[2] == 'check':\n"
    "    assert decode_problem(data) is None\n"
    "else:\n"
    "    Image.open(io.BytesIO(data)).load()\n"
    "print(hwm() - before)\n"
)


@LINUX
def test_checking_a_whole_8192_picture_costs_a_fraction_of_decoding_it(tmp_path: Path) -> None:
    """The check reads all of a true 8192×8192 picture's data at 1/8 scale: under a tenth of its pixels."""
    path = tmp_path / "grey.jpg"
    path.write_bytes(whole_grey())

    def grown(mode: str) -> float:
        done = subprocess.run(
            [sys.executable, "-c", CHECK, str(path), mode], capture_output=True, text=True, timeout=120
        )
        assert done.returncode == 0, done.stderr
        return int(done.stdout.split()[-1]) / 1024

    full, check = grown("full"), grown("check")
    assert full > 60, f"a full decode of 8192x8192 grey holds 64 MB of pixels ({full:.0f} MB)"
    assert check < full / 10, f"the check grew {check:.1f} MB, a full decode {full:.0f} MB"
