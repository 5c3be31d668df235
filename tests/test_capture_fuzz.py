"""Damaged inputs never crash ``rtmu decode``: a clear CaptureError or a decoded remainder, nothing else."""

from __future__ import annotations

from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from capture_builders import Conversation, catalogue, pcapng_file, server_greeting, update_numbers
from rtmu.capture import CaptureError, open_capture
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.protocol.packet import encode_packet
from testdata import CAPTURES

PCAP = (CAPTURES / "strings.pcap").read_bytes()


def _pcapng() -> bytes:
    intro, lists = server_greeting(catalogue(["updateNumbers"]), udp_port=7272)
    conv = Conversation().handshake().send(False, intro).send(True, encode_packet(5)).send(False, lists)
    conv.send(False, encode_packet(256, update_numbers())).close()
    return pcapng_file(conv.frames())


PCAPNG = _pcapng()


def _decode_all(path: Path) -> None:
    try:
        source = open_capture(path)
    except CaptureError:
        return
    try:
        for _ in CaptureDecoder().run(source.events()):
            pass
    except CaptureError:
        pass


def _mutate(data: bytes, flips: list[tuple[int, int]], cut: int | None) -> bytes:
    out = bytearray(data)
    for at, value in flips:
        out[at % len(out)] = value
    return bytes(out[:cut] if cut is not None else out)


@settings(max_examples=60, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    which=st.sampled_from(["pcap", "pcapng"]),
    flips=st.lists(st.tuples(st.integers(0, 1 << 20), st.integers(0, 255)), max_size=40),
    cut=st.none() | st.integers(0, 40000),
)
def test_damaged_captures_never_crash(tmp_path, which, flips, cut):
    path = tmp_path / f"x.{which}"
    path.write_bytes(_mutate(PCAP if which == "pcap" else PCAPNG, flips, cut))
    _decode_all(path)


@settings(max_examples=60, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=3000) | st.text(max_size=500).map(lambda t: t.encode("utf-8")))
def test_arbitrary_files_never_crash(tmp_path, data):
    path = tmp_path / "x.bin"
    path.write_bytes(data)
    _decode_all(path)


@settings(max_examples=40, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lines=st.lists(st.text(alphabet="0123456789abcdefABCDEF :|*.>x<,#-\t", max_size=60), max_size=20))
def test_hex_like_text_never_crashes(tmp_path, lines):
    path = tmp_path / "x.txt"
    path.write_text("\n".join(lines))
    _decode_all(path)


def test_damaged_pcapng_blocks_stop_with_a_warning(tmp_path):
    import struct

    shb = (
        struct.pack("<II", 0x0A0D0D0A, 28)
        + struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1)
        + struct.pack("<I", 28)
    )
    short_idb = struct.pack("<III", 1, 12, 12)  # an interface block without its fields
    options_cut = struct.pack("<II", 1, 24) + struct.pack("<HHI", 1, 0, 0) + struct.pack("<HH", 9, 1)
    options_cut += struct.pack("<I", 24)  # if_tsresol announced, its value missing
    for body, warned in ((shb + short_idb, True), (shb + options_cut, False)):
        path = tmp_path / "x.pcapng"
        path.write_bytes(body)
        source = open_capture(path)
        assert list(CaptureDecoder().run(source.events())) == []
        assert bool(source.stats.warnings) is warned
