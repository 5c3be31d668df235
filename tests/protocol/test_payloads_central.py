"""The central server's packets, byte for byte as ARIA's ``ArCentralManager`` builds them."""

from __future__ import annotations

import pytest

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads import Side, decode_payload
from rtmu.protocol.payloads.central import (
    ENTRY_MIN_BYTES,
    CentralEntry,
    ClientAdded,
    ClientList,
    ClientRemoved,
    SwitchRequest,
)


def aria_entry(port: int, name: str, ip: str) -> bytes:
    """As ``netClientList`` writes one: empty host, ubyte2 port, name, empty flags, IP (strings NUL-ended)."""
    return b"\x00" + port.to_bytes(2, "little") + name.encode() + b"\x00" + b"\x00" + ip.encode() + b"\x00"


def test_client_list_reads_arias_layout() -> None:
    entries = aria_entry(7273, "patrolbot", "10.0.0.5") + aria_entry(7274, "", "10.0.0.6")
    raw = (2).to_bytes(2, "little") + entries
    listed = ClientList.decode(raw)
    assert listed.entries == (
        CentralEntry("", 7273, "patrolbot", "", "10.0.0.5"),
        CentralEntry("", 7274, "", "", "10.0.0.6"),
    )
    assert listed.encode() == raw


def test_added_and_removed_carry_one_entry_without_a_count() -> None:
    raw = aria_entry(7275, "seekur", "192.168.1.20")
    assert ClientAdded.decode(raw).entry == CentralEntry("", 7275, "seekur", "", "192.168.1.20")
    assert ClientRemoved.decode(raw).encode() == raw
    assert decode_payload("clientAdded", Side.REPLY, raw) == ClientAdded.decode(raw)


def test_switch_asks_with_the_robot_identifier() -> None:
    assert SwitchRequest("robot1").encode() == b"robot1\x00"
    assert SwitchRequest.decode(b"\x00").robot_name == ""
    assert decode_payload("switch", Side.REPLY, b"") is not None  # the empty acceptance


def test_a_count_larger_than_the_bytes_is_refused_before_anything_is_built() -> None:
    raw = (10_000).to_bytes(2, "little") + aria_entry(7273, "one", "10.0.0.1")
    with pytest.raises(PayloadError, match="robot count claims 10000"):
        ClientList.decode(raw)


def test_a_truncated_entry_names_its_field() -> None:
    raw = (1).to_bytes(2, "little") + aria_entry(7273, "one", "10.0.0.1")[:7]  # up to the name
    with pytest.raises(FieldUnderrun, match="flags"):
        ClientList.decode(raw)


def test_the_largest_list_one_packet_can_hold_decodes_and_is_bounded_by_the_packet() -> None:
    count = (MAX_PAYLOAD - 2) // ENTRY_MIN_BYTES  # 5331 entries of four empty strings and a port
    raw = count.to_bytes(2, "little") + b"\x00\x01\x00\x00\x00\x00" * count
    assert len(raw) <= MAX_PAYLOAD
    assert len(ClientList.decode(raw).entries) == count


def test_markup_in_names_is_kept_as_the_exact_text() -> None:
    name = '<span foreground="red">x</span> &amp; \x1b[2J'
    entry = CentralEntry("", 7300, name, "", "10.0.0.9")
    assert ClientAdded.decode(ClientAdded(entry).encode()).entry.name == name
