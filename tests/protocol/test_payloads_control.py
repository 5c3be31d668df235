"""Control packets: every type round-trips, documented bytes decode, malformed bytes are protocol errors."""

from __future__ import annotations

import contextlib
import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.protocol.commands import ClientCommand, ServerCommand
from rtmu.protocol.errors import FieldUnderrun, ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads import control as ctl

DIGEST = bytes.fromhex("d41d8cd98f00b204e9800998ecf8427e")
SAMPLES: list[ctl.ControlPayload] = [
    ctl.ServerIntroduction("alpha", 17272, 0x1E564427, 0x35E51CAF, "_yDK=p6JTRp0j_Iq6lNF1xs", "6MTX"),
    ctl.Rejected(4, "Server rejecting client connection since protocol version does not match"),
    ctl.ServerUdpIntroduction(0x35E51CAF),
    ctl.ServerShutdown(),
    ctl.Connected(),
    ctl.ServerUdpConfirmation(),
    ctl.ServerTcpOnly(),
    ctl.ClientIntroduction(10000, "alice", DIGEST, "6MTX", 2),
    ctl.Request(0x0108, -1, b"sonar\x00"),
    ctl.RequestStop(0x0108),
    ctl.ClientUdpIntroduction(0x1E564427),
    ctl.ClientShutdown(),
    ctl.ClientUdpConfirmation(),
    ctl.ClientTcpOnly(),
]
TYPES = sorted(ctl.control_types().values(), key=lambda c: (c.SIDE.value, c.COMMAND))
WITH_FIELDS = [s for s in SAMPLES if s.encode()]


def test_every_control_type_has_a_sample_and_every_handshake_command_a_type() -> None:
    assert {type(s) for s in SAMPLES} == set(TYPES)
    for command in ClientCommand:
        if command is not ClientCommand.LIST:  # declared by ARIA, never sent
            assert ctl.control_type(command, Side.ARGS) is not None, command
    for command in ServerCommand:
        if not command.name.startswith("LIST"):  # the list packets belong to DataList
            assert ctl.control_type(command, Side.REPLY) is not None, command
    assert ctl.control_type(ServerCommand.LIST, Side.REPLY) is None


def test_control_types_stay_out_of_the_data_name_registry() -> None:
    # A data could be named like a command; only numbers below 256 are control packets.
    assert payload_type_for("INTRODUCTION", Side.REPLY) is None
    assert payload_type_for("", Side.ARGS) is None


def test_the_same_number_is_a_different_packet_in_each_direction() -> None:
    assert ctl.control_type(5, Side.ARGS) is ctl.ClientTcpOnly
    assert ctl.control_type(5, Side.REPLY) is ctl.Connected
    assert ctl.control_type(129, Side.ARGS) is ctl.Request
    assert ctl.control_type(2, Side.ARGS) is ctl.ClientIntroduction
    assert ctl.control_type(2, Side.REPLY) is ctl.ServerIntroduction


@pytest.mark.parametrize("sample", SAMPLES, ids=lambda s: type(s).__name__)
def test_sample_round_trips_and_prints_as_json(sample: ctl.ControlPayload) -> None:
    raw = sample.encode()
    assert type(sample).decode(raw) == sample
    assert type(sample).decode(raw).encode() == raw
    json.dumps(sample.to_fields())


@pytest.mark.parametrize("sample", WITH_FIELDS, ids=lambda s: type(s).__name__)
def test_every_truncation_is_a_protocol_error_or_a_shorter_valid_payload(sample: ctl.ControlPayload) -> None:
    raw = sample.encode()
    for cut in range(len(raw)):
        with contextlib.suppress(ProtocolError):
            type(sample).decode(raw[:cut])


@pytest.mark.parametrize("cls", TYPES, ids=lambda c: c.__name__)
@settings(max_examples=150, deadline=None)
@given(raw=st.binary(max_size=64))
def test_random_bytes_never_raise_anything_but_protocol_errors(
    cls: type[ctl.ControlPayload], raw: bytes
) -> None:
    try:
        decoded = cls.decode(raw)
    except ProtocolError:
        return
    json.dumps(decoded.to_fields())


@settings(max_examples=200, deadline=None)
@given(
    udp=st.integers(0, 0xFFFF),
    user=st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=20),
    digest=st.binary(min_size=16, max_size=16),
    version=st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=8),
    client_type=st.integers(-128, 127),
)
def test_any_client_introduction_round_trips(
    udp: int, user: str, digest: bytes, version: str, client_type: int
) -> None:
    intro = ctl.ClientIntroduction(udp, user, digest, version, client_type)
    assert ctl.ClientIntroduction.decode(intro.encode()) == intro


@settings(max_examples=200, deadline=None)
@given(number=st.integers(0, 0xFFFF), interval=st.integers(-(2**31), 2**31 - 1), args=st.binary(max_size=40))
def test_any_request_round_trips(number: int, interval: int, args: bytes) -> None:
    request = ctl.Request(number, interval, args)
    assert ctl.Request.decode(request.encode()) == request


# -- the protocol document's bytes -------------------------------------------------------------


def test_captured_server_introduction() -> None:
    """§2.4's capture: UDP port 17272, the two keys, a 23-character password key, no version."""
    raw = b"alpha\x00" + bytes.fromhex("7843 2744561e af1ce535") + b"_yDK=p6JTRp0j_Iq6lNF1xs\x00\x00"
    intro = ctl.ServerIntroduction.decode(raw)
    assert intro == ctl.ServerIntroduction(
        "alpha", 17272, 0x1E564427, 0x35E51CAF, "_yDK=p6JTRp0j_Iq6lNF1xs", ""
    )
    assert intro.encode() == raw


def test_captured_client_introduction() -> None:
    """§2.5: the C++ client with no user and no password, UDP port 10000."""
    raw = bytes.fromhex("1027 00 d41d8cd98f00b204e9800998ecf8427e 00 00")
    intro = ctl.ClientIntroduction.decode(raw)
    assert intro == ctl.ClientIntroduction(10000, "", DIGEST, "", 0)
    assert intro.encode() == raw


def test_captured_reason_1_rejection() -> None:
    raw = bytes.fromhex("0100 00")
    rejected = ctl.Rejected.decode(raw)
    assert (rejected.reason, rejected.text) == (1, "")
    assert rejected.encode() == raw
    assert "wrong user name or password" in rejected.explanation


def test_request_keeps_its_arguments_as_bytes() -> None:
    assert ctl.Request(0x0108, 100).encode() == bytes.fromhex("0801 64000000")
    assert ctl.Request.decode(bytes.fromhex("0801 ffffffff") + b"sonar\x00") == ctl.Request(
        0x0108, -1, b"sonar\x00"
    )


# -- what is optional and what is not ----------------------------------------------------------


def test_optional_trailing_fields_read_as_aria_reads_them() -> None:
    assert ctl.Rejected.decode(b"") == ctl.Rejected(0, "")
    assert ctl.ServerIntroduction.decode(b"alpha\x00" + bytes(10) + b"key\x00").protocol_version == ""
    short = ctl.ClientIntroduction.decode(bytes(2) + b"bob\x00" + DIGEST)
    assert (short.protocol_version, short.client_type) == ("", 0)


@pytest.mark.parametrize(
    ("cls", "raw", "field"),
    [
        (ctl.ServerIntroduction, b"alpha\x00\x01", "server UDP port"),
        (ctl.ServerIntroduction, b"", "version tag"),
        (ctl.ServerIntroduction, b"alpha\x00" + bytes(10), "password key"),
        (ctl.ClientIntroduction, b"\x00\x00bob\x00\x01\x02", "password digest"),
        (ctl.ClientIntroduction, b"\x00", "client UDP port"),
        (ctl.ClientIntroduction, b"\x00\x00", "user name"),
        (ctl.Request, b"\x08\x01\x00", "interval"),
        (ctl.Request, b"", "data number"),
        (ctl.RequestStop, b"\x08", "data number"),
        (ctl.ServerUdpIntroduction, b"\x01\x02\x03", "intro key"),
        (ctl.ClientUdpIntroduction, b"", "auth key"),
    ],
)
def test_missing_required_fields_name_the_field(
    cls: type[ctl.ControlPayload], raw: bytes, field: str
) -> None:
    with pytest.raises(FieldUnderrun) as info:
        cls.decode(raw)
    assert info.value.field == field


def test_a_digest_of_the_wrong_length_is_not_sent() -> None:
    with pytest.raises(ValueError, match="16 bytes"):
        ctl.ClientIntroduction(0, "bob", b"short").encode()
