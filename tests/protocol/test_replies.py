"""Reply tracking in the sans-I/O client: which reply answers which request, where it ends, when given up.

No sockets and no clock here: a logged-in ``ClientConnection`` and ``ServerConnection`` pair,
time passed in as ``now``. ``tests/client/test_connection.py`` checks the same rules through
``AriaClient`` over real sockets (timeouts, cancels); these pin each rule on its own.
"""

from __future__ import annotations

import pytest

from rtmu.protocol.client_connection import ClientConnection, payload_name
from rtmu.protocol.datalist import DataEntry, DataList
from rtmu.protocol.errors import PayloadError, ProtocolError
from rtmu.protocol.events import (
    DataReceived,
    Event,
    ReplyComplete,
    ReplyError,
    ReplyFailed,
    ReplyId,
    ReplyPacket,
)
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.camera import SetCameraRel
from rtmu.protocol.payloads.drive import RatioDrive, TurnByAngle
from rtmu.protocol.payloads.mapstream import MapTooLarge
from rtmu.protocol.replies import ABANDON_GRACE, TooManyPending
from rtmu.protocol.server_connection import ServerConnection

from .test_handshake import make_server, pump


def catalogue() -> DataList:
    return DataList(
        [
            DataEntry(0x0108, "updateNumbers", flags="RETURN_SINGLE"),
            DataEntry(0x0110, "getMapName", flags="RETURN_SINGLE"),
            DataEntry(0x0111, "getSensorCurrent", flags="RETURN_SINGLE"),
            DataEntry(0x0112, "getGoals", flags="RETURN_UNTIL_EMPTY"),
            DataEntry(0x0113, "popupList", flags="RETURN_SINGLE"),  # ARIA lists it wrongly: ends when empty
            DataEntry(0x0117, "ratioDrive", flags="RETURN_NONE"),
            DataEntry(0x0118, "turnByAngle", flags="RETURN_NONE"),
            DataEntry(0x0119, "setCameraRelCam1", flags="RETURN_NONE"),
            DataEntry(0x0120, "getMap", flags="RETURN_SINGLE"),  # a map stream whatever its flags say
        ]
    )


def connect() -> tuple[ClientConnection, ServerConnection]:
    client = ClientConnection()
    server = make_server(datalist=catalogue())
    pump(client, server)
    return client, server


def answer(
    client: ClientConnection, server: ServerConnection, name: str, *payloads: bytes, now: float = 0.0
) -> list[Event]:
    """The server sends ``payloads`` as packets of ``name``; the client's events."""
    server.receive_data(client.data_to_send())
    for payload in payloads:
        server.send_data(name, payload)
    return client.receive_data(server.data_to_send(), now)


def outcome(events: list[Event]) -> list[object]:
    """Events in short: ('data', payload), ('packet', serial, payload, swallowed), ('done', …)…"""
    out: list[object] = []
    for e in events:
        if isinstance(e, DataReceived):
            out.append(("data", e.payload))
        elif isinstance(e, ReplyPacket):
            out.append(("packet", e.reply.serial, e.payload, e.swallowed))
        elif isinstance(e, ReplyComplete):
            out.append(("done", e.reply.serial, e.payloads))
        elif isinstance(e, ReplyFailed):
            out.append(("failed", e.reply.serial, e.reason, e.message))
    return out


def ask(client: ClientConnection, name: str, **kw: object) -> ReplyId:
    reply = client.request_reply(name, now=kw.pop("now", 0.0), **kw)  # type: ignore[arg-type]
    assert reply is not None
    return reply


# -- where a reply ends ----------------------------------------------------------------------------


def test_a_single_reply_ends_with_its_packet_and_the_next_packet_is_unsolicited() -> None:
    client, server = connect()
    r = ask(client, "getMapName")
    events = answer(client, server, "getMapName", b"a\0", b"b\0")
    assert outcome(events) == [
        ("packet", r.serial, b"a\0", False),
        ("done", r.serial, (b"a\0",)),
        ("data", b"b\0"),  # a broadcast or subscription update: no request claims it
    ]
    assert client.replies.waiting(r.number) == ()


def test_expect_n_waits_for_exactly_n_packets() -> None:
    client, server = connect()
    r = ask(client, "getSensorCurrent", expect=3)
    events = answer(client, server, "getSensorCurrent", b"1", b"2", b"3", b"4")
    assert outcome(events)[-3:] == [
        ("packet", r.serial, b"3", False),
        ("done", r.serial, (b"1", b"2", b"3")),
        ("data", b"4"),
    ]


@pytest.mark.parametrize("name", ["getGoals", "popupList"])
def test_return_until_empty_ends_at_the_empty_packet(name: str) -> None:
    client, server = connect()
    r = ask(client, name)
    events = answer(client, server, name, b"x\0", b"y\0", b"")
    assert outcome(events)[-1] == ("done", r.serial, (b"x\0", b"y\0", b""))
    assert sum(isinstance(e, ReplyComplete) for e in events) == 1


def test_a_map_ends_at_its_empty_packet_or_at_once_with_no_map() -> None:
    client, server = connect()
    r = ask(client, "getMap")
    events = answer(
        client, server, "getMap", b"2D-Map\0", b"\x00", b""
    )  # a 00 inside the map does not end it
    assert outcome(events)[-1] == ("done", r.serial, (b"2D-Map\0", b"\x00", b""))
    none = ask(client, "getMap")
    events = answer(client, server, "getMap", b"\x00", b"late")
    assert outcome(events) == [
        ("packet", none.serial, b"\x00", False),
        ("done", none.serial, (b"\x00",)),
        ("data", b"late"),
    ]


def test_the_callers_end_test_ends_the_reply_and_its_errors_fail_it() -> None:
    client, server = connect()
    r = ask(client, "getMap", until=lambda p: p == b"end")
    events = answer(client, server, "getMap", b"", b"end")  # the caller's test, not the map rule
    assert outcome(events)[-1] == ("done", r.serial, (b"", b"end"))

    def refuse(payload: bytes) -> bool:
        raise PayloadError("bad block")

    bad = ask(client, "getMap", until=refuse)
    events = answer(client, server, "getMap", b"x", b"")
    assert outcome(events) == [
        ("packet", bad.serial, b"x", True),  # the failing packet is not handed to the waiter
        ("failed", bad.serial, ReplyError.MALFORMED, "malformed reply: bad block"),
        ("data", b""),  # the slot is gone: the rest is nobody's
    ]

    def endless(payload: bytes) -> bool:
        raise MapTooLarge("more than 10 points")

    big = ask(client, "getMap", until=endless)
    (_, failed) = answer(client, server, "getMap", b"x")
    assert failed == ReplyFailed(
        big, ReplyError.MALFORMED, "the server's map is too large, download stopped: more than 10 points"
    )


def test_data_without_a_reply_is_sent_and_not_tracked() -> None:
    client, _ = connect()
    assert client.request_reply("turnByAngle", FieldWriter().double(90).bytes(), now=0.0) is None
    assert client.data_to_send() != b""
    assert list(client.replies) == []


def test_replies_answer_requests_in_order() -> None:
    client, server = connect()
    ids = [ask(client, "getMapName") for _ in range(3)]
    events = answer(client, server, "getMapName", b"1", b"2", b"3")
    done = [(e.reply, e.payloads) for e in events if isinstance(e, ReplyComplete)]
    assert done == [(ids[0], (b"1",)), (ids[1], (b"2",)), (ids[2], (b"3",))]


# -- lost, late and abandoned replies --------------------------------------------------------------


def test_a_lost_reply_does_not_shift_the_later_ones() -> None:
    client, server = connect()
    lost = ask(client, "getMapName", now=0.0)
    client.abandon_reply(lost, now=0.1)  # its waiter timed out; nothing came
    retry = ask(client, "getMapName", now=0.1)  # a newer request: the silent slot counts as lost
    events = answer(client, server, "getMapName", b"retry", now=0.15)
    assert outcome(events)[-1] == ("done", retry.serial, (b"retry",))


def test_a_late_reply_still_lines_up_with_its_abandoned_request() -> None:
    client, server = connect()
    first = ask(client, "getMapName", now=0.0)
    client.abandon_reply(first, now=0.1)
    events = answer(client, server, "getMapName", b"late", now=0.2)  # before any newer request
    assert outcome(events) == [("packet", first.serial, b"late", True)]  # swallowed by its own slot
    second = ask(client, "getMapName", now=0.3)
    assert outcome(answer(client, server, "getMapName", b"mine", now=0.4))[-1] == (
        "done",
        second.serial,
        (b"mine",),
    )


def test_an_abandoned_map_swallows_its_own_packets_until_the_grace_runs_out() -> None:
    client, server = connect()
    first = ask(client, "getMap", now=0.0)
    answer(client, server, "getMap", b"line 1", now=0.0)
    client.abandon_reply(first, now=1.0)  # it stalled half way; its waiter gave up
    second = ask(client, "getMap", now=1.1)  # the first has packets: it is not dropped for a newer one
    events = answer(client, server, "getMap", b"line 2", b"", now=1.2)  # the rest of the first, late
    assert outcome(events) == [("packet", first.serial, b"line 2", True), ("packet", first.serial, b"", True)]
    events = answer(client, server, "getMap", b"", now=1.3)
    assert outcome(events)[-1] == ("done", second.serial, (b"",))

    stalled = ask(client, "getMap", now=2.0)
    answer(client, server, "getMap", b"line 1", now=2.0)
    client.abandon_reply(stalled, now=2.0)
    later = ask(client, "getMap", now=2.0)
    quiet = 2.0 + ABANDON_GRACE  # no packet for the whole grace: the stalled map counts as lost
    assert outcome(answer(client, server, "getMap", b"", now=quiet)) == [
        ("packet", later.serial, b"", False),
        ("done", later.serial, (b"",)),
    ]


def test_requests_waiting_per_data_are_capped_and_abandoned_ones_make_room() -> None:
    client, server = connect()
    client.replies.max_pending = 2
    first = ask(client, "getMap")
    answer(client, server, "getMap", b"line 1")  # half a map: its slot is not dropped for a newer request
    ask(client, "getMap")
    client.data_to_send()
    with pytest.raises(TooManyPending, match="2 requests for 'getMap'"):
        ask(client, "getMap")
    assert client.data_to_send() == b""  # refused before anything was sent
    client.abandon_reply(first, now=0.0)
    ask(client, "getMap")  # the oldest abandoned slot made room
    assert first not in [p.id for p in client.replies]


# -- bounds ----------------------------------------------------------------------------------------


def test_a_reply_past_its_bound_fails_and_the_rest_is_swallowed() -> None:
    client, server = connect()
    r = ask(client, "getMap", max_packets=2)
    events = answer(client, server, "getMap", b"1", b"2", b"3", b"4", b"")
    failed = [e for e in events if isinstance(e, ReplyFailed)]
    assert failed == [
        ReplyFailed(
            r, ReplyError.TOO_LARGE, "more than 2 packets of 'getMap' in one reply; the rest is dropped"
        )
    ]
    assert not any(isinstance(e, (DataReceived, ReplyComplete)) for e in events)  # swallowed to its end
    r = ask(client, "getMap", max_bytes=3)
    failed = [e for e in answer(client, server, "getMap", b"12", b"34", b"") if isinstance(e, ReplyFailed)]
    assert failed == [
        ReplyFailed(
            r, ReplyError.TOO_LARGE, "more than 3 bytes of 'getMap' in one reply; the rest is dropped"
        )
    ]
    whole = ask(client, "getMap")
    assert outcome(answer(client, server, "getMap", b"a", b""))[-1] == ("done", whole.serial, (b"a", b""))


def test_a_stream_keeps_nothing_and_bounds_only_what_is_unread() -> None:
    client, server = connect()
    r = ask(client, "getMap", streaming=True, max_packets=2)
    for n in range(5):  # a reader that keeps up: five packets, never more than one unread
        (packet,) = answer(client, server, "getMap", b"%d" % n)
        assert isinstance(packet, ReplyPacket)
        assert client.replies.get(r).payloads == []  # type: ignore[union-attr]
        client.reply_taken(r, packet.payload)
    assert outcome(answer(client, server, "getMap", b""))[-1] == ("done", r.serial, ())
    slow = ask(client, "getMap", streaming=True, max_packets=2)
    events = answer(client, server, "getMap", b"1", b"2", b"3")
    assert [e for e in events if isinstance(e, ReplyFailed)] == [
        ReplyFailed(
            slow, ReplyError.TOO_LARGE, "more than 2 packets of 'getMap' not read yet; the rest is dropped"
        )
    ]


# -- typed sends -------------------------------------------------------------------------------------


def test_a_typed_payload_names_its_data() -> None:
    client, server = connect()
    client.send(TurnByAngle(90.0))
    typed = client.data_to_send()
    client.request_once("turnByAngle", FieldWriter().double(90.0).bytes())
    assert typed == client.data_to_send() != b""
    client.request_once(RatioDrive(10.0, 0.0))
    assert server.receive_data(client.data_to_send())[0].name == "ratioDrive"  # type: ignore[union-attr]
    assert payload_name(TurnByAngle(1.0)) == "turnByAngle"
    with pytest.raises(ProtocolError, match="several data names"):
        client.send(SetCameraRel(1.0, 0.0, 0.0))  # a family: which camera?
    client.send(SetCameraRel(1.0, 0.0, 0.0), name="setCameraRelCam1")
    assert client.data_to_send() != b""
