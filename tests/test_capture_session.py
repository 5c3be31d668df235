"""The session decoder: names by direction and per connection, UDP attribution, drops, decode errors."""

from __future__ import annotations

import pytest

from capture_builders import (
    Conversation,
    Frame,
    catalogue,
    client_intro,
    ethernet,
    ipv4,
    pcap_file,
    request,
    server_greeting,
    server_intro,
    tcp,
    udp_frame,
    update_numbers,
)
from rtmu.capture import open_capture
from rtmu.capture.conversation import DecodedPacket, DropReport
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.packet import encode_packet

NAMES_A = ["updateNumbers", "ratioDrive", "getSensorCurrent", "getMap"]
NAMES_B = ["ratioDrive", "getMap", "updateNumbers", "getSensorCurrent"]  # numbered differently


def _decode(path, **kw) -> tuple[list[DecodedPacket], list[DropReport], CaptureDecoder]:
    decoder = CaptureDecoder()
    packets, drops = [], []
    for item in decoder.run(open_capture(path, **kw).events()):
        (packets if isinstance(item, DecodedPacket) else drops).append(item)
    return packets, drops, decoder


def _session(names, client_port, *, udp_port=0, client_udp=0, extra=b"", client_extra=b"") -> Conversation:
    datalist = catalogue(names, {"getMap": "RETURN_UNTIL_EMPTY"})
    intro, lists = server_greeting(datalist, udp_port)
    conv = Conversation(client=("127.0.0.1", client_port)).handshake()
    conv.send(False, intro)
    conv.send(True, client_intro(client_udp) + (b"" if client_udp else encode_packet(5)))
    conv.send(False, lists, pieces=4)
    drive = FieldWriter().double(50).double(0).double(100).bytes()
    conv.send(
        True,
        request(datalist.number("updateNumbers"), 100) + encode_packet(datalist.number("ratioDrive"), drive),
    )
    conv.send(True, client_extra)
    conv.send(False, encode_packet(datalist.number("updateNumbers"), update_numbers()) + extra)
    return conv


def _write(tmp_path, frames, name="s.pcap"):
    path = tmp_path / name
    path.write_bytes(pcap_file(frames))
    return path


def test_names_follow_direction_and_each_connections_own_list(tmp_path):
    a = _session(NAMES_A, 50001).close()
    b = _session(NAMES_B, 50002).close()
    path = _write(tmp_path, a.frames() + b.frames())
    packets, drops, decoder = _decode(path)
    assert not drops
    assert [s.id for s in decoder.sessions] == [1, 2]
    for conn, names in ((1, NAMES_A), (2, NAMES_B)):
        mine = [p for p in packets if p.conn == conn]
        by = {(p.direction, p.command): p.name for p in mine}
        assert by[("s2c", 5)] == "CONNECTED"
        assert by[("c2s", 5)] == "TCP_ONLY"
        assert by[("s2c", 129)] == "LIST"
        assert by[("c2s", 129)] == "REQUEST"
        assert by[("s2c", 256 + names.index("updateNumbers"))] == "updateNumbers"
        assert by[("c2s", 256 + names.index("ratioDrive"))] == "ratioDrive"
        lst = next(p for p in mine if p.name == "LIST")
        assert lst.fields["count"] == 4
        assert [e["name"] for e in lst.fields["entries"]] == names
        req = next(p for p in mine if p.name == "REQUEST")
        assert req.fields == {
            "data": 256 + names.index("updateNumbers"),
            "data_name": "updateNumbers",
            "interval_ms": 100,
        }
        intro = next(p for p in mine if p.name == "INTRODUCTION" and p.direction == "s2c")
        assert intro.fields["version_tag"] == "alpha"
        numbers = next(p for p in mine if p.name == "updateNumbers")
        assert numbers.fields["x"] == 1000 and numbers.fields["y"] == -2000
        drive = next(p for p in mine if p.name == "ratioDrive")
        assert (drive.fields["trans"], drive.fields["rot"], drive.fields["throttle"]) == (50, 0, 100)
    assert all(p.checksum_ok and p.transport == "tcp" and p.error is None for p in packets)
    assert decoder.sessions[0].server_guessed is False


def test_udp_is_attributed_by_announced_ports_and_by_udp_keys(tmp_path):
    conv = _session(NAMES_A, 50001, udp_port=7272, client_udp=10000)
    frames = conv.frames()
    numbers = encode_packet(256, update_numbers(x=5))
    frames.append(udp_frame(conv.time + 1, ("127.0.0.1", 7272), ("127.0.0.1", 10000), numbers))
    # the client's UDP_INTRODUCTION from another port carries the auth key: that route is learnt
    frames.append(
        udp_frame(
            conv.time + 2,
            ("127.0.0.1", 10007),
            ("127.0.0.1", 7272),
            encode_packet(3, bytes.fromhex("2744561e")),
        )
    )
    frames.append(udp_frame(conv.time + 3, ("127.0.0.1", 7272), ("127.0.0.1", 10007), numbers))
    # an unrelated ArNetworking-looking flow, and a datagram that is not ArNetworking at all
    frames.append(udp_frame(conv.time + 4, ("10.9.9.9", 9000), ("10.9.9.8", 9001), numbers))
    frames.append(udp_frame(conv.time + 5, ("127.0.0.1", 53), ("127.0.0.1", 40000), b"\x12\x34 dns"))
    packets, drops, decoder = _decode(_write(tmp_path, frames))
    udp = [p for p in packets if p.transport == "udp"]
    assert [(p.conn, p.direction, p.name) for p in udp] == [
        (1, "s2c", "updateNumbers"),
        (1, "c2s", "UDP_INTRODUCTION"),
        (1, "s2c", "updateNumbers"),
        (2, "s2c", None),  # its own connection; no list, so no name
    ]
    assert udp[1].fields == {"auth_key": 0x1E564427}
    assert decoder.sessions[0].udp_datagrams == 3
    assert decoder.sessions[1].transport == "udp"
    assert decoder.ignored_datagrams == 1
    assert not drops


def test_tcp_that_is_not_arnetworking_is_left_out(tmp_path):
    http = Conversation(server=("127.0.0.1", 80)).handshake()
    http.send(True, b"GET / HTTP/1.1\r\nHost: x\r\n\r\n").send(False, b"HTTP/1.1 200 OK\r\n\r\nhi").close()
    arnl = _session(NAMES_A, 50001).close()
    packets, _, decoder = _decode(_write(tmp_path, http.frames() + arnl.frames()))
    assert {p.conn for p in packets} == {1}
    assert decoder.ignored_tcp_flows == 1
    assert str(decoder.sessions[0].server.port) == "7272"


def test_mid_stream_capture_finds_the_server_by_what_it_says(tmp_path):
    # no SYN, the server on a high port, the client on a low one: only the content can tell
    conv = Conversation(client=("127.0.0.1", 2000), server=("127.0.0.1", 60000))
    conv.send(False, server_intro()).send(True, client_intro()).send(False, encode_packet(5))
    packets, _, decoder = _decode(_write(tmp_path, conv.frames()))
    assert [(p.direction, p.name) for p in packets] == [
        ("s2c", "INTRODUCTION"),
        ("c2s", "INTRODUCTION"),
        ("s2c", "CONNECTED"),
    ]
    assert decoder.sessions[0].server_guessed is True
    assert decoder.sessions[0].server.port == 60000


def test_mid_stream_without_handshake_falls_back_to_the_ports(tmp_path):
    conv = Conversation(client=("127.0.0.1", 45000), server=("127.0.0.1", 7272))
    conv.send(True, encode_packet(300, b"abc"))
    packets, _, _ = _decode(_write(tmp_path, conv.frames()))
    assert [(p.direction, p.command, p.name) for p in packets] == [("c2s", 300, None)]


def test_rejected_reads_as_a_sentence(tmp_path):
    conv = Conversation().handshake()
    conv.send(False, server_intro()).send(True, client_intro(user="bob"))
    conv.send(False, encode_packet(6, FieldWriter().byte2(1).string("").bytes())).close()
    packets, _, decoder = _decode(_write(tmp_path, conv.frames()))
    rejected = packets[-1]
    assert rejected.name == "REJECTED"
    assert rejected.fields["reason"] == 1
    assert "wrong user name or password" in rejected.fields["explanation"]
    assert decoder.sessions[0].user == "bob"
    assert decoder.sessions[0].rejected


def test_malformed_control_packets_show_their_error_and_decoding_goes_on(tmp_path):
    conv = Conversation().handshake()
    conv.send(False, server_intro()).send(True, encode_packet(2, b"\x00\x00bob\x00\x01\x02"))  # digest cut
    conv.send(True, encode_packet(129, b"\x08\x01\x00") + encode_packet(130, b"\x08\x01"))
    conv.send(False, encode_packet(6, b"\x04\x00")).close()  # reason, then no text: ARIA reads ""
    packets, _, decoder = _decode(_write(tmp_path, conv.frames()))
    by_name = {(p.direction, p.name): p for p in packets}
    intro = by_name[("c2s", "INTRODUCTION")]
    assert intro.error is not None and "password digest" in intro.error and intro.fields == {}
    assert by_name[("c2s", "REQUEST")].error is not None
    assert by_name[("c2s", "REQUESTSTOP")].error is None  # bytes after the number are ignored
    assert by_name[("c2s", "REQUESTSTOP")].fields == {"data": 0x0108, "data_name": None}
    rejected = by_name[("s2c", "REJECTED")]
    assert rejected.error is None and (rejected.fields["reason"], rejected.fields["text"]) == (4, "")
    (session,) = decoder.sessions
    assert session.user is None  # learnt only from an introduction that decodes
    assert session.rejected is not None and "protocol version" in session.rejected


def test_decode_error_is_shown_and_decoding_goes_on(tmp_path):
    extra = encode_packet(256, b"\x01\x02\x03") + encode_packet(256, update_numbers(x=7))
    packets, _, _ = _decode(_write(tmp_path, _session(NAMES_A, 50001, extra=extra).frames()))
    numbers = [p for p in packets if p.name == "updateNumbers"]
    assert len(numbers) == 3
    assert numbers[1].error and numbers[1].fields == {}
    assert numbers[2].error is None and numbers[2].fields["x"] == 7


def test_request_arguments_are_decoded_with_the_args_type(tmp_path):
    args = FieldWriter().string("sonar").bytes()
    datalist = catalogue(NAMES_A)
    extra = request(datalist.number("getSensorCurrent"), 500, args)
    packets, _, _ = _decode(_write(tmp_path, _session(NAMES_A, 50001, client_extra=extra).frames()))
    req = [p for p in packets if p.name == "REQUEST"][-1]
    assert req.fields["data_name"] == "getSensorCurrent"
    assert req.fields["interval_ms"] == 500
    assert req.fields["args"]["names"] == ["sonar"]


def test_end_of_reply_marker_is_labelled(tmp_path):
    extra = encode_packet(256 + NAMES_A.index("getMap"), FieldWriter().string("2D-Map").bytes())
    extra += encode_packet(256 + NAMES_A.index("getMap"), b"\x00") + encode_packet(
        256 + NAMES_A.index("getMap")
    )
    packets, _, _ = _decode(_write(tmp_path, _session(NAMES_A, 50001, extra=extra).frames()))
    maps = [p for p in packets if p.name == "getMap"]
    assert [p.fields.get("line") for p in maps] == ["2D-Map", "", None]
    assert maps[-1].note == "end of reply"


def test_garbage_and_bad_checksums_are_reported_and_the_stream_recovers(tmp_path):
    good = encode_packet(5)
    bad = bytearray(encode_packet(300, b"hello"))
    bad[-1] ^= 0xFF
    path = tmp_path / "raw.bin"
    path.write_bytes(b"\x00\x11\x0f\x22" + bytes(bad) + b"\x0f\x0c\x07\x00" + good)
    packets, drops, decoder = _decode(path, direction="s2c")
    assert [(p.command, p.checksum_ok) for p in packets] == [(300, False), (5, True)]
    assert packets[0].payload == b"hello" and packets[0].length == len(bad)
    assert packets[1].name == "CONNECTED"
    assert packets[0].dropped_before == drops[0].counts
    assert drops[0].counts == {"garbage_bytes": 4 + len(bad) + 4, "bad_length": 1, "bad_checksum": 1}
    assert decoder.sessions[0].drops["bad_checksum"] == 1


def test_trailing_garbage_is_a_drop_report_without_a_packet(tmp_path):
    path = tmp_path / "raw.bin"
    path.write_bytes(encode_packet(5) + b"\x0f\x0c\x20\x00\x05")  # a header whose body never comes
    packets, drops, decoder = _decode(path)
    assert len(packets) == 1 and packets[0].dropped_before is None
    assert drops[-1].counts == {"garbage_bytes": 5, "truncated_at_close": 1}
    assert decoder.sessions[0].drops["truncated_at_close"] == 1


def test_a_hole_in_the_capture_is_reported_and_decoding_resumes(tmp_path):
    conv = _session(NAMES_A, 50001, extra=encode_packet(256, update_numbers(x=1)) * 3)
    frames = conv.frames()
    last = conv.segments[-1]
    # lose 10 bytes in the middle of the last server segment: rebuild it as two pieces without them
    time, _, seq, flags, payload = last
    head, tail = payload[:5], payload[15:]
    frames[-1] = Frame(time, ethernet(ipv4("127.0.0.1", "127.0.0.1", 6, tcp(7272, 50001, seq, flags, head))))
    frames.append(
        Frame(time, ethernet(ipv4("127.0.0.1", "127.0.0.1", 6, tcp(7272, 50001, seq + 15, flags, tail))))
    )
    packets, drops, _ = _decode(_write(tmp_path, frames))
    assert any(d.counts.get("capture_gap_bytes") == 10 for d in drops)
    numbers = [p for p in packets if p.name == "updateNumbers" and p.checksum_ok]
    assert len(numbers) == 3  # the damaged one is lost, the three after it are found


@pytest.mark.parametrize(
    ("content", "direction", "expected"),
    [
        (client_intro() + encode_packet(5), "auto", [("c2s", "INTRODUCTION"), ("c2s", "TCP_ONLY")]),
        (server_intro() + encode_packet(5), "auto", [("s2c", "INTRODUCTION"), ("s2c", "CONNECTED")]),
        (encode_packet(5), "auto", [("s2c", "CONNECTED")]),
        (encode_packet(5), "c2s", [("c2s", "TCP_ONLY")]),
    ],
)
def test_stream_direction_is_guessed_or_given(tmp_path, content, direction, expected):
    path = tmp_path / "raw.bin"
    path.write_bytes(content)
    packets, _, decoder = _decode(path, direction=direction)
    assert [(p.direction, p.name) for p in packets] == expected
    assert decoder.sessions[0].server_guessed is (direction == "auto")
