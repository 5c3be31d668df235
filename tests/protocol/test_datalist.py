"""The data catalogue and its three list packets (protocol §2.7–2.8)."""

from __future__ import annotations

import contextlib

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol import DataEntry, DataList, FieldWriter, Packet, PacketDecoder, PayloadError, ServerCommand
from rtmu.protocol.packet import MAX_LENGTH
from testdata import CAPTURES

from .test_packet import tcp_streams

ROWS = [
    ("identSetSelfIdentifier", "sets our identifier", "string: id", "none", "", "RETURN_NONE"),
    ("updateNumbers", "robot status numbers", "none", "byte2 battery ...", "RobotInfo", "RETURN_SINGLE"),
    ("ratioDrive", "drive by ratios", "double trans ...", "none", "Movement", "RETURN_NONE"),
    ("getMap", "the map as text", "none", "strings", "Map", "RETURN_UNTIL_EMPTY|SLOW_PACKET"),
]


def catalogue() -> DataList:
    return DataList.build(ROWS)


def absorb_all(packets: list[Packet]) -> DataList:
    client = DataList()
    for packet in packets:
        assert client.absorb(packet)
    return client


def test_build_numbers_from_256_in_order() -> None:
    dl = catalogue()
    assert [e.number for e in dl] == [256, 257, 258, 259]
    assert dl.number("ratioDrive") == 258
    assert dl.name(259) == "getMap"
    assert dl.entry(257) == dl.entry("updateNumbers")
    assert dl.entry("nope") is None and dl.entry(999) is None
    assert dl.number("nope") is None and dl.name(1) is None
    assert "getMap" in dl and "nope" not in dl
    assert len(dl) == 4
    assert dl.entry("getMap").flag_set == frozenset({"RETURN_UNTIL_EMPTY", "SLOW_PACKET"})  # type: ignore[union-attr]
    assert DataEntry(1, "x").flag_set == frozenset()


def test_list_packets_come_in_arias_order_with_exact_contents() -> None:
    packets = catalogue().list_packets()
    assert [p.command for p in packets] == [
        ServerCommand.LIST,
        ServerCommand.LISTARGRET,
        ServerCommand.LISTGROUPANDFLAGS,
    ]
    expected_list = FieldWriter().ubyte2(4)
    for number, (name, description, *_) in enumerate(ROWS, 256):
        expected_list.ubyte2(number).string(name).string(description)
    assert packets[0].payload == expected_list.bytes()
    assert packets[1].payload.startswith(b"\x04\x00\x00\x01string: id\x00none\x00")
    assert packets[2].payload.startswith(b"\x04\x00\x00\x01\x00RETURN_NONE\x00\x01\x01RobotInfo\x00")


def test_client_absorbs_what_the_server_sends() -> None:
    server = catalogue()
    client = absorb_all(server.list_packets())
    assert list(client) == list(server)
    assert client.complete


def test_catalogue_is_complete_only_after_group_and_flags() -> None:
    list_packet, argret, groups = catalogue().list_packets()
    client = DataList()
    client.absorb(list_packet)
    assert client.have_list and not client.complete
    assert client.number("getMap") == 259  # LIST alone is enough to start requesting
    client.absorb(argret)
    assert client.have_argret and not client.complete
    client.absorb(groups)
    assert client.complete


def test_non_list_packets_are_not_absorbed() -> None:
    client = DataList()
    for command in (ServerCommand.CONNECTED, ServerCommand.REJECTED, 256, 300):
        assert not client.absorb(Packet(command, b""))
    assert len(client) == 0


def test_large_argument_descriptions_split_listargret_over_several_packets() -> None:
    rows = [(f"data{i}", "d", "a" * 300 + str(i), "r" * 100, "", "") for i in range(200)]
    server = DataList.build(rows)
    packets = server.list_packets()
    commands = [p.command for p in packets]
    argrets = [p for p in packets if p.command == ServerCommand.LISTARGRET]
    assert len(argrets) >= 3
    assert commands == [
        ServerCommand.LIST,
        *[ServerCommand.LISTARGRET] * len(argrets),
        ServerCommand.LISTGROUPANDFLAGS,
    ]
    counts = [int.from_bytes(p.payload[:2], "little") for p in argrets]
    assert sum(counts) == 200  # each packet carries its own count
    assert all(len(p.encode()) <= MAX_LENGTH for p in packets)
    # the wire round trip, through the decoder
    stream = b"".join(p.encode() for p in packets)
    client = absorb_all(PacketDecoder().feed(stream))
    assert client.complete
    assert client.entry("data199").argument_description == "a" * 300 + "199"  # type: ignore[union-attr]
    assert list(client) == list(server)


def test_single_variants_carry_one_entry_without_a_count() -> None:
    client = absorb_all(catalogue().list_packets())
    client.absorb(
        Packet(ServerCommand.LISTSINGLE, FieldWriter().ubyte2(300).string("late").string("d").bytes())
    )
    client.absorb(
        Packet(ServerCommand.LISTARGRETSINGLE, FieldWriter().ubyte2(300).string("a").string("r").bytes())
    )
    client.absorb(
        Packet(
            ServerCommand.LISTGROUPANDFLAGSSINGLE, FieldWriter().ubyte2(300).string("G").string("F").bytes()
        )
    )
    assert client.entry("late") == DataEntry(300, "late", "d", "a", "r", "G", "F")


def test_argret_for_an_unknown_number_is_skipped() -> None:
    client = absorb_all(catalogue().list_packets()[:1])
    payload = FieldWriter().ubyte2(2).ubyte2(999).string("a").string("r").ubyte2(256).string("x").string("y")
    client.absorb(Packet(ServerCommand.LISTARGRET, payload.bytes()))
    assert client.entry(999) is None
    assert client.entry(256).argument_description == "x"  # type: ignore[union-attr]


def test_relisting_a_number_renames_it() -> None:
    client = absorb_all(catalogue().list_packets())
    client.absorb(
        Packet(ServerCommand.LISTSINGLE, FieldWriter().ubyte2(257).string("renamed").string("").bytes())
    )
    assert client.number("renamed") == 257
    assert "updateNumbers" not in client
    assert client.entry(257).command_group == "RobotInfo"  # type: ignore[union-attr]


def test_entries_that_did_not_fit_are_tolerated() -> None:
    """ARIA drops entries and fields that overflow its packet: the count may promise more."""
    payload = FieldWriter().ubyte2(5).ubyte2(256).string("a").string("b").ubyte2(257).string("c").bytes()
    client = DataList()
    client.absorb(Packet(ServerCommand.LIST, payload))
    assert [(e.number, e.name, e.description) for e in client] == [(256, "a", "b"), (257, "c", "")]
    client.absorb(Packet(ServerCommand.LIST, payload + b"\x01"))  # half a data number: ignored
    assert len(client) == 2


def test_absurd_count_is_a_payload_error() -> None:
    with pytest.raises(PayloadError, match="65535"):
        DataList().absorb(Packet(ServerCommand.LIST, b"\xff\xff" + b"\x00\x01a\x00b\x00"))


@given(st.integers(129, 134), st.binary(max_size=200))
def test_any_list_payload_is_absorbed_or_refused_cleanly(command: int, payload: bytes) -> None:
    client = DataList()
    with contextlib.suppress(PayloadError):
        client.absorb(Packet(command, payload))
    assert len(client) <= len(payload)


def test_visible_to_filters_by_command_group() -> None:
    dl = catalogue()
    assert dl.visible_to(None) is dl
    assert dl.visible_to({"ALL"}) is dl
    bob = dl.visible_to({"RobotInfo", "movement", "Stop"})
    assert [e.name for e in bob] == ["identSetSelfIdentifier", "updateNumbers", "ratioDrive"]
    assert bob.number("ratioDrive") == 258  # numbers are kept
    assert [e.name for e in dl.visible_to(set())] == ["identSetSelfIdentifier"]


def test_the_captured_catalogue_of_a_real_server() -> None:
    """clientCommandLister against serverDemo: 114 data in LIST, LISTARGRET, LISTGROUPANDFLAGS."""
    streams = tcp_streams(CAPTURES / "clientCommandLister-serverDemoMap.pcap")
    from_server = next(s for (_, sport, _, _), s in streams.items() if sport == 7272)
    client = DataList()
    for packet in PacketDecoder().feed(from_server):
        client.absorb(packet)
    assert client.complete
    assert len(client) == 114
    assert [e.number for e in client] == list(range(256, 256 + 114))
    assert client.number("identSetSelfIdentifier") == 256
    for name in ("updateNumbers", "updateStrings", "ratioDrive", "getMap", "stop"):
        assert name in client, name
    assert "RETURN_SINGLE" in client.entry("updateNumbers").flag_set  # type: ignore[union-attr]
    # and our server side writes the same catalogue back as the same packets
    ours = b"".join(p.encode() for p in client.list_packets())
    assert ours in from_server
