"""Capture reading: pcap/pcapng variants, link layers, IPv4/IPv6, TCP reassembly, UDP, hex dumps."""

from __future__ import annotations

import itertools
import shutil
import subprocess
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture_builders import (
    ACK,
    FIN,
    PSH,
    RST,
    SYN,
    Conversation,
    Frame,
    ethernet,
    ip_packet,
    ipv4,
    ipv6,
    pcap_file,
    pcapng_file,
    tcp,
    udp,
    udp_frame,
)
from rtmu.capture import (
    CaptureError,
    Datagram,
    Endpoint,
    StreamData,
    StreamEnd,
    StreamGap,
    UnreadableInput,
    open_capture,
    parse_hex,
)
from rtmu.capture.base import CaptureStats
from rtmu.capture.net import Segment
from rtmu.capture.tcp import TcpReassembler
from rtmu.protocol.packet import encode_packet

CLIENT = Endpoint("127.0.0.1", 50000)
SERVER = Endpoint("127.0.0.1", 7272)


def _streams(path: Path, fmt: str = "auto") -> tuple[dict[tuple[int, Endpoint], bytes], list, object]:
    source = open_capture(path, fmt)
    streams: dict[tuple[int, Endpoint], bytearray] = {}
    others = []
    for event in source.events():
        if isinstance(event, StreamData):
            streams.setdefault((event.flow.id, event.src), bytearray()).extend(event.data)
        else:
            others.append(event)
    return {k: bytes(v) for k, v in streams.items()}, others, source


def _conversation(**kw) -> Conversation:
    conv = Conversation(**kw).handshake()
    conv.send(False, b"hello from the server " * 3)
    conv.send(True, b"and the client answers", pieces=3)
    conv.send(False, b"bye")
    return conv.close()


# -- file formats and link layers ---------------------------------------------------------
@pytest.mark.parametrize("link_type", [1, 0, 108, 101, 12, 14, 113, 276])
@pytest.mark.parametrize("big_endian", [False, True])
@pytest.mark.parametrize("nano", [False, True])
def test_pcap_variants_give_the_same_streams(tmp_path, link_type, big_endian, nano):
    conv = _conversation()
    path = tmp_path / "c.pcap"
    path.write_bytes(pcap_file(conv.frames(link_type), link_type, big_endian=big_endian, nano=nano))
    streams, others, source = _streams(path)
    assert streams == {
        (1, SERVER): b"hello from the server " * 3 + b"bye",
        (1, CLIENT): b"and the client answers",
    }
    assert sum(isinstance(e, StreamEnd) for e in others) == 2
    assert source.stats.link_type == link_type
    assert source.stats.first_time == pytest.approx(conv.segments[0][0], abs=1e-6)


@pytest.mark.parametrize("big_endian", [False, True])
@pytest.mark.parametrize("nano", [False, True])
def test_pcapng_is_read_too(tmp_path, big_endian, nano):
    conv = _conversation()
    path = tmp_path / "c.pcapng"
    path.write_bytes(pcapng_file(conv.frames(1), 1, big_endian=big_endian, nano=nano))
    streams, _, source = _streams(path)
    assert source.kind == "pcapng"
    assert streams[(1, SERVER)] == b"hello from the server " * 3 + b"bye"
    assert source.stats.first_time == pytest.approx(conv.segments[0][0], abs=1e-6)


@pytest.mark.parametrize("hop_by_hop", [False, True])
def test_ipv6_with_and_without_extension_header(tmp_path, hop_by_hop):
    frames = [
        Frame(1.0, ethernet(ipv6("::1", "::2", 6, tcp(40000, 7272, 10, SYN), hop_by_hop=hop_by_hop))),
        Frame(1.1, ethernet(ipv6("::2", "::1", 6, tcp(7272, 40000, 99, SYN | ACK), hop_by_hop=hop_by_hop))),
        Frame(
            1.2,
            ethernet(ipv6("::2", "::1", 6, tcp(7272, 40000, 100, PSH | ACK, b"six"), hop_by_hop=hop_by_hop)),
        ),
    ]
    path = tmp_path / "v6.pcap"
    path.write_bytes(pcap_file(frames))
    streams, _, _ = _streams(path)
    assert streams == {(1, Endpoint("::2", 7272)): b"six"}
    assert str(Endpoint("::2", 7272)) == "[::2]:7272"


def test_vlan_tag_and_ethernet_padding(tmp_path):
    ip = ipv4("10.0.0.1", "10.0.0.2", 6, tcp(7272, 40000, 7, PSH | ACK, b"ab"))
    path = tmp_path / "vlan.pcap"
    path.write_bytes(pcap_file([Frame(1.0, ethernet(ip, vlan=True, pad_to=80))]))
    streams, _, _ = _streams(path)
    assert list(streams.values()) == [b"ab"]  # the padding after the IP packet is not payload


def test_frames_that_are_not_tcp_or_udp_are_counted_and_skipped(tmp_path):
    arp = b"\xff" * 12 + b"\x08\x06" + b"\x00" * 28
    icmp = ethernet(ipv4("10.0.0.1", "10.0.0.2", 1, b"\x08\x00" + b"\x00" * 6))
    fragment = ethernet(ipv4("10.0.0.1", "10.0.0.2", 17, udp(1, 2, b"x"), fragment=True))
    good = ethernet(ipv4("10.0.0.1", "10.0.0.2", 17, udp(7272, 10000, b"\x0f\x0cdata")))
    path = tmp_path / "mix.pcap"
    path.write_bytes(pcap_file([Frame(1, arp), Frame(2, icmp), Frame(3, fragment), Frame(4, good)]))
    _, others, source = _streams(path)
    assert [type(e) for e in others] == [Datagram]
    assert others[0].data == b"\x0f\x0cdata"
    assert source.stats.not_ip == 2
    assert source.stats.ip_fragments == 1
    assert source.stats.frames == 4


def test_a_file_cut_in_the_middle_of_a_frame_keeps_what_came_before(tmp_path):
    conv = _conversation()
    data = pcap_file(conv.frames())
    path = tmp_path / "cut.pcap"
    path.write_bytes(data[:-10])
    streams, _, source = _streams(path)
    assert streams[(1, SERVER)].startswith(b"hello from the server ")
    assert any("cut short" in w for w in source.stats.warnings)


def test_snap_length_cut_becomes_a_gap(tmp_path):
    conv = Conversation().handshake()
    conv.send(False, b"A" * 100).send(False, b"B" * 10)
    frames = conv.frames()
    cut = frames[3]
    frames[3] = Frame(cut.time, cut.data[:-40], original_length=len(cut.data))
    path = tmp_path / "snap.pcap"
    path.write_bytes(pcap_file(frames))
    streams, others, source = _streams(path)
    assert streams[(1, SERVER)] == b"A" * 60 + b"B" * 10
    gaps = [e for e in others if isinstance(e, StreamGap)]
    assert [g.missing for g in gaps] == [40]
    assert source.stats.truncated_frames == 1


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"", "empty"),
        (b"\x00\x01\x02\x03 binary without sync bytes", "not a recognised format"),
        (b"hello, this is plain text\n", "not a hex dump"),
        (b"\xd4\xc3\xb2\xa1\x09\x00", "cut short"),
        (b"\xd4\xc3\xb2\xa1" + b"\x07\x00\x04\x00" + b"\x00" * 16, "version 7"),
    ],
)
def test_unrecognised_inputs_are_refused_with_one_sentence(tmp_path, content, message):
    path = tmp_path / "x.bin"
    path.write_bytes(content)
    with pytest.raises(CaptureError, match=message):
        open_capture(path)


def test_unsupported_link_type_is_refused_or_skipped(tmp_path):
    frames = _conversation().frames(101)
    path = tmp_path / "wifi.pcap"
    path.write_bytes(pcap_file(frames, 105))
    with pytest.raises(CaptureError, match="link type 105 is not supported"):
        open_capture(path)
    path = tmp_path / "wifi.pcapng"
    path.write_bytes(pcapng_file(frames, 105))
    streams, _, source = _streams(path)
    assert streams == {}
    assert source.stats.not_ip == len(frames)
    assert source.stats.warnings == ["link type 105 is not supported; its frames were skipped"]


def test_missing_file_is_unreadable(tmp_path):
    with pytest.raises(UnreadableInput, match="cannot read"):
        open_capture(tmp_path / "nope.pcap")
    with pytest.raises(UnreadableInput, match="directory"):
        open_capture(tmp_path)


# -- TCP reassembly ------------------------------------------------------------------------
def _reassemble(
    segments: list[tuple[Endpoint, Endpoint, int, int, bytes]],
) -> tuple[dict, list, CaptureStats]:
    stats = CaptureStats()
    tcp_ = TcpReassembler(stats)
    events = []
    for i, (src, dst, seq, flags, payload) in enumerate(segments):
        events.extend(tcp_.segment(Segment(6, src, dst, payload, 0, seq, flags), float(i)))
    events.extend(tcp_.finish())
    streams: dict = {}
    for e in events:
        if isinstance(e, StreamData):
            streams.setdefault((e.flow.id, e.src), bytearray()).extend(e.data)
    return {k: bytes(v) for k, v in streams.items()}, events, stats


def test_out_of_order_and_retransmitted_segments_are_put_back_in_order():
    c, s = CLIENT, SERVER
    segs = [
        (c, s, 100, SYN, b""),
        (s, c, 900, SYN | ACK, b""),
        (s, c, 907, ACK, b"world"),  # arrives before "hello "
        (s, c, 901, ACK, b"hello "),
        (s, c, 901, ACK, b"hello "),  # plain retransmission
        (s, c, 904, ACK, b"lo world!"),  # old bytes, then 1 new one
        (s, c, 913, ACK | FIN, b" end"),
    ]
    streams, events, stats = _reassemble(segs)
    assert streams == {(1, s): b"hello world! end"}
    assert stats.out_of_order_segments == 1
    assert stats.retransmitted_bytes == 6 + 8
    assert not any(isinstance(e, StreamGap) for e in events)
    first = next(e for e in events if isinstance(e, StreamData))
    assert first.flow.server == s  # it accepted the SYN


def test_sequence_numbers_wrap_around():
    c, s = CLIENT, SERVER
    isn = 0xFFFFFFFA
    segs = [
        (s, c, isn, SYN | ACK, b""),
        (s, c, isn + 1, ACK, b"abcd"),
        (s, c, (isn + 9) & 0xFFFFFFFF, ACK, b"ijkl"),
        (s, c, (isn + 5) & 0xFFFFFFFF, ACK, b"efgh"),
    ]
    streams, _, _ = _reassemble(segs)
    assert streams == {(1, s): b"abcdefghijkl"}


def test_capture_starting_mid_stream_takes_the_first_segment_as_the_start():
    c, s = CLIENT, SERVER
    segs = [(s, c, 123456, ACK, b"middle "), (c, s, 777, ACK, b"ack"), (s, c, 123463, ACK, b"more")]
    streams, events, _ = _reassemble(segs)
    assert streams == {(1, s): b"middle more", (1, c): b"ack"}
    assert next(e for e in events if isinstance(e, StreamData)).flow.server is None  # no SYN: not known


def test_a_hole_that_never_fills_is_reported_as_a_gap_at_the_end():
    c, s = CLIENT, SERVER
    segs = [(c, s, 10, SYN, b""), (c, s, 11, ACK, b"abc"), (c, s, 20, ACK, b"xyz")]
    streams, events, _ = _reassemble(segs)
    assert streams == {(1, c): b"abcxyz"}
    gaps = [e for e in events if isinstance(e, StreamGap)]
    assert [g.missing for g in gaps] == [6]
    assert isinstance(events[-1], StreamEnd)


def test_a_new_syn_on_the_same_ports_is_a_new_connection():
    c, s = CLIENT, SERVER
    segs = [
        (c, s, 10, SYN, b""),
        (s, c, 50, SYN | ACK, b""),
        (c, s, 11, ACK, b"first"),
        (c, s, 16, FIN | ACK, b""),
        (s, c, 51, FIN | ACK, b""),
        (c, s, 5000, SYN, b""),
        (s, c, 9000, SYN | ACK, b""),
        (c, s, 5001, ACK, b"second"),
        (s, c, 9001, RST, b""),
    ]
    streams, events, _ = _reassemble(segs)
    assert streams == {(1, c): b"first", (2, c): b"second"}
    ends = [(e.flow.id, e.src) for e in events if isinstance(e, StreamEnd)]
    assert sorted(ends) == sorted([(1, c), (1, s), (2, c), (2, s)])  # every direction ends once


def test_real_retransmission_of_a_syn_does_not_start_a_new_connection():
    c, s = CLIENT, SERVER
    segs = [(c, s, 10, SYN, b""), (c, s, 10, SYN, b""), (s, c, 50, SYN | ACK, b""), (s, c, 51, ACK, b"x")]
    streams, _, _ = _reassemble(segs)
    assert streams == {(1, s): b"x"}


def test_udp_datagrams_pass_through_with_their_endpoints(tmp_path):
    payload = encode_packet(3, b"\x01\x02\x03\x04")
    path = tmp_path / "u.pcap"
    path.write_bytes(pcap_file([udp_frame(5.0, ("10.1.1.1", 7272), ("10.1.1.2", 10000), payload)]))
    _, others, _ = _streams(path)
    assert others == [Datagram(Endpoint("10.1.1.1", 7272), Endpoint("10.1.1.2", 10000), 5.0, payload)]


def test_any_port_is_reassembled(tmp_path):
    conv = _conversation(server=("192.168.5.5", 443), client=("192.168.5.6", 61000))
    path = tmp_path / "p.pcap"
    path.write_bytes(pcap_file(conv.frames()))
    streams, _, _ = _streams(path)
    assert streams[(1, Endpoint("192.168.5.5", 443))].startswith(b"hello")


# -- hex dumps -------------------------------------------------------------------------------
SAMPLE = bytes(range(256)) + b"0123456789abcdef" * 3 + b"\x0f\x0c\x08\x00\x05\x00\x00\x05" + b"ab"


def _xxd_like(data: bytes, group: int = 2) -> str:
    lines = []
    for off in range(0, len(data), 16):
        chunk = data[off : off + 16]
        groups = [chunk[i : i + group].hex() for i in range(0, len(chunk), group)]
        hexpart = " ".join(groups).ljust(32 + (16 // group) - 1)
        text = "".join(chr(b) if 32 <= b < 127 else "." for b in chunk)
        lines.append(f"{off:08x}: {hexpart}  {text}")
    return "\n".join(lines) + "\n"


def _hexdump_c(data: bytes) -> str:
    lines = []
    for off in range(0, len(data), 16):
        chunk = data[off : off + 16]
        left = " ".join(f"{b:02x}" for b in chunk[:8])
        right = " ".join(f"{b:02x}" for b in chunk[8:])
        text = "".join(chr(b) if 32 <= b < 127 else "." for b in chunk)
        lines.append(f"{off:08x}  {left:<23}  {right:<23}  |{text}|")
    lines.append(f"{len(data):08x}")
    return "\n".join(lines) + "\n"


def _tshark(data: bytes) -> str:
    lines = []
    for off in range(0, len(data), 16):
        chunk = data[off : off + 16]
        text = "".join(chr(b) if 32 <= b < 127 else "." for b in chunk)
        lines.append(f"{off:04x}  {' '.join(f'{b:02x}' for b in chunk):<47}   {text}")
    return "\n".join(lines) + "\n"


def _parse(text: str) -> bytes:
    return b"".join(parse_hex(text.splitlines(keepends=True)))


@pytest.mark.parametrize(
    "render",
    [
        lambda d: d.hex(" "),
        lambda d: d.hex(),
        lambda d: "\n".join(d[i : i + 7].hex(":") for i in range(0, len(d), 7)),
        lambda d: ", ".join(f"0x{b:02X}" for b in d),
        lambda d: "# a comment first\n\n" + d.hex(" ", 2),
        _xxd_like,
        lambda d: _xxd_like(d, 1),
        lambda d: _xxd_like(d, 4),
        _hexdump_c,
        _tshark,
    ],
    ids=["spaced", "solid", "colons", "c-array", "comment", "xxd", "xxd-g1", "xxd-g4", "hexdump-C", "tshark"],
)
def test_hex_dump_styles(render, tmp_path):
    assert _parse(render(SAMPLE)) == SAMPLE


def test_ascii_column_that_looks_like_hex_is_not_taken_for_bytes():
    data = b"abcdef01" * 2 + b"cafe"  # printable hex digits: the ASCII column is valid hex too
    assert _parse(_xxd_like(data)) == data
    assert _parse(_xxd_like(data, 1)) == data


@pytest.mark.parametrize(
    "tool",
    [
        ["xxd"],
        ["xxd", "-g1"],
        ["od", "-A", "x", "-t", "x1z", "-v"],
        ["od", "-A", "x", "-t", "x1z"],
        ["od", "-t", "x1"],
        ["od", "-x"],
        ["hexdump", "-C"],
        ["hexdump"],
    ],
    ids=lambda t: " ".join(t),
)
def test_real_dump_tools(tool, tmp_path):
    # scripts/setup.sh installs every one of them (tests/test_setup_programs.py checks): a missing
    # tool is a broken set-up, not a reason to skip.
    assert shutil.which(tool[0]), f"{tool[0]} is not installed: run scripts/setup.sh"
    data = SAMPLE + b"\x00" * 64 + b"\x0f\x0c\x08\x00\x05\x00\x00\x05" + b"z"  # repeated lines: od prints '*'
    raw = tmp_path / "in.bin"
    raw.write_bytes(data)
    text = subprocess.run([*tool, str(raw)], check=True, capture_output=True, text=True).stdout
    assert _parse(text) == data


def test_bad_hex_names_the_line():
    with pytest.raises(CaptureError, match="line 2"):
        _parse("0f 0c\n0f zz\n")
    with pytest.raises(CaptureError, match="offset"):
        _parse("00000000: 0f0c 0800\n00000010: 0500 0005\n")
    with pytest.raises(CaptureError, match="no bytes"):
        _parse("# nothing here\n")


def test_hex_file_is_detected_and_read_as_one_stream(tmp_path):
    packet = encode_packet(5)
    path = tmp_path / "dump.txt"
    path.write_text(_xxd_like(b"\x00garbage" + packet))
    streams, _, source = _streams(path)
    assert source.kind == "hex"
    assert list(streams.values()) == [b"\x00garbage" + packet]


def test_raw_bytes_are_one_stream(tmp_path):
    path = tmp_path / "raw.bin"
    path.write_bytes(b"\x00\x01" + encode_packet(5) * 5000)  # several read chunks
    streams, _, source = _streams(path)
    assert source.kind == "raw"
    assert list(streams.values()) == [b"\x00\x01" + encode_packet(5) * 5000]


def test_forced_formats(tmp_path):
    path = tmp_path / "x"
    path.write_text("0f 0c 08 00 05 00 00 05\n")
    assert open_capture(path, "hex").kind == "hex"
    assert open_capture(path, "raw").kind == "raw"
    with pytest.raises(CaptureError, match="not a pcap"):
        open_capture(path, "pcap")
    pcap = tmp_path / "p.pcap"
    pcap.write_bytes(pcap_file([Frame(1.0, ethernet(ip_packet("1.1.1.1", "2.2.2.2", 17, udp(1, 2, b"x"))))]))
    with pytest.raises(CaptureError, match="not hexadecimal"):
        open_capture(pcap, "hex")


@settings(max_examples=150)
@given(
    data=st.binary(min_size=1, max_size=2000),
    cuts=st.lists(st.integers(1, 1999), max_size=25),
    extra=st.lists(st.tuples(st.integers(0, 1999), st.integers(1, 300)), max_size=6),
    isn=st.integers(0, 0xFFFFFFFF),
    rnd=st.randoms(use_true_random=False),
)
def test_any_segmentation_order_and_duplication_gives_back_the_stream(data, cuts, extra, isn, rnd):
    c, s = CLIENT, SERVER
    edges = sorted({0, len(data), *(x for x in cuts if x < len(data))})
    pieces = [(a, data[a:b]) for a, b in itertools.pairwise(edges)]
    pieces += [(a, data[a : a + n]) for a, n in extra if a < len(data)]  # retransmissions, overlaps
    rnd.shuffle(pieces)
    segs = [(s, c, isn, SYN | ACK, b"")]
    segs += [(s, c, (isn + 1 + a) & 0xFFFFFFFF, ACK, chunk) for a, chunk in pieces]
    streams, events, _ = _reassemble(segs)
    assert streams == {(1, s): data}
    assert not any(isinstance(e, StreamGap) for e in events)


def test_too_much_data_behind_a_hole_gives_up_on_the_hole(monkeypatch):
    monkeypatch.setattr("rtmu.capture.tcp.MAX_PENDING_BYTES", 100)
    c, s = CLIENT, SERVER
    segs = [(s, c, 0, SYN | ACK, b""), (s, c, 1, ACK, b"start")]
    segs += [(s, c, 16 + 40 * i, ACK, bytes([65 + i]) * 40) for i in range(4)]  # 10 bytes never arrive
    stats = CaptureStats()
    tcp_ = TcpReassembler(stats)
    events = []
    for i, (src, dst, seq, flags, payload) in enumerate(segs):
        events.extend(tcp_.segment(Segment(6, src, dst, payload, 0, seq, flags), float(i)))
    kinds = [(type(e).__name__, getattr(e, "missing", None)) for e in events]
    assert kinds[:2] == [("StreamData", None), ("StreamGap", 10)]  # before the end of the capture
    data = b"".join(e.data for e in events if isinstance(e, StreamData))
    assert data == b"start" + b"A" * 40 + b"B" * 40 + b"C" * 40 + b"D" * 40


def test_late_retransmission_after_the_close_is_not_a_new_connection():
    c, s = CLIENT, SERVER
    segs = [
        (c, s, 10, SYN, b""),
        (s, c, 50, SYN | ACK, b""),
        (s, c, 51, ACK, b"data"),
        (s, c, 55, FIN | ACK, b""),
        (c, s, 11, FIN | ACK, b""),
        (s, c, 51, ACK, b"data"),  # a late copy
    ]
    streams, events, _ = _reassemble(segs)
    assert streams == {(1, s): b"data"}
    assert {e.flow.id for e in events} == {1}
