"""``rtmu decode`` on the biggest real capture (columbia map: 63 954 packets, 63 824 of them getMap).

Figures: packets decoded per second with typed payloads (baseline: framing and
names only, no payload types), the whole command's wall time in text and JSON
mode (interpreter start included), and its peak memory on the capture and on
a capture five times longer — memory must not grow with the capture.
"""

from __future__ import annotations

import os
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.common import Result, best_time
from rtmu.capture import open_capture
from rtmu.capture.session_decoder import CaptureDecoder

CAPTURE = Path(__file__).resolve().parents[1] / "tests" / "data" / "captures" / "map-binary-columbia.pcap"

# The child's own high-water mark. Not getrusage's ru_maxrss: Linux carries that across fork and exec,
# so every child reported the benchmark process's peak (all figures were equal). VmHWM belongs to the
# address space, which exec replaces.
_PEAK = (
    "import os, sys\n"
    "from rtmu.cli import main\n"
    "sys.stdout = open(os.devnull, 'w')\n"
    "main(sys.argv[1:])\n"
    "with open('/proc/self/status') as status:\n"
    "    print(next(line.split()[1] for line in status if line.startswith('VmHWM:')), file=sys.stderr)\n"
)


def _count(decode_payloads: bool) -> int:
    return sum(1 for _ in CaptureDecoder(decode_payloads=decode_payloads).run(open_capture(CAPTURE).events()))


def _wall(args: list[str], repeat: int = 3) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "rtmu", *args], stdout=subprocess.DEVNULL, check=True)
        best = min(best, time.perf_counter() - t0)
    return best


def _peak_mb(args: list[str]) -> float:
    done = subprocess.run([sys.executable, "-c", _PEAK, *args], capture_output=True, text=True, check=True)
    return int(done.stderr.split()[-1]) / 1024  # VmHWM is in kB


def _repeated(copies: int, out: Path) -> None:
    """The capture played ``copies`` times, each copy on other client ports: new connections, same content."""
    data = CAPTURE.read_bytes()
    header, records = data[:24], []
    pos = 24
    while pos + 16 <= len(data):
        sec, usec, incl, orig = struct.unpack_from("<IIII", data, pos)
        records.append((sec, usec, orig, data[pos + 16 : pos + 16 + incl]))
        pos += 16 + incl
    body = bytearray(header)
    for k in range(copies):
        for sec, usec, orig, frame in records:
            frame = bytearray(frame)
            ihl = (frame[14] & 0x0F) * 4
            for at in (14 + ihl, 14 + ihl + 2):  # TCP source and destination ports
                (port,) = struct.unpack_from(">H", frame, at)
                if port != 17400:
                    struct.pack_into(">H", frame, at, port + 97 * k)
            body += struct.pack("<IIII", sec + 10 * k, usec, len(frame), orig) + frame
    out.write_bytes(bytes(body))


def run() -> list[Result]:
    packets = _count(True)
    typed = best_time(lambda: _count(True), repeat=3, min_seconds=0.5)
    framing = best_time(lambda: _count(False), repeat=3, min_seconds=0.5)
    results = [
        Result("decode.columbia_packets_per_s", packets / typed, "packets/s", baseline=packets / framing),
        Result("decode.columbia_cli_json_s", _wall(["decode", "--json", str(CAPTURE)]), "s"),
        Result("decode.columbia_cli_text_s", _wall(["decode", str(CAPTURE)]), "s"),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        five = Path(tmp) / "columbia-x5.pcap"
        _repeated(5, five)
        small_mb = _peak_mb(["decode", "--json", str(CAPTURE.with_name("strings.pcap"))])
        one_mb = _peak_mb(["decode", "--json", str(CAPTURE)])
        five_mb = _peak_mb(["decode", "--json", str(five)])
        os.remove(five)
    # baseline: the same command on a 95-frame capture, i.e. the interpreter and its imports
    results.append(Result("decode.columbia_json_peak_rss_mb", one_mb, "MiB", baseline=small_mb))
    results.append(Result("decode.columbia_x5_json_peak_rss_mb", five_mb, "MiB", baseline=one_mb))
    return results
