"""Golden tests on real ARIA 2.9.1 sessions (``tests/data/captures``): what ``rtmu decode`` reads from them.

Facts are checked two ways where it matters: with an independent parse of the
raw payload written here from the protocol document, and with the typed
payloads of :mod:`rtmu.protocol.payloads`. Every registered payload type must
re-encode every real packet of its data byte for byte, every control packet must
re-encode through its control type, and every data list must rebuild as sent.
"""

from __future__ import annotations

import functools
import io
import itertools
import math
import struct
from collections import Counter
from dataclasses import dataclass

import pytest

from rtmu.capture import CaptureSource, open_capture
from rtmu.capture.conversation import DecodedPacket, DropReport
from rtmu.capture.session_decoder import CaptureDecoder, side_of
from rtmu.protocol.fields import FieldReader
from rtmu.protocol.payloads import control
from rtmu.protocol.payloads.base import Side, payload_type_for
from testdata import ARIA_MAPS, CAPTURES

CAPTURE_NAMES = sorted(p.name for p in CAPTURES.glob("*.pcap"))


@dataclass
class Decoded:
    packets: list[DecodedPacket]
    drops: list[DropReport]
    decoder: CaptureDecoder
    source: CaptureSource

    def data(self, name: str, direction: str = "s2c", conn: int | None = None) -> list[DecodedPacket]:
        return [
            p
            for p in self.packets
            if p.name == name and p.direction == direction and (conn is None or p.conn == conn) and p.is_data
        ]

    def rel(self, packet: DecodedPacket) -> float:
        assert packet.time is not None and self.source.stats.first_time is not None
        return packet.time - self.source.stats.first_time


@functools.cache
def decoded(name: str) -> Decoded:
    source = open_capture(CAPTURES / name)
    decoder = CaptureDecoder()
    packets: list[DecodedPacket] = []
    drops: list[DropReport] = []
    for item in decoder.run(source.events()):
        (packets if isinstance(item, DecodedPacket) else drops).append(item)
    return Decoded(packets, drops, decoder, source)


def test_the_captures_are_there():
    assert CAPTURES.is_dir(), f"{CAPTURES} missing: the captured ARIA sessions are part of the repository"
    assert len(CAPTURE_NAMES) >= 8


# -- every capture ------------------------------------------------------------------------
@pytest.mark.parametrize("name", CAPTURE_NAMES)
def test_every_packet_is_valid_and_nothing_is_dropped(name):
    d = decoded(name)
    assert d.packets
    assert all(p.checksum_ok for p in d.packets)
    assert d.drops == []
    for session in d.decoder.sessions:
        assert not session.drops, session.drops
        assert not session.server_guessed  # every capture holds the SYN
        assert session.datalist.complete
    stats = d.source.stats
    assert (stats.tcp_gaps, stats.not_ip, stats.truncated_frames, stats.warnings) == (0, 0, 0, [])
    assert d.decoder.ignored_tcp_flows == 0 and d.decoder.ignored_datagrams == 0


@pytest.mark.parametrize("name", CAPTURE_NAMES)
def test_every_packet_is_named_and_decodes_without_error(name):
    d = decoded(name)
    assert [p for p in d.packets if p.error] == []
    assert [(p.direction, p.command) for p in d.packets if p.name is None] == []


@pytest.mark.parametrize("name", CAPTURE_NAMES)
def test_the_handshake_reads_as_in_the_protocol_document(name):
    d = decoded(name)
    for session in d.decoder.sessions:
        if session.transport != "tcp":
            continue
        mine = [p for p in d.packets if p.conn == session.id and p.transport == "tcp"]
        first = mine[0]
        assert (first.direction, first.name, first.fields["version_tag"]) == ("s2c", "INTRODUCTION", "alpha")
        assert mine[1].direction == "c2s" and mine[1].name == "INTRODUCTION"
        assert session.server_udp_port == first.fields["udp_port"]
        assert session.client_udp_port == mine[1].fields["udp_port"]
        names = [(p.direction, p.name) for p in mine]
        assert ("s2c", "CONNECTED") in names
        lists = [p.name for p in mine if p.name and p.name.startswith("LIST")]
        assert lists == ["LIST", "LISTARGRET", "LISTGROUPANDFLAGS"]
        counts = {p.fields["count"] for p in mine if p.name in lists}
        assert counts == {len(session.datalist)}


# -- what each capture shows ---------------------------------------------------------------
def test_client_command_lister_sees_the_full_list_of_114_names():
    d = decoded("clientCommandLister-serverDemoMap.pcap")
    (session,) = d.decoder.sessions
    (lst,) = [p for p in d.packets if p.name == "LIST"]
    assert lst.fields["count"] == 114 and len(lst.fields["entries"]) == 114
    assert len(session.datalist) == 114
    numbers = [e["number"] for e in lst.fields["entries"]]
    assert numbers == list(range(256, 256 + 114))  # ascending from 256, no holes on this server
    assert lst.fields["entries"][0]["name"] == "identSetSelfIdentifier"
    for name in ("updateNumbers", "ratioDrive", "getMapBinary", "getSensorCurrent", "getStrings"):
        assert name in session.datalist
    assert "RETURN_UNTIL_EMPTY" in session.datalist.entry("getMap").flag_set
    # UDP: the server's UDP_INTRODUCTIONs (intro key) and the client's (auth key) join this session
    udp = [(p.direction, p.name) for p in d.packets if p.transport == "udp"]
    assert sorted(udp) == [
        ("c2s", "UDP_INTRODUCTION"),
        ("s2c", "UDP_INTRODUCTION"),
        ("s2c", "UDP_INTRODUCTION"),
    ]
    intro = d.packets[0].fields
    for p in d.packets:
        if p.transport == "udp":
            assert p.fields == (
                {"auth_key": intro["auth_key"]} if p.direction == "c2s" else {"intro_key": intro["intro_key"]}
            )


def _ratios(payload: bytes) -> tuple[float, ...]:
    r = FieldReader(payload)
    values = []
    while not r.at_end():
        values.append(r.double())
    return tuple(values)


def test_drive_capture_ratio_drive_then_turn_then_jog():
    d = decoded("drive-tcponly.pcap")
    drives = d.data("ratioDrive", "c2s")
    raw = [_ratios(p.payload) for p in drives]
    assert raw == [(50.0, 0.0, 100.0)] * 20 + [(0.0, 20.0, 100.0)] * 10
    typed = [(p.fields["trans"], p.fields["rot"], p.fields["throttle"]) for p in drives]
    assert typed == [r[:3] for r in raw]
    gaps = [d.rel(b) - d.rel(a) for a, b in itertools.pairwise(drives)]
    assert all(0.05 < g < 0.15 for g in gaps)  # resent every ~100 ms, as the watchdog wants
    order = [p.name for p in d.packets if p.direction == "c2s" and p.is_data]
    tail = [n for n in order if n != "ratioDrive"]
    assert tail == ["stop", "turnByAngle", "moveDist"]
    assert _ratios(d.data("turnByAngle", "c2s")[0].payload) == (90.0,)
    assert _ratios(d.data("moveDist", "c2s")[0].payload) == (300.0,)
    assert next(p.fields for p in d.data("getModeInfo"))["mode_name"] == "stop"
    assert "ratioDrive" in [p.fields["mode_name"] for p in d.data("getModeInfo")]
    stops = [p for p in d.packets if p.name == "REQUESTSTOP"]
    assert sorted(p.fields["data_name"] for p in stops) == ["getModeInfo", "updateNumbers", "updateStrings"]


def test_drive_capture_statuses_match_the_decoded_poses_file():
    d = decoded("drive-tcponly.pcap")
    rows = []
    for line in (CAPTURES / "drive-tcponly.poses.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        rows.append(line.split()[:9])
    numbers = d.data("updateNumbers")
    assert len(numbers) == len(rows) == 105
    for packet, row in zip(numbers, rows, strict=True):
        battery, x, y, th, vel, rot, lat, temp = struct.unpack("<hiihhhhb", packet.payload)
        expected = [f"{d.rel(packet):.3f}", f"{battery / 10:.1f}", *map(str, (x, y, th, vel, rot, lat, temp))]
        assert row == expected
        f = packet.fields
        typed = (f["x"], f["y"], f["th"], f["vel"], f["rot_vel"], f["lat_vel"], f["temperature"])
        assert typed == (x, y, th, vel, rot, lat, temp)


def _map_file(name: str) -> dict[str, list[str]]:
    sections: dict[str, list[str]] = {"header": [], "LINES": [], "DATA": []}
    current = "header"
    for line in (ARIA_MAPS / name).read_text(encoding="latin-1").splitlines():
        if line in ("LINES", "DATA"):
            current = line
            continue
        sections[current].append(line)
    return sections


def _binary_map(
    payloads: list[bytes],
) -> tuple[list[str], list[tuple[int, ...]], list[tuple[int, int]], list[int]]:
    """getMapBinary as §4.5 tells it: text until LINES/DATA, then binary blocks until a zero count."""
    text: list[str] = []
    segments: list[tuple[int, ...]] = []
    points: list[tuple[int, int]] = []
    point_blocks: list[int] = []
    section = None
    assert payloads[-1] == b""
    for payload in payloads[:-1]:
        if section is None:
            line = FieldReader(payload).string()
            text.append(line)
            if line in ("LINES", "DATA"):
                section = line
            continue
        (count,) = struct.unpack_from("<i", payload)
        if count == 0:
            assert len(payload) == 4
            section = None
            continue
        width = 4 if section == "LINES" else 2
        assert len(payload) == 4 + count * 4 * width and count <= 1000
        values = struct.unpack_from(f"<{count * width}i", payload, 4)
        rows = [values[i : i + width] for i in range(0, len(values), width)]
        if section == "LINES":
            segments.extend(rows)
        else:
            points.extend(rows)  # type: ignore[arg-type]
            point_blocks.append(count)
    return text, segments, points, point_blocks


def _ints(lines: list[str]) -> list[tuple[int, ...]]:
    return [tuple(int(v) for v in line.split()) for line in lines]


def test_columbia_binary_map_delivers_63311_points_in_64_blocks():
    d = decoded("map-binary-columbia.pcap")
    replies = d.data("getMapBinary", conn=1)
    text, segments, points, blocks = _binary_map([p.payload for p in replies])
    assert len(blocks) == 64 and sum(blocks) == 63311 == len(points)
    assert "NumPoints: 63311" in text and text[0] == "2D-Map"
    assert "Resolution: 20" in text
    columbia = _map_file("columbia.map")
    assert points == _ints(columbia["DATA"])
    assert segments == _ints(columbia["LINES"]) and len(segments) == 470
    typed = Counter(p.fields.get("kind") for p in replies)
    assert (
        typed["points"] == 64
        and sum(p.fields.get("count", 0) for p in replies if p.fields.get("kind") == "points") == 63311
    )
    assert [d.rel(p) for p in replies] == sorted(d.rel(p) for p in replies)
    (name,) = d.data("getMapName", conn=1)
    assert name.fields["file_name"].endswith("columbia.map")
    (ident,) = d.data("getMapId", conn=1)
    assert ident.fields["size"] == (ARIA_MAPS / "columbia.map").stat().st_size


def test_columbia_text_map_delivers_every_line():
    d = decoded("map-binary-columbia.pcap")
    replies = d.data("getMap", conn=2)
    assert len(replies) == 63823 and len(d.data("getMap", "c2s", conn=2)) == 1  # 63 824 getMap packets
    assert replies[-1].payload == b"" and replies[-1].note == "end of reply"
    lines = [FieldReader(p.payload).string() for p in replies[:-1]]
    assert lines[-1] == ""  # end of map
    lines = lines[:-1]
    assert [p.fields["line"] for p in replies[:-2]] == lines
    columbia = _map_file("columbia.map")
    start = lines.index("DATA")
    assert lines[start + 1 :] == columbia["DATA"]
    assert lines[lines.index("LINES") + 1 : start] == columbia["LINES"]
    assert lines[0] == "2D-Map" and len(lines) == 63821


def test_office_map_is_lines_only():
    d = decoded("map-binary.pcap")
    text, segments, points, _ = _binary_map([p.payload for p in d.data("getMapBinary", conn=1)])
    office = _map_file("office.map")
    assert segments == _ints(office["LINES"]) and len(segments) == 101
    assert points == [] and text[-1] == "DATA"
    lines = [p.fields["line"] for p in d.data("getMap", conn=2)]
    assert lines[-2:] == ["", None]
    assert lines[lines.index("LINES") + 1 : lines.index("DATA")] == office["LINES"]


def test_video_frame_is_a_jpeg_with_two_trailing_bytes():
    from PIL import Image

    d = decoded("getVideoExample-serverDemo.pcap")
    (request,) = d.data("sendVideo", "c2s")
    (frame,) = d.data("sendVideo")
    width, height = struct.unpack_from("<HH", frame.payload)
    jpeg = frame.payload[4:-2]
    assert jpeg[:2] == b"\xff\xd8" and jpeg[-2:] == b"\xff\xd9"
    assert frame.payload[-4:-2] == b"\xff\xd9"  # the forwarder's 2 extra bytes follow the end marker
    with Image.open(io.BytesIO(jpeg)) as image:
        image.load()
        assert image.format == "JPEG" and image.size == (width, height) == (320, 240)
    assert (frame.fields["width"], frame.fields["height"]) == (320, 240)
    assert frame.fields["trailing"] == frame.payload[-2:].hex()
    assert request.payload == b""


def test_strings_pair_values_with_labels():
    d = decoded("strings.pcap")
    (info,) = d.data("getStringsInfo")
    r = FieldReader(info.payload)
    labels = [(r.string(), r.ubyte2()) for _ in range(r.ubyte2())]
    assert labels == [("Motor Packet Count", 10)]
    values = d.data("getStrings")
    assert len(values) == 6
    for packet in values:
        r = FieldReader(packet.payload)
        texts = []
        while not r.at_end():
            texts.append(r.string())
        assert len(texts) == len(labels)
        assert texts[0].isdigit()
    requests = {p.fields["data_name"]: p.fields["interval_ms"] for p in d.packets if p.name == "REQUEST"}
    assert requests == {"updateStrings": -1, "updateNumbers": 100, "getStrings": 1000}
    assert len(d.data("updateNumbers")) == 59 and {p.transport for p in d.data("updateNumbers")} == {"udp"}
    assert json_safe(info.fields) and json_safe(values[0].fields)


def json_safe(value: object) -> bool:
    import json

    json.dumps(value, allow_nan=False)
    return True


def test_sensors_sonar_sees_the_wall_one_metre_ahead():
    d = decoded("sensors.pcap")
    (listing,) = d.data("getSensorList")
    r = FieldReader(listing.payload)
    names = [r.string() for _ in range(r.byte2())]
    assert names == ["sim_lms2xx_1", "bumpers", "irs", "sonar"]
    asked = [tuple(p.fields["names"]) for p in d.data("getSensorCurrent", "c2s")]
    assert asked == [
        ("sim_lms2xx_1",),
        ("bumpers",),
        ("irs",),
        ("sonar",),
        ("sonar", "sim_lms2xx_1"),
        ("nosuch",),
    ]
    replies = {}
    for p in d.data("getSensorCurrent"):
        r = FieldReader(p.payload)
        count = r.byte2()
        name = r.string()
        readings = [(r.byte4(), r.byte4()) for _ in range(max(count, 0))]
        assert r.at_end()
        replies.setdefault(name, []).append((count, readings))
        assert p.fields["name"] == name and [tuple(x) for x in p.fields["readings"]] == readings
    assert [c for c, _ in replies["sonar"]] == [24, 24]
    assert [c for c, _ in replies["sim_lms2xx_1"]] == [181, 181]
    assert replies["nosuch"] == [(-1, [])] and replies["bumpers"] == [(0, [])]
    (pose,) = d.data("updateNumbers")
    x, y, th = pose.fields["x"], pose.fields["y"], pose.fields["th"]
    ahead = []
    for rx, ry in replies["sonar"][0][1]:
        bearing = math.degrees(math.atan2(ry - y, rx - x)) - th
        if abs((bearing + 180) % 360 - 180) < 15:
            ahead.append(math.hypot(rx - x, ry - y))
    assert ahead and all(950 < dist < 1050 for dist in ahead)


def test_robot_update_example_gets_update_numbers_over_udp_in_its_session():
    d = decoded("robotUpdateExample-serverDemo.pcap")
    (session,) = d.decoder.sessions
    numbers = d.data("updateNumbers")
    assert len(numbers) == 58 and {(p.conn, p.transport) for p in numbers} == {(session.id, "udp")}
    assert session.udp_datagrams == 61 and session.client_udp_port == 10000
    assert [p.transport for p in d.data("updateStrings")] == ["tcp"]


# -- every registered payload type re-encodes every real packet ---------------------------------
MUST_ROUND_TRIP = [
    ("updateNumbers", Side.REPLY),
    ("updateStrings", Side.REPLY),
    ("getModeInfo", Side.REPLY),
    ("ratioDrive", Side.ARGS),
    ("turnByAngle", Side.ARGS),
    ("moveDist", Side.ARGS),
    ("getMapName", Side.REPLY),
    ("getMapId", Side.REPLY),
    ("getMapBinary", Side.REPLY),
    ("getMap", Side.REPLY),
    ("sendVideo", Side.REPLY),
    ("getStringsInfo", Side.REPLY),
    ("getStrings", Side.REPLY),
    ("getSensorList", Side.REPLY),
    ("getSensorCurrent", Side.REPLY),
    ("getSensorCurrent", Side.ARGS),
]


def _typed_payloads(d: Decoded):
    """(name, side, payload) of every data payload and every REQUEST's arguments."""
    for p in d.packets:
        if p.is_data and p.name:
            yield p.name, side_of(p.direction), p.payload
        elif (
            p.name == "REQUEST" and p.direction == "c2s" and p.fields.get("data_name") and len(p.payload) > 6
        ):
            yield p.fields["data_name"], Side.ARGS, p.payload[6:]


@functools.cache
def round_trips() -> Counter[tuple[str, Side]]:
    """Check every typed packet of every capture; return how many were checked per (name, side)."""
    checked: Counter[tuple[str, Side]] = Counter()
    failures = []
    for name in CAPTURE_NAMES:
        for data_name, side, payload in _typed_payloads(decoded(name)):
            kind = payload_type_for(data_name, side)
            if kind is None:
                continue
            try:
                again = kind.decode(payload).encode()
            except Exception as exc:
                if payload:
                    failures.append(f"{name}: {data_name} {side.value}: {exc!r}")
                continue  # an empty payload is an end marker, not every type's business
            if again != payload:
                failures.append(f"{name}: {data_name} {side.value}: {payload.hex()} → {again.hex()}")
            checked[(data_name, side)] += 1
    assert failures == []
    return checked


def test_every_registered_type_re_encodes_real_packets_byte_for_byte():
    checked = round_trips()
    assert sum(checked.values()) > 60000  # the columbia map alone carries 63 823 typed packets


@pytest.mark.parametrize(
    ("name", "side"), MUST_ROUND_TRIP, ids=[f"{n}-{s.value}" for n, s in MUST_ROUND_TRIP]
)
def test_payload_types_cover_the_captured_services(name, side):
    # A missing type is a failure, not a skip: every service the captures carry must decode.
    assert payload_type_for(name, side) is not None, f"no payload type for {name} ({side.value}) registered"
    assert round_trips()[(name, side)] >= 1


# -- every control packet re-encodes too --------------------------------------------------------
MUST_ROUND_TRIP_CONTROL = [
    ("s2c", "INTRODUCTION"),
    ("c2s", "INTRODUCTION"),
    ("c2s", "TCP_ONLY"),
    ("s2c", "CONNECTED"),
    ("c2s", "REQUEST"),
    ("c2s", "REQUESTSTOP"),
    ("c2s", "UDP_INTRODUCTION"),
    ("s2c", "UDP_INTRODUCTION"),
    ("c2s", "SHUTDOWN"),
]


@functools.cache
def control_round_trips() -> Counter[tuple[str, str]]:
    """Decode and re-encode every control packet of every capture (lists aside); how many per kind."""
    checked: Counter[tuple[str, str]] = Counter()
    failures = []
    for name in CAPTURE_NAMES:
        for p in decoded(name).packets:
            if p.is_data or (p.name or "").startswith("LIST"):
                continue
            kind = control.control_type(p.command, side_of(p.direction))
            if kind is None:
                failures.append(f"{name}: no control type for {p.direction} {p.name or p.command}")
                continue
            again = kind.decode(p.payload).encode()
            if again != p.payload:
                failures.append(f"{name}: {p.direction} {p.name}: {p.payload.hex()} → {again.hex()}")
            checked[(p.direction, p.name or str(p.command))] += 1
    assert failures == []
    return checked


def test_every_control_packet_re_encodes_byte_for_byte():
    checked = control_round_trips()
    for kind in MUST_ROUND_TRIP_CONTROL:
        assert checked[kind] >= 1, f"no {kind} in the captures"
    assert checked[("s2c", "INTRODUCTION")] == checked[("c2s", "INTRODUCTION")] == 10
    assert sum(checked.values()) >= 79


def test_every_captured_data_list_is_rebuilt_byte_for_byte():
    """The lists a server sends (LIST, LISTARGRET, LISTGROUPANDFLAGS) are what DataList builds from them."""
    rebuilt = 0
    for name in CAPTURE_NAMES:
        d = decoded(name)
        for session in d.decoder.sessions:
            if session.transport != "tcp":
                continue
            sent = [
                (p.command, p.payload)
                for p in d.packets
                if p.conn == session.id and p.direction == "s2c" and (p.name or "").startswith("LIST")
            ]
            assert sent == [(p.command, p.payload) for p in session.datalist.list_packets()], name
            rebuilt += 1
    assert rebuilt == 10
