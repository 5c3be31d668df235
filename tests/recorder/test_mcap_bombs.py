"""Hostile recordings stay bounded: a decompression bomb is refused before it is inflated.

The files are written byte by byte (:mod:`.mcapcraft`): a chunk that truly inflates to hundreds of
megabytes from a few kilobytes, one that lies about its size, and one of very many tiny packets.
``rtmu decode`` and ``rtmu replay`` run as processes; each reports its own peak memory (``VmHWM``),
held against the same command on a small honest recording.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from rtmu.capture.mcap_bounded import MAX_CHUNK_BYTES, MAX_RATIO, BoundedMcap, McapBoundError
from rtmu.recorder import replay_file
from rtmu.recorder.replay_file import ReplayFileError, load

from .mcapcraft import bomb, chunk, connection, mcap_file, message, raw_channels, zeros_zstd

PEAK = (
    "import os, sys\n"
    "from rtmu.cli import main\n"
    "sys.stdout = open(os.devnull, 'w')\n"
    "code = main(sys.argv[1:])\n"
    "with open('/proc/self/status') as status:\n"
    "    hwm = next(line.split()[1] for line in status if line.startswith('VmHWM:'))\n"
    "print(code, hwm, file=sys.stderr)\n"
)
LINUX = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM is Linux's")


def run_measured(*args: str) -> tuple[int, float, str]:
    """(exit code, peak resident MB, stderr) of ``rtmu ARGS`` in a fresh interpreter."""
    done = subprocess.run([sys.executable, "-c", PEAK, *args], capture_output=True, text=True, timeout=300)
    code, hwm = done.stderr.split()[-2:]
    return int(code), int(hwm) / 1024, done.stderr


def honest(tmp_path: Path) -> Path:
    packets = b"".join(message(2, n, 10 + n, b"\xfa\xfb\x04\x00\x0b\x00\x0b\x00") for n in range(50))
    return mcap_file(tmp_path / "honest.mcap", raw_channels(), chunk(connection() + packets))


@LINUX
def test_a_true_bomb_is_refused_by_decode_and_replay_before_it_is_inflated(tmp_path: Path) -> None:
    path = mcap_file(tmp_path / "bomb.mcap", raw_channels(), chunk(connection()), bomb(600 * 1024 * 1024))
    assert path.stat().st_size < 64 * 1024, "a few kilobytes…"
    with pytest.raises(McapBoundError, match="decompression bomb"), path.open("rb") as f:
        list(BoundedMcap(f).messages())
    _, base_mb, _ = run_measured("decode", str(honest(tmp_path)))
    code, peak_mb, err = run_measured("decode", str(path))
    assert code != 0 and "refused" in err and "before decompressing" in err, err
    assert peak_mb - base_mb < 48, f"decode grew {peak_mb - base_mb:.0f} MB on a refused file"
    with pytest.raises(ReplayFileError, match="decompression bomb"):
        load(path)
    replayed = subprocess.run(
        [sys.executable, "-m", "rtmu", "replay", str(path)], capture_output=True, text=True, timeout=120
    )
    assert replayed.returncode != 0 and "decompression bomb" in replayed.stderr, replayed.stderr


def test_a_chunk_that_claims_too_much_or_too_many_times_its_size_is_refused_unread(tmp_path: Path) -> None:
    big = chunk(b"", compressed=b"\x00" * 1024, claimed=MAX_CHUNK_BYTES + 1)
    path = mcap_file(tmp_path / "big.mcap", raw_channels(), big)
    with pytest.raises(McapBoundError, match=r"claims 67\.1 MB"), path.open("rb") as f:
        list(BoundedMcap(f).messages())
    ratio = chunk(b"", compressed=b"\x00" * 10_000, claimed=10_000 * MAX_RATIO + 70_000)
    path = mcap_file(tmp_path / "ratio.mcap", raw_channels(), ratio)
    with pytest.raises(McapBoundError, match=f"over {MAX_RATIO}×"), path.open("rb") as f:
        list(BoundedMcap(f).messages())
    budget = mcap_file(tmp_path / "budget.mcap", raw_channels(), *[chunk(connection())] * 3)
    with pytest.raises(McapBoundError, match="claim over"), budget.open("rb") as f:
        list(BoundedMcap(f, budget=150).messages())


@LINUX
def test_a_chunk_that_hides_its_size_is_inflated_no_further_than_it_claims(tmp_path: Path) -> None:
    """Claims 1 000 bytes, holds 300 MB of zeros: the reader stops at byte 1 001 and says so."""
    lying = chunk(b"", compressed=zeros_zstd(300 * 1024 * 1024), claimed=1000)
    path = mcap_file(tmp_path / "lying.mcap", raw_channels(), chunk(connection()), lying)
    with (
        pytest.raises(McapBoundError, match="claims 1000 bytes uncompressed but holds more"),
        path.open("rb") as f,
    ):
        list(BoundedMcap(f).messages())
    _, base_mb, _ = run_measured("decode", str(honest(tmp_path)))
    code, peak_mb, err = run_measured("decode", str(path))
    assert code != 0 and "holds more" in err, err
    assert peak_mb - base_mb < 48, f"decode grew {peak_mb - base_mb:.0f} MB"


@LINUX
def test_very_many_tiny_packets_decode_in_bounded_memory_and_a_replay_counts_what_it_holds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """200 000 eight-byte packets (the 23 kB file that took decode to 7.5 GB was of this kind)."""
    packet = b"\xfa\xfb\x04\x00\x0b\x00\x0b\x00"
    per_chunk = 10_000
    chunks = [
        chunk(b"".join(message(2, n, 10 + n, packet) for n in range(k * per_chunk, (k + 1) * per_chunk)))
        for k in range(20)
    ]
    path = mcap_file(tmp_path / "tiny.mcap", raw_channels(), chunk(connection()), *chunks)
    _, base_mb, _ = run_measured("decode", "--json", str(honest(tmp_path)))
    code, peak_mb, err = run_measured("decode", "--json", str(path))
    assert code == 0, err
    assert peak_mb - base_mb < 64, f"decode grew {peak_mb - base_mb:.0f} MB for 200 000 tiny packets"
    monkeypatch.setattr(replay_file, "MAX_REPLAY_BYTES", 8 * 1024 * 1024)  # each chunk counts its keeping
    with pytest.raises(ReplayFileError, match="tiny chunks"):
        load(path)
