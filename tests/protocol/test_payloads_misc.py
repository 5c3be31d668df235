"""Strings info, simple commands, popups and server built-ins (protocol §3.9, §4.9–4.11)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.commands import CommandEntry, CommandList, StringCommandArgs, StringCommandList
from rtmu.protocol.payloads.popup import PopupClicked, PopupClose, PopupCreate, PopupListEnd, PopupType
from rtmu.protocol.payloads.server import (
    HeartbeatInterval,
    HeartbeatTcp,
    IdleProcessingPending,
    RequestClientRestart,
    SelfIdentifier,
)
from rtmu.protocol.payloads.strings import StringItem, Strings, StringsInfo

text = st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=20)


def test_strings_info_captured() -> None:
    raw = b"\x01\x00Answer\0\x0a\x00"
    info = StringsInfo.decode(raw)
    assert info == StringsInfo((StringItem("Answer", 10),))
    assert info.encode() == raw
    real = b"\x01\x00Motor Packet Count\0\x0a\x00"  # strings.pcap
    assert StringsInfo.decode(real).encode() == real


def test_strings_have_no_count_and_pair_by_order() -> None:
    assert Strings.decode(b"42\0") == Strings(("42",))
    assert Strings(("42",)).encode() == b"42\0"
    assert Strings.decode(b"") == Strings(())
    info = StringsInfo((StringItem("Wireless Link Quality", 4), StringItem("Battery", 6)))
    values = Strings.decode(b"71\0" + b"12.8\0")
    assert info.pair(values) == [("Wireless Link Quality", "71"), ("Battery", "12.8")]
    assert info.pair(Strings(("71",))) == [("Wireless Link Quality", "71")]


def test_strings_info_hostile_and_short() -> None:
    with pytest.raises(PayloadError, match="item count"):
        StringsInfo.decode(b"\xff\xffA\0\x01\x00")
    with pytest.raises(FieldUnderrun, match="max width"):
        StringsInfo.decode(b"\x01\x00Answer\0\x0a")


@given(st.lists(st.tuples(text, st.integers(0, 65535)), max_size=6), st.lists(text, max_size=6))
def test_strings_round_trip(items: list[tuple[str, int]], values: list[str]) -> None:
    info = StringsInfo(tuple(StringItem(a, b) for a, b in items))
    assert StringsInfo.decode(info.encode()) == info
    assert Strings.decode(Strings(tuple(values)).encode()) == Strings(tuple(values))


def test_command_lists_captured_layout() -> None:
    raw = (
        b"\x02\x00safeRatioDrivingEnable\0Enables safe driving\0"
        b"safeRatioDrivingDisable\0Disables safe driving\0"
    )
    c = CommandList.decode(raw)
    assert c.commands[0] == CommandEntry("safeRatioDrivingEnable", "Enables safe driving")
    assert c.encode() == raw
    s = StringCommandList.decode(raw)
    assert isinstance(s, StringCommandList) and s.commands == c.commands
    with pytest.raises(PayloadError, match="command count"):
        CommandList.decode(b"\x10\x00a\0b\0")
    assert StringCommandArgs("MicroControllerCommand 1 2").encode() == b"MicroControllerCommand 1 2\0"


@given(st.lists(st.tuples(text, text), max_size=6))
def test_command_list_round_trip(rows: list[tuple[str, str]]) -> None:
    c = CommandList(tuple(CommandEntry(a, b) for a, b in rows))
    assert CommandList.decode(c.encode()) == c


def test_popup_create_layout() -> None:
    p = PopupCreate(7, "dock", "Docking", "Dock now?", PopupType.QUESTION, ("Yes", "No", ""), 0, 1)
    raw = p.encode()
    assert raw == b"\x07\0\0\0dock\0Docking\0Dock now?\0\x04Yes\0No\0\0\x00\x01"
    assert PopupCreate.decode(raw) == p
    with pytest.raises(FieldUnderrun, match="escape button"):
        PopupCreate.decode(raw[:-1])
    with pytest.raises(ValueError):
        PopupCreate(1, "", "", "", 1, ("a", "b"), 0, 0).encode()  # type: ignore[arg-type]


@given(
    st.integers(-(2**31), 2**31 - 1),
    text,
    text,
    text,
    st.integers(-128, 127),
    st.tuples(text, text, text),
    st.integers(-128, 127),
    st.integers(-128, 127),
)
def test_popup_create_round_trip(
    pid: int, ign: str, title: str, msg: str, kind: int, buttons: tuple[str, str, str], d: int, e: int
) -> None:
    p = PopupCreate(pid, ign, title, msg, kind, buttons, d, e)
    assert PopupCreate.decode(p.encode()) == p


def test_popup_close_clicked_list() -> None:
    assert PopupClose.decode(b"\x07\0\0\0Yes\0") == PopupClose(7, "Yes")
    assert PopupClose(7, "Yes").encode() == b"\x07\0\0\0Yes\0"
    assert PopupClicked(7, 1).encode() == b"\x07\0\0\0\x01"
    assert PopupClicked.decode(b"\x07\0\0\0\x02") == PopupClicked(7, 2)
    with pytest.raises(FieldUnderrun, match="button"):
        PopupClicked.decode(b"\x07\0\0\0")
    assert PopupListEnd.decode(b"") == PopupListEnd() and PopupListEnd().encode() == b""


def test_server_builtins() -> None:
    assert HeartbeatInterval.decode(bytes.fromhex("F4010000")) == HeartbeatInterval(500)
    assert HeartbeatInterval(500).encode() == bytes.fromhex("F4010000")
    assert HeartbeatTcp.decode(b"").encode() == b""
    assert IdleProcessingPending.decode(b"\x01").pending
    r = RequestClientRestart(1, "config changed")
    assert RequestClientRestart.decode(r.encode()) == r
    assert SelfIdentifier.decode(b"rtmu\0") == SelfIdentifier("rtmu")


@pytest.mark.parametrize(
    ("name", "side", "cls"),
    [
        ("getStringsInfo", Side.REPLY, StringsInfo),
        ("getStrings", Side.REPLY, Strings),
        ("listCommands", Side.REPLY, CommandList),
        ("listStringCommands", Side.REPLY, StringCommandList),
        ("popupCreate", Side.REPLY, PopupCreate),
        ("popupClose", Side.REPLY, PopupClose),
        ("popupClicked", Side.ARGS, PopupClicked),
        ("popupList", Side.REPLY, PopupListEnd),
        ("heartbeatUdp", Side.REPLY, payload_type_for("heartbeatUdp", Side.REPLY)),
    ],
)
def test_registered(name: str, side: Side, cls: type) -> None:
    assert cls is not None and payload_type_for(name, side) is cls
