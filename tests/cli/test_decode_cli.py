"""``rtmu decode`` end to end, as a subprocess: pcap, pcapng, hex dump and raw bytes, text and JSON."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from capture_builders import (
    Conversation,
    catalogue,
    pcap_file,
    pcapng_file,
    server_greeting,
    update_numbers,
)
from rtmu.base.exit_codes import EXIT_BAD_FILE, EXIT_SIGPIPE, EXIT_USAGE
from rtmu.protocol.packet import encode_packet
from testdata import CAPTURES

PACKET_KEYS = {"conn", "dir", "command", "name", "length", "checksum_ok", "fields"}


def rtmu(*args: str | Path, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rtmu", "decode", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


def json_lines(out: str) -> list[dict]:
    return [json.loads(line) for line in out.splitlines()]


def server_stream() -> bytes:
    """What a server sends: introduction, CONNECTED, the lists, then updateNumbers and a map line."""
    datalist = catalogue(["updateNumbers", "getMap"])
    intro, lists = server_greeting(datalist)
    return intro + lists + encode_packet(256, update_numbers(x=1234)) + encode_packet(257, b"2D-Map\x00")


def xxd(data: bytes) -> str:
    lines = []
    for off in range(0, len(data), 16):
        chunk = data[off : off + 16]
        hexpart = " ".join(chunk[i : i + 2].hex() for i in range(0, len(chunk), 2))
        text = "".join(chr(b) if 32 <= b < 127 else "." for b in chunk)
        lines.append(f"{off:08x}: {hexpart:<39}  {text}")
    return "\n".join(lines) + "\n"


def damaged_stream() -> tuple[bytes, bytes, bytes]:
    bad = bytearray(encode_packet(300, b"hello"))
    bad[-2] ^= 0x40  # corrupt the checksum
    good = encode_packet(5)
    return b"\xde\xad\xbe\xef" + bytes(bad) + good, bytes(bad), good


# -- pcap ------------------------------------------------------------------------------
def test_pcap_text_shows_packets_fields_and_summary():
    result = rtmu(CAPTURES / "drive-tcponly.pcap")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    out = result.stdout
    assert out.startswith("# drive-tcponly.pcap: pcap, link type 1 (Ethernet)")
    assert "ratioDrive" in out and "trans=50 rot=0 throttle=100" in out and "trans=0 rot=20" in out
    assert "REQUEST" in out and "data_name='updateNumbers' interval_ms=100" in out
    assert "c2s tcp        5 TCP_ONLY" in out and "s2c tcp        5 CONNECTED" in out
    assert "== summary" in out and "client 127.0.0.1:41882  server 127.0.0.1:17400" in out
    assert "dropped: nothing" in out


def test_pcap_json_has_every_packet_with_the_agreed_keys():
    result = rtmu("--json", CAPTURES / "strings.pcap")
    assert result.returncode == 0, result.stderr
    records = json_lines(result.stdout)
    assert len(records) == 82
    for r in records:
        assert r.keys() >= PACKET_KEYS
        assert r["dir"] in ("c2s", "s2c") and r["checksum_ok"] is True and isinstance(r["fields"], dict)
        assert isinstance(r["command"], int) and isinstance(r["length"], int) and r["conn"] == 1
    udp = [r for r in records if r["transport"] == "udp"]
    assert len(udp) == 62 and {r["name"] for r in udp} == {"UDP_INTRODUCTION", "updateNumbers"}
    info = next(r for r in records if r["name"] == "getStringsInfo" and r["dir"] == "s2c")
    assert "Motor Packet Count" in json.dumps(info["fields"])
    assert records[0]["time"] < records[-1]["time"]


def test_big_capture_json_prints_every_packet_and_text_folds_the_map():
    result = rtmu("--json", CAPTURES / "map-binary-columbia.pcap")
    assert result.returncode == 0, result.stderr
    records = json_lines(result.stdout)
    assert len(records) == 63954
    assert sum(r["name"] == "getMap" for r in records) == 63824
    assert sum(
        r["fields"].get("count", 0) for r in records if r["name"] == "getMapBinary" and r["conn"] == 1
    ) == (63311 + 470)
    text = rtmu(CAPTURES / "map-binary-columbia.pcap")
    assert text.returncode == 0
    assert len(text.stdout.splitlines()) < 100
    assert "… 63818 more getMap packets" in text.stdout
    assert "line='2D-Map'" in text.stdout and "(end of reply)" in text.stdout


def test_all_prints_every_packet_and_filters_select():
    folded = rtmu(CAPTURES / "map-binary.pcap").stdout
    full = rtmu("--all", "--no-summary", CAPTURES / "map-binary.pcap").stdout
    assert "more getMap packets" in folded and "(--all shows them)" not in full
    assert len(full.splitlines()) == 2 + 149  # two header lines, then every packet
    picked = json_lines(
        rtmu("--json", "--conn", "2", "--name", "getMap", CAPTURES / "map-binary.pcap").stdout
    )
    assert len(picked) == 113 and {(r["conn"], r["name"]) for r in picked} == {(2, "getMap")}


def test_json_summary_lines_on_request():
    records = json_lines(rtmu("--json", "--summary", CAPTURES / "robotUpdateExample-serverDemo.pcap").stdout)
    summary = [r for r in records if r.get("kind") == "summary"]
    assert len(summary) == 1 and summary[0]["udp_datagrams"] == 61
    assert summary[0]["directions"]["s2c"]["by_name"]["updateNumbers"] == 58
    assert records[-1]["kind"] == "capture" and records[-1]["frames"] == 81


def test_pcapng_is_decoded(tmp_path):
    conv = Conversation().handshake().send(False, server_stream()).close()
    path = tmp_path / "s.pcapng"
    path.write_bytes(pcapng_file(conv.frames(), nano=True))
    records = json_lines(rtmu("--json", path).stdout)
    assert [r["name"] for r in records][-2:] == ["updateNumbers", "getMap"]
    assert records[-2]["fields"]["x"] == 1234


# -- hex dump and raw bytes ---------------------------------------------------------------
def test_hex_dump_is_decoded_with_names_learnt_from_its_lists(tmp_path):
    path = tmp_path / "dump.txt"
    path.write_text(xxd(server_stream()))
    text = rtmu(path)
    assert text.returncode == 0, text.stderr
    assert text.stdout.startswith("# dump.txt: hex")
    assert "updateNumbers" in text.stdout and "x=1234" in text.stdout
    records = json_lines(rtmu("--json", path).stdout)
    assert [r["name"] for r in records] == [
        "INTRODUCTION",
        "CONNECTED",
        "LIST",
        "LISTARGRET",
        "LISTGROUPANDFLAGS",
        "updateNumbers",
        "getMap",
    ]
    assert {r["dir"] for r in records} == {"s2c"} and {r["time"] for r in records} == {None}
    assert records[-1]["fields"] == {"line": "2D-Map"}


def test_raw_bytes_with_garbage_and_a_bad_checksum(tmp_path):
    stream, bad, _good = damaged_stream()
    path = tmp_path / "bytes.bin"
    path.write_bytes(stream)
    result = rtmu("--json", "--payload", path)
    assert result.returncode == 0, result.stderr
    first, second = json_lines(result.stdout)
    assert (first["command"], first["checksum_ok"], first["length"]) == (300, False, len(bad))
    assert first["payload"] == b"hello".hex() and first["fields"] == {}
    assert first["dropped_before"] == {"garbage_bytes": 4 + len(bad), "bad_checksum": 1}
    assert (second["command"], second["checksum_ok"], second["name"]) == (5, True, "CONNECTED")
    text = rtmu(path).stdout
    assert "BAD CHECKSUM" in text and "!! dropped: " in text
    assert "s2c 4 garbage bytes" not in text  # drops are worded per kind
    assert f"{4 + len(bad)} garbage bytes, 1 bad checksum" in text


def test_json_reports_bytes_dropped_at_the_very_end_of_a_stream(tmp_path):
    """Drops reach --json through the next packet's dropped_before; at the end none follows."""
    good = encode_packet(5)
    path = tmp_path / "tail.bin"
    path.write_bytes(good + b"\x0f\x0c\x10\x00\x05")  # then a header whose packet never arrives
    result = rtmu("--json", path)
    assert result.returncode == 0, result.stderr
    packet, dropped = json_lines(result.stdout)
    assert packet["name"] == "CONNECTED" and "kind" not in packet
    assert dropped.keys() >= PACKET_KEYS
    assert dropped["kind"] == "dropped" and dropped["command"] is None and dropped["name"] is None
    assert (dropped["conn"], dropped["dir"], dropped["transport"]) == (1, "s2c", "stream")
    assert dropped["length"] == 5 and dropped["checksum_ok"] is False
    assert dropped["fields"] == {"garbage_bytes": 5, "truncated_at_close": 1}
    text = rtmu(path).stdout  # the text output showed it already, once
    assert text.count("!! dropped: 5 garbage bytes, 1 packet cut off at the end") == 1


def test_json_reports_trailing_garbage_of_each_tcp_direction(tmp_path):
    conv = Conversation().handshake().send(False, server_stream()).send(False, b"\x00junk\x0f")
    conv.send(True, encode_packet(5)).send(True, b"\xff" * 7).close()
    path = tmp_path / "tail.pcap"
    path.write_bytes(pcap_file(conv.frames()))
    records = json_lines(rtmu("--json", path).stdout)
    dropped = {r["dir"]: r for r in records if r.get("kind") == "dropped"}
    assert dropped.keys() == {"s2c", "c2s"}
    assert dropped["s2c"]["length"] == 6 and dropped["s2c"]["fields"] == {"garbage_bytes": 6}
    assert dropped["c2s"]["length"] == 7 and dropped["c2s"]["fields"] == {"garbage_bytes": 7}
    assert all(r["transport"] == "tcp" and r["conn"] == 1 and r["time"] is not None for r in dropped.values())
    assert records[-1]["kind"] == "dropped"  # at the end of the stream, after its last packet
    assert (
        sum(r.get("kind") == "dropped" for r in json_lines(rtmu("--json", "--no-summary", path).stdout)) == 2
    )


def test_raw_bytes_direction_can_be_given(tmp_path):
    path = tmp_path / "client.bin"
    path.write_bytes(encode_packet(5) + encode_packet(129, bytes.fromhex("0801c8000000")))
    records = json_lines(rtmu("--json", "--direction", "c2s", path).stdout)
    assert [(r["dir"], r["name"]) for r in records] == [("c2s", "TCP_ONLY"), ("c2s", "REQUEST")]
    assert records[1]["fields"]["interval_ms"] == 200


def test_hex_dump_of_damaged_bytes(tmp_path):
    stream, _, _ = damaged_stream()
    path = tmp_path / "dump.hex"
    path.write_text(stream.hex(" ") + "\n")
    records = json_lines(rtmu("--json", path).stdout)
    assert [r["checksum_ok"] for r in records] == [False, True]


# -- errors --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("make", "code", "words"),
    [
        (lambda p: p / "missing.pcap", EXIT_USAGE, "cannot read"),
        (lambda p: p, EXIT_USAGE, "directory"),
        (lambda p: _write(p / "notes.txt", b"just some notes, not hex\n"), EXIT_BAD_FILE, "not a hex dump"),
        (
            lambda p: _write(p / "noise.bin", bytes(range(0x10, 0x0F, -1)) * 3 + b"\x00\x01"),
            EXIT_BAD_FILE,
            "not a recognised",
        ),
        (lambda p: _write(p / "short.pcap", b"\xd4\xc3\xb2\xa1\x02\x00"), EXIT_BAD_FILE, "cut short"),
        (lambda p: _write(p / "empty.pcap", b""), EXIT_BAD_FILE, "empty"),
    ],
    ids=["missing", "directory", "text", "binary-noise", "short-pcap", "empty"],
)
def test_unreadable_or_unknown_input_fails_with_one_line(tmp_path, make, code, words):
    result = rtmu(make(tmp_path))
    assert result.returncode == code
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("rtmu decode: ") and words in lines[0]


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def test_closed_pipe_ends_quietly():
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "decode", "--all", str(CAPTURES / "map-binary-columbia.pcap")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=60) == EXIT_SIGPIPE  # the reader went away: 141, as every command
    assert b"Traceback" not in err


def test_a_server_text_is_escaped_once_so_a_backslash_shows_as_one_escape(tmp_path):
    r"""A password key ``a\b`` + CR is shown as ``'a\\b\r'``: one escape each, not ``a\\\\b``."""
    from rtmu.protocol.commands import ServerCommand
    from rtmu.protocol.payloads.control import ServerIntroduction

    intro = ServerIntroduction("alpha", 0, 1, 2, "a\\b\r", "").encode()
    path = tmp_path / "server.bin"
    path.write_bytes(encode_packet(ServerCommand.INTRODUCTION, intro))
    out = rtmu("--direction", "s2c", path).stdout
    line = next(line for line in out.splitlines() if "password_key" in line)
    assert r"password_key='a\\b\r'" in line, line
    assert "\\\\\\" not in line and "\r" not in line  # never three backslashes in a row, never a raw CR
    record = json_lines(rtmu("--json", "--direction", "s2c", path).stdout)[0]
    assert record["fields"]["password_key"] == "a\\b\r"  # JSON carries the exact string
