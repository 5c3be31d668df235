"""ArConfig payloads: hand-built section packets per version, setConfig pairs, round trips, hostile input."""

from __future__ import annotations

import contextlib
import struct
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, PayloadError, ProtocolError
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.config import (
    MAX_LIST_DEPTH,
    ConfigParam,
    ConfigRequest,
    ConfigSectionFlags,
    ConfigSectionPacket,
    ConfigSectionPacketV1,
    ConfigSectionPacketV2,
    ConfigSectionPacketV3,
    ConfigUpdated,
    LastEditablePriority,
    ParamType,
    Priority,
    SetConfig,
    SetConfigReply,
)


def s(text: str) -> bytes:
    return text.encode("latin-1") + b"\x00"


def i4(value: int) -> bytes:
    return struct.pack("<i", value)


def test_a_v4_section_packet_decodes_field_by_field_as_aria_writes_it() -> None:
    raw = (
        b"S" + s("Teleop") + s("Driving") + s("Motion") + struct.pack("<H", 1)
        + b"P" + s("Timeout") + s("seconds") + bytes([1]) + b"d" + s("2") + s("0") + s("60") + i4(1)
        + s("") + s("longer text") + bytes([0]) + bytes([1]) + s("")
        + b"P" + s("Fast") + s("") + bytes([0]) + b"b" + bytes([1]) + s("") + s("") + bytes([3])
        + bytes([0]) + s("")
        + b"P" + s("") + s("") + bytes([0]) + b"." + s("") + s("") + bytes([0]) + bytes([0]) + s("")
        + b"P" + s("Mode") + s("how") + bytes([4]) + b"s" + s("a") + s("Choices:a;;b") + s("") + bytes([0])
        + bytes([0]) + s("")
        + b"P" + s("Count") + s("") + bytes([2]) + b"i" + i4(-5) + i4(-10) + i4(10) + s("") + s("")
        + bytes([0]) + bytes([0]) + s("")
    )  # fmt: skip
    packet = ConfigSectionPacket.decode(raw)
    assert (packet.name, packet.comment, packet.category, packet.index, packet.end) == (
        "Teleop", "Driving", "Motion", 1, False,
    )  # fmt: skip
    timeout, fast, sep, mode, count = packet.params
    assert timeout == ConfigParam(
        "Timeout", ParamType.DOUBLE, 2.0, "seconds", Priority.INTERMEDIATE, 0.0, 60.0, 1,
        extra="longer text", serializable=True,
    )  # fmt: skip
    assert (fast.kind, fast.value, fast.restart) == (ParamType.BOOL, True, 3)
    assert sep.kind is ParamType.SEPARATOR and sep.value is None
    assert mode.choices == ("a", "b") and mode.priority == Priority.FACTORY
    assert (count.value, count.minimum, count.maximum) == (-5, -10, 10)
    assert packet.encode() == raw


def test_older_versions_lack_category_index_precision_explanation_and_restart() -> None:
    param = b"P" + s("Speed") + s("mm/s") + bytes([0]) + b"d" + s("1.5") + s("-INF") + s("INF") + s("")
    v1 = b"S" + s("Robot") + s("") + param
    got = ConfigSectionPacketV1.decode(v1)
    assert got.params[0].value == 1.5 and got.params[0].minimum == float("-inf")
    assert got.params[0].precision == -1 and got.encode() == v1
    v2_param = b"P" + s("Speed") + s("") + bytes([0]) + b"d" + s("1") + s("0") + s("2") + i4(3) + s("")
    v2 = b"S" + s("Robot") + s("") + s("cat") + v2_param + s("why") + bytes([2])
    got2 = ConfigSectionPacketV2.decode(v2)
    assert (got2.category, got2.params[0].precision, got2.params[0].extra, got2.params[0].restart) == (
        "cat", 3, "why", 2,
    )  # fmt: skip
    v3 = b"S" + s("Robot") + s("") + s("") + struct.pack("<H", 7)
    assert ConfigSectionPacketV3.decode(v3).index == 7


def test_upper_case_types_carry_no_display_hint() -> None:
    raw = b"S" + s("A") + s("") + b"P" + s("N") + s("") + bytes([0]) + b"I" + i4(1) + i4(0) + i4(2)
    (param,) = ConfigSectionPacketV1.decode(raw).params
    assert (param.kind, param.value, param.display_hint) == (ParamType.INT, 1, "")


def test_the_empty_packet_ends_the_reply() -> None:
    end = ConfigSectionPacket.decode(b"")
    assert end.end and end.encode() == b""


def test_lists_nest_members_with_their_own_layout() -> None:
    member = ConfigParam("x", ParamType.INT, 3, minimum=0, maximum=5)
    inner = ConfigParam("inner", ParamType.LIST, children=(member,))
    outer = ConfigParam("outer", ParamType.LIST, children=(inner, member))
    packet = ConfigSectionPacket("Lists", params=(outer,))
    assert ConfigSectionPacket.decode(packet.encode()) == packet


def test_every_config_data_finds_its_type() -> None:
    for name, cls in (
        ("getConfigBySectionsV4", ConfigSectionPacket),
        ("getConfigBySectionsV3", ConfigSectionPacketV3),
        ("getConfigBySectionsV2", ConfigSectionPacketV2),
        ("getConfigBySections", ConfigSectionPacketV1),
        ("setConfig", SetConfigReply),
        ("configUpdated", ConfigUpdated),
        ("getConfigSectionFlags", ConfigSectionFlags),
        ("getLastEditablePriority", LastEditablePriority),
    ):
        assert payload_type_for(name, Side.REPLY) is cls
    assert payload_type_for("setConfig", Side.ARGS) is SetConfig
    assert payload_type_for("getConfigBySectionsV4", Side.ARGS) is ConfigRequest


def test_set_config_is_text_pairs_with_section_pairs() -> None:
    request = SetConfig.of({"Teleop": {"Timeout": "0.5"}, "Camera": {"FrameSize": "640x480"}})
    assert request.encode() == (
        s("Section")
        + s("Teleop")
        + s("Timeout")
        + s("0.5")
        + s("Section")
        + s("Camera")
        + s("FrameSize")
        + s("640x480")
    )
    assert SetConfig.decode(request.encode()) == request
    assert request.by_section() == [("Teleop", "Timeout", "0.5"), ("Camera", "FrameSize", "640x480")]
    assert SetConfigReply.decode(b"\x00").accepted
    refused = SetConfigReply.decode(s("Teleop/Timeout: 99 is above the maximum of 60"))
    assert not refused.accepted and "Timeout" in refused.error


def test_request_args_are_the_two_optional_priority_bytes() -> None:
    assert ConfigRequest(Priority.FACTORY, Priority.EXPERT).encode() == bytes([4, 3])
    assert ConfigRequest.decode(b"") == ConfigRequest(None, None)
    assert ConfigRequest.decode(bytes([2])) == ConfigRequest(2, None)
    assert ConfigRequest(None, None).encode() == b""


def test_section_flags_and_priority_replies() -> None:
    flags = ConfigSectionFlags((("Teleop", ""), ("Robot config", "RESTRICTED|HIDDEN")))
    assert ConfigSectionFlags.decode(flags.encode()) == flags
    assert LastEditablePriority.decode(bytes([3])).priority == Priority.EXPERT
    assert Priority.of(9) is Priority.FACTORY and Priority.of(-1) is Priority.BASIC


# -- hostile input --------------------------------------------------------------------------------


def test_an_unknown_type_letter_is_a_payload_error_naming_the_parameter() -> None:
    raw = b"S" + s("A") + s("") + b"P" + s("Weird") + s("") + bytes([0]) + b"z"
    with pytest.raises(PayloadError, match="Weird"):
        ConfigSectionPacketV1.decode(raw)


def test_a_missing_marker_or_section_start_is_refused() -> None:
    with pytest.raises(PayloadError, match="'S'"):
        ConfigSectionPacket.decode(b"X" + s("A"))
    with pytest.raises(PayloadError, match="expected 'P'"):
        ConfigSectionPacketV1.decode(b"S" + s("A") + s("") + b"Q")


def test_a_truncated_parameter_names_the_field() -> None:
    raw = b"S" + s("A") + s("") + b"P" + s("Count") + s("") + bytes([0]) + b"i" + i4(1)
    with pytest.raises(FieldUnderrun, match="Count min"):
        ConfigSectionPacketV1.decode(raw)


def test_a_lying_list_count_is_refused_before_allocating() -> None:
    raw = b"S" + s("A") + s("") + b"P" + s("L") + s("") + bytes([0]) + b"l" + i4(2_000_000_000)
    started = time.perf_counter()
    with pytest.raises(PayloadError, match="L members"):
        ConfigSectionPacketV1.decode(raw)
    assert time.perf_counter() - started < 5  # refused, not looped (a generous bound: a loaded machine)


def test_lists_nested_too_deep_are_refused() -> None:
    param = ConfigParam("leaf", ParamType.BOOL, True)
    for depth in range(MAX_LIST_DEPTH + 1):
        param = ConfigParam(f"list{depth}", ParamType.LIST, children=(param,))
    with pytest.raises(PayloadError, match="nests deeper"):
        ConfigSectionPacket.decode(ConfigSectionPacket("A", params=(param,)).encode())


def test_a_full_packet_of_tiny_parameters_decodes_bounded_by_its_size() -> None:
    one = FieldWriter().byte(ord("P"))
    ConfigParam("b", ParamType.BOOL, True).write(one, 4)
    unit = one.bytes()
    head = ConfigSectionPacket("A").encode()
    raw = head + unit * ((MAX_PAYLOAD - len(head)) // len(unit))
    packet = ConfigSectionPacket.decode(raw)
    assert len(packet.params) == (MAX_PAYLOAD - len(head)) // len(unit)


def test_a_long_string_value_decodes_whole() -> None:
    text = "x" * 30_000
    packet = ConfigSectionPacket("A", params=(ConfigParam("Long", ParamType.STRING, text),))
    assert ConfigSectionPacket.decode(packet.encode()).params[0].value == text


@given(st.binary(max_size=400))
@settings(max_examples=300)
def test_any_bytes_decode_or_fail_cleanly(data: bytes) -> None:
    for cls in (ConfigSectionPacket, ConfigSectionPacketV1, ConfigSectionPacketV2, ConfigSectionPacketV3):
        with contextlib.suppress(ProtocolError):
            cls.decode(b"S" + data)
    for other in (SetConfig, SetConfigReply, ConfigSectionFlags, ConfigRequest):
        with contextlib.suppress(ProtocolError):
            other.decode(data)


# -- round trips ----------------------------------------------------------------------------------
text = st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=30)
int4 = st.integers(-(2**31), 2**31 - 1)
doubles = st.sampled_from([0.0, 1.5, -2.25, 1e-3, 123456.0, float("inf"), float("-inf")])


NONE = st.none()


def _params(version: int) -> st.SearchStrategy[ConfigParam]:
    def common(kind: ParamType, value, lo=NONE, hi=NONE):
        v2 = version >= 2
        v4 = version >= 4
        return st.builds(
            ConfigParam,
            text, st.just(kind), value, text, st.integers(0, 4), lo, hi,
            st.integers(-1, 10) if v2 and kind is ParamType.DOUBLE else st.just(-1),
            st.just(()),
            text,
            text if v2 else st.just(""),
            st.integers(0, 4) if v2 else st.just(0),
            st.booleans() if v4 else st.just(False),
            text if v4 else st.just(""),
        )  # fmt: skip

    return st.one_of(
        common(ParamType.BOOL, st.booleans()),
        common(ParamType.INT, int4, int4, int4),
        common(ParamType.DOUBLE, doubles, doubles, doubles),
        common(ParamType.STRING, text),
    )


@pytest.mark.parametrize(
    "cls", [ConfigSectionPacket, ConfigSectionPacketV3, ConfigSectionPacketV2, ConfigSectionPacketV1]
)
def test_section_packets_round_trip(cls: type[ConfigSectionPacket]) -> None:
    @given(text, text, st.lists(_params(cls.VERSION), max_size=8), st.integers(1, 65535))
    @settings(max_examples=60)
    def check(name: str, comment: str, params: list[ConfigParam], index: int) -> None:
        packet = cls(
            name, comment, tuple(params), "cat" if cls.VERSION >= 2 else "", index if cls.VERSION >= 3 else 1
        )
        assert cls.decode(packet.encode()) == packet

    check()


@given(st.lists(st.tuples(text, text), max_size=20))
def test_set_config_round_trips(pairs: list[tuple[str, str]]) -> None:
    request = SetConfig(tuple(pairs))
    assert SetConfig.decode(request.encode()) == request
