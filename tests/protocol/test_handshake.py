"""ClientConnection ↔ ServerConnection back to back, no sockets (protocol §2.3–2.14, §3.2–3.4)."""

from __future__ import annotations

import hashlib
import random

import pytest

from rtmu.protocol import (
    ClientCommand,
    DataEntry,
    DataList,
    FieldWriter,
    Packet,
    PacketDecoder,
    ProtocolError,
    RejectReason,
    ServerCommand,
    encode_packet,
)
from rtmu.protocol.auth import UserTable
from rtmu.protocol.client_connection import ClientConnection, ClientState, UnknownData
from rtmu.protocol.commands import ClientType
from rtmu.protocol.events import (
    ClientIntroduced,
    Connected,
    DataListReady,
    DataReceived,
    Event,
    Ignored,
    LoginRefused,
    PeerShutdown,
    Rejected,
    RequestOnce,
    RequestReceived,
    RequestStopped,
    ServerIntroduction,
    TcpOnlyRequested,
)
from rtmu.protocol.server_connection import ServerConnection, ServerState

USERS = "UserInfoVersion1\nuser alice secret1 all\nuser bob pw2 RobotInfo Movement Stop\n"
REJECTED_REASON_1 = bytes.fromhex("0F 0C 0B 00 06 00 01 00 00 00 07")
SHUTDOWN = bytes.fromhex("0F 0C 08 00 01 00 00 01")
TCP_ONLY = bytes.fromhex("0F 0C 08 00 05 00 00 05")


def server_catalogue() -> DataList:
    """Numbers chosen so the document's examples apply: 0x0108 and 0x0117 (§1.1, §1.3 C)."""
    entries = [
        DataEntry(256, "identSetSelfIdentifier"),
        DataEntry(
            0x0108, "updateNumbers", "status", "none", "byte2 battery ...", "RobotInfo", "RETURN_SINGLE"
        ),
        DataEntry(0x0109, "updateStrings", "", "", "", "RobotInfo", "RETURN_SINGLE"),
        DataEntry(0x0117, "ratioDrive", "drive", "double trans ...", "none", "Movement", "RETURN_NONE"),
        DataEntry(0x0118, "stop", "", "", "", "Stop", "RETURN_NONE"),
        DataEntry(0x0119, "getSafeDrive", "", "", "", "UnsafeMovement", "RETURN_SINGLE"),
        DataEntry(0x0120, "getMap", "", "", "", "Map", "RETURN_UNTIL_EMPTY"),
        DataEntry(0x0124, "heartbeatTcp", "", "", "", "", "RETURN_NONE"),
    ]
    return DataList(entries)


def make_server(
    users: str | None = None, server_key: str = "", datalist: DataList | None = None
) -> ServerConnection:
    table = UserTable.parse(users) if users is not None else None
    return ServerConnection(
        datalist or server_catalogue(), table, server_key=server_key, rng=random.Random(7)
    )


def pump(client: ClientConnection, server: ServerConnection) -> tuple[list[Event], list[Event]]:
    """Move bytes both ways until both sides are quiet; the events each side reported."""
    client_events: list[Event] = []
    server_events: list[Event] = []
    for _ in range(50):
        to_client, to_server = server.data_to_send(), client.data_to_send()
        if not to_client and not to_server:
            return client_events, server_events
        client_events += client.receive_data(to_client)
        server_events += server.receive_data(to_server)
    raise AssertionError("the two sides never went quiet")


def connect(
    user: str = "", password: str = "", **server_args: object
) -> tuple[ClientConnection, ServerConnection]:
    client = ClientConnection(user, password, server_key=str(server_args.get("server_key", "")))
    server = make_server(**server_args)  # type: ignore[arg-type]
    pump(client, server)
    return client, server


def packets(data: bytes) -> list[Packet]:
    return PacketDecoder().feed(data)


def of_type(events: list[Event], kind: type) -> list:
    return [e for e in events if isinstance(e, kind)]


# -- accepted ------------------------------------------------------------------------------------


def test_happy_path_without_a_user_file() -> None:
    client = ClientConnection()
    server = make_server()
    client_events, server_events = pump(client, server)
    assert [type(e) for e in client_events] == [ServerIntroduction, Connected, DataListReady]
    assert client.state is ClientState.CONNECTED
    assert server.state is ServerState.CONNECTED
    assert server_events == [ClientIntroduced("", 0, "", 0), TcpOnlyRequested()]
    assert server.tcp_only
    assert list(client.datalist) == list(server_catalogue())
    ready = client_events[-1]
    assert isinstance(ready, DataListReady) and ready.datalist is client.datalist


def test_server_introduction_fields() -> None:
    server = make_server()
    (intro_packet,) = packets(server.data_to_send())
    assert intro_packet.command == ServerCommand.INTRODUCTION
    client = ClientConnection()
    (intro,) = client.receive_data(intro_packet.encode())
    assert isinstance(intro, ServerIntroduction)
    assert intro.version_tag == "alpha"
    assert intro.udp_port == 0
    assert 0 <= intro.auth_key < 2**31 and 0 <= intro.intro_key < 2**31
    assert intro.password_key == server.password_key
    assert all("0" <= ch <= "y" for ch in intro.password_key)
    assert intro.protocol_version == ""
    assert client.introduction == intro


def test_client_introduction_bytes_with_everything_empty() -> None:
    """A server whose password key is empty: the digest is md5("") (§2.5), then TCP_ONLY follows."""
    intro = FieldWriter().string("alpha").ubyte2(0).ubyte4(1).ubyte4(2).string("").string("").bytes()
    client = ClientConnection()
    client.receive_data(encode_packet(ServerCommand.INTRODUCTION, intro))
    sent = client.data_to_send()
    introduction, _tcp_only = packets(sent)
    assert introduction.payload[:3] == b"\x00\x00\x00"  # UDP port 0, empty user name
    assert introduction.payload[3:19].hex() == "d41d8cd98f00b204e9800998ecf8427e"
    assert introduction.payload[19:] == b"\x00\x00"  # empty protocol version, client type 0
    # the C++ client's captured INTRODUCTION differs only in its UDP port (10000 → 0) and checksum
    captured = bytes.fromhex(
        "0F 0C 1D 00 02 00 10 27 00 D4 1D 8C D9 8F 00 B2 04 E9 80 09 98 EC F8 42 7E 00 00 EB 9A"
    )
    assert sent[6:8] == b"\x00\x00" and sent[8:27] == captured[8:27]
    assert sent[29:] == TCP_ONLY
    assert client.state is ClientState.EXCHANGED_INTROS


def test_client_sends_its_user_digest_version_and_type() -> None:
    client = ClientConnection(
        "alice", "secret1", server_key="k", protocol_version="v2", client_type=ClientType.REAL
    )
    server = make_server()
    client.receive_data(server.data_to_send())
    introduction, tcp_only = packets(client.data_to_send())
    expected = hashlib.md5(("k" + server.password_key + "secret1").encode()).digest()
    assert (
        introduction.payload
        == FieldWriter().ubyte2(0).string("alice").raw(expected).string("v2").byte(1).bytes()
    )
    assert tcp_only == Packet(ClientCommand.TCP_ONLY, b"")


@pytest.mark.parametrize(("user", "password"), [("alice", "secret1"), ("ALICE", "secret1"), ("bob", "pw2")])
def test_accepted_with_a_user_file(user: str, password: str) -> None:
    client, server = connect(user, password, users=USERS)
    assert client.state is ClientState.CONNECTED
    assert server.user is not None and server.user.name == user.lower()


def test_server_key_must_match_on_both_sides() -> None:
    client = ClientConnection("alice", "secret1", server_key="shared")
    server = make_server(USERS, server_key="shared")
    pump(client, server)
    assert client.state is ClientState.CONNECTED
    client = ClientConnection("alice", "secret1")
    server = make_server(USERS, server_key="shared")
    pump(client, server)
    assert client.state is ClientState.REJECTED


def test_without_a_user_file_any_user_and_password_are_accepted() -> None:
    client, server = connect("nobody", "whatever")
    assert client.state is ClientState.CONNECTED
    assert server.user is None


def test_groups_filter_what_bob_sees() -> None:
    alice, _ = connect("alice", "secret1", users=USERS)
    bob, bob_server = connect("bob", "pw2", users=USERS)
    assert len(alice.datalist) == len(server_catalogue())
    names = {e.name for e in bob.datalist}
    assert names == {
        "identSetSelfIdentifier",
        "updateNumbers",
        "updateStrings",
        "ratioDrive",
        "stop",
        "heartbeatTcp",
    }
    assert len(bob.datalist) < len(alice.datalist)
    assert bob.datalist.number("ratioDrive") == alice.datalist.number("ratioDrive") == 0x0117
    with pytest.raises(UnknownData, match="getMap"):
        bob.request("getMap", -1)
    # what the server would accept from bob is the same filtered list
    assert "getMap" not in bob_server.datalist


def test_large_data_list_is_split_over_several_listargret_packets() -> None:
    big = DataList.build((f"data{i}", "d", "x" * 400, "y" * 100, "", "") for i in range(300))
    client = ClientConnection()
    server = make_server(datalist=big)
    client.receive_data(server.data_to_send())
    server.receive_data(client.data_to_send())
    wire = server.data_to_send()
    commands = [p.command for p in packets(wire)]
    assert commands.count(ServerCommand.LISTARGRET) >= 4
    assert commands[0] == ServerCommand.CONNECTED and commands[-1] == ServerCommand.LISTGROUPANDFLAGS
    events = client.receive_data(wire)
    assert [type(e) for e in events] == [Connected, DataListReady]
    assert len(client.datalist) == 300
    assert client.datalist.entry("data299").argument_description == "x" * 400  # type: ignore[union-attr]


# -- refused -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("user", "password"),
    [("alice", "wrong"), ("carol", "secret1"), ("al-ice", "secret1"), ("", "")],
    ids=["wrong-password", "unknown-user", "not-alphanumeric", "no-user"],
)
def test_bad_login_is_rejected_with_reason_1(user: str, password: str) -> None:
    client = ClientConnection(user, password)
    server = make_server(USERS)
    client.receive_data(server.data_to_send())
    server_events = server.receive_data(client.data_to_send())
    assert server_events == [LoginRefused(1, "")]
    assert server.state is ServerState.CLOSING
    wire = server.data_to_send()
    assert wire == REJECTED_REASON_1  # the captured packet, byte for byte
    (rejected,) = client.receive_data(wire)
    assert rejected == Rejected(1, "", "wrong user name or password")
    assert client.state is ClientState.REJECTED
    with pytest.raises(ProtocolError, match="REJECTED"):
        client.request("updateNumbers", 100)


def test_server_ignores_everything_after_a_reject() -> None:
    client = ClientConnection("alice", "wrong")
    server = make_server(USERS)
    client.receive_data(server.data_to_send())
    late = encode_packet(ClientCommand.REQUEST, FieldWriter().ubyte2(0x0108).byte4(100).bytes())
    assert server.receive_data(client.data_to_send() + late) == [LoginRefused(1, "")]
    assert server.receive_data(late) == []


def test_short_client_introduction_is_rejected_not_crashed() -> None:
    server = make_server()
    server.data_to_send()
    assert server.receive_data(encode_packet(ClientCommand.INTRODUCTION, b"\x00\x00bob\x00\x01\x02")) == [
        LoginRefused(1, "")
    ]
    assert server.data_to_send() == REJECTED_REASON_1
    assert server.malformed_packets == 1


LONG_REASONS = {
    2: "10.0.0.1",
    4: "Server rejecting client connection since protocol version does not match",
    5: "Server rejecting connection since it would exceed the maximum number of allowed connections"
    " (which is 1)",
    6: "Server rejecting client connection since type (real or sim) does not match (but is specified)",
    99: "",
}


@pytest.mark.parametrize(("reason", "text"), [(1, ""), *LONG_REASONS.items()])
def test_rejected_before_connected_is_fatal_for_the_client(reason: int, text: str) -> None:
    """Reasons 4 and 6 are followed by CONNECTED and the lists on a real server (pitfall 13)."""
    server = make_server()
    client = ClientConnection()
    client.receive_data(server.data_to_send())
    client.data_to_send()
    rejected = encode_packet(ServerCommand.REJECTED, FieldWriter().byte2(reason).string(text).bytes())
    connected = encode_packet(ServerCommand.CONNECTED)
    lists = b"".join(p.encode() for p in server_catalogue().list_packets())
    events = client.receive_data(rejected + connected + lists)
    assert isinstance(events[0], Rejected)
    assert events[0].reason == reason and events[0].text == text
    assert all(isinstance(e, Ignored) for e in events[1:])
    assert len(events) == 1 + 4
    assert client.state is ClientState.REJECTED
    assert len(client.datalist) == 0
    message = events[0].message
    if reason in set(RejectReason):
        assert RejectReason(reason).explanation in message
    else:
        assert str(reason) in message
    if text:
        assert text in message
    assert client.data_to_send() == b""  # nothing more is sent; the caller closes
    client.shutdown()
    assert client.data_to_send() == b""


def test_rejected_while_waiting_for_the_list_is_fatal_too() -> None:
    server = make_server()
    client = ClientConnection()
    client.receive_data(server.data_to_send())
    events = client.receive_data(
        encode_packet(ServerCommand.CONNECTED) + encode_packet(ServerCommand.REJECTED, b"\x06\x00no\x00")
    )
    assert [type(e) for e in events] == [Connected, Rejected]
    assert client.state is ClientState.REJECTED


def test_rejected_with_an_empty_payload_still_reads() -> None:
    client = ClientConnection()
    client.receive_data(make_server().data_to_send())
    (event,) = client.receive_data(encode_packet(ServerCommand.REJECTED))
    assert isinstance(event, Rejected) and event.reason == 0 and "unknown reason" in event.message


def test_malformed_server_introduction_is_a_protocol_error() -> None:
    client = ClientConnection()
    with pytest.raises(ProtocolError, match="introduction"):
        client.receive_data(encode_packet(ServerCommand.INTRODUCTION, b"alpha\x00\x01"))


# -- state machine details ---------------------------------------------------------------------


def test_client_ignores_everything_before_the_server_introduction() -> None:
    client = ClientConnection()
    events = client.receive_data(encode_packet(ServerCommand.CONNECTED) + encode_packet(0x0108, b"x"))
    assert [type(e) for e in events] == [Ignored, Ignored]
    assert client.state is ClientState.WAITING_INTRODUCTION
    assert client.data_to_send() == b""


def test_client_ignores_udp_bookkeeping_at_any_point() -> None:
    server = make_server()
    client = ClientConnection()
    client.receive_data(server.data_to_send())
    noise = encode_packet(ServerCommand.TCP_ONLY) + encode_packet(ServerCommand.UDP_CONFIRMATION)
    server.receive_data(client.data_to_send())
    events = client.receive_data(noise + server.data_to_send() + noise)
    assert [type(e) for e in events] == [Ignored, Ignored, Connected, DataListReady, Ignored, Ignored]
    assert client.state is ClientState.CONNECTED


def test_data_before_the_list_is_complete_is_ignored() -> None:
    server = make_server()
    client = ClientConnection()
    client.receive_data(server.data_to_send())
    server.receive_data(client.data_to_send())
    connected, list_packet, argret, groups = packets(server.data_to_send())
    events = client.receive_data(connected.encode() + list_packet.encode() + encode_packet(0x0108, b"early"))
    assert isinstance(events[-1], Ignored)
    assert client.state is ClientState.WAITING_LIST
    client.receive_data(argret.encode() + groups.encode())
    assert client.state is ClientState.CONNECTED


def test_server_ignores_requests_before_the_introduction_but_takes_tcp_only() -> None:
    server = make_server()
    request = encode_packet(ClientCommand.REQUEST, FieldWriter().ubyte2(0x0108).byte4(100).bytes())
    events = server.receive_data(TCP_ONLY + request)
    assert events[0] == TcpOnlyRequested()
    assert isinstance(events[1], Ignored)
    assert server.tcp_only and server.subscriptions == {}


def test_udp_introduction_over_tcp_means_tcp_only() -> None:
    _, server = connect()
    server.tcp_only = False
    assert server.receive_data(encode_packet(ClientCommand.UDP_INTRODUCTION, b"\x01\x00\x00\x00")) == [
        TcpOnlyRequested()
    ]
    assert server.tcp_only


# -- requests --------------------------------------------------------------------------------------


def test_request_bytes_are_the_documented_example() -> None:
    client, server = connect()
    client.request("updateNumbers", 200)
    wire = client.data_to_send()
    assert wire == bytes.fromhex("0F 0C 0E 00 81 00 08 01 C8 00 00 00 02 51")  # §1.1 / §1.3 A
    assert server.receive_data(wire) == [RequestReceived(0x0108, "updateNumbers", 200, b"", True)]
    assert server.subscriptions == {0x0108: 200}


def test_re_request_replaces_the_interval_and_is_not_new() -> None:
    client, server = connect()
    client.request("updateNumbers", 200)
    client.request("updateNumbers", -1, b"\x01\x02")
    events = server.receive_data(client.data_to_send())
    assert events == [
        RequestReceived(0x0108, "updateNumbers", 200, b"", True),
        RequestReceived(0x0108, "updateNumbers", -1, b"\x01\x02", False),
    ]
    assert server.subscriptions == {0x0108: -1}


def test_request_with_arguments_appends_them() -> None:
    client, _ = connect()
    client.request("heartbeatTcp", -1, b"args")
    (packet,) = packets(client.data_to_send())
    assert packet == Packet(
        ClientCommand.REQUEST, b"\x24\x01" + (-1).to_bytes(4, "little", signed=True) + b"args"
    )


def test_request_stop() -> None:
    client, server = connect()
    client.request("updateNumbers", 100)
    server.receive_data(client.data_to_send())
    client.request_stop("updateNumbers")
    wire = client.data_to_send()
    assert wire == encode_packet(130, b"\x08\x01")
    assert wire == bytes.fromhex("0F 0C 0A 00 82 00 08 01 00 8B")
    assert server.receive_data(wire) == [RequestStopped(0x0108, "updateNumbers")]
    assert server.subscriptions == {}
    (ignored,) = server.receive_data(wire)
    assert isinstance(ignored, Ignored) and "not subscribed" in ignored.why


def test_request_once_is_the_data_number_with_the_arguments() -> None:
    client, server = connect()
    args = FieldWriter().double(50).double(0).double(100).double(0).bytes()
    client.request_once("ratioDrive", args)
    wire = client.data_to_send()
    assert wire == bytes.fromhex("0F 0C 13 00 17 01 35 30 00 30 00 31 30 30 00 30 00 C2 4C")  # §1.3 C
    assert server.receive_data(wire) == [RequestOnce(0x0117, "ratioDrive", args)]
    client.request_once("stop")
    assert client.data_to_send() == encode_packet(0x0118)


def test_requests_need_a_connection_and_a_known_name() -> None:
    client = ClientConnection()
    for call in (
        lambda: client.request("x", 1),
        lambda: client.request_stop("x"),
        lambda: client.request_once("x"),
    ):
        with pytest.raises(ProtocolError, match="not connected"):
            call()
    client, _ = connect()
    with pytest.raises(UnknownData, match="noSuchData"):
        client.request_once("noSuchData")
    assert isinstance(UnknownData("x"), ProtocolError)


def test_server_ignores_unknown_data_numbers_and_short_requests() -> None:
    _, server = connect()
    bad = encode_packet(ClientCommand.REQUEST, FieldWriter().ubyte2(0x0999).byte4(100).bytes())
    short = encode_packet(ClientCommand.REQUEST, b"\x08\x01\x00")
    once = encode_packet(0x0999, b"")
    events = server.receive_data(bad + short + once + encode_packet(ClientCommand.LIST))
    assert [type(e) for e in events] == [Ignored] * 4
    assert server.subscriptions == {}
    assert server.malformed_packets == 1  # the short REQUEST; unknown numbers are well formed
    stop = server.receive_data(encode_packet(ClientCommand.REQUESTSTOP, b"\x08"))
    assert [type(e) for e in stop] == [Ignored] and "data number" in stop[0].why
    assert server.malformed_packets == 2


def test_bob_cannot_request_data_outside_his_groups() -> None:
    _, server = connect("bob", "pw2", users=USERS)
    request = encode_packet(ClientCommand.REQUEST, FieldWriter().ubyte2(0x0120).byte4(-1).bytes())
    events = server.receive_data(request + encode_packet(0x0120))
    assert [type(e) for e in events] == [Ignored, Ignored]
    assert server.subscriptions == {}


def test_replies_reach_the_client_with_their_name() -> None:
    client, server = connect()
    server.send_data("updateNumbers", b"\x82\x00" + bytes(17))
    server.send_data("noSuchData", b"dropped")
    events = client.receive_data(server.data_to_send())
    assert events == [DataReceived(0x0108, "updateNumbers", b"\x82\x00" + bytes(17))]
    unknown = client.receive_data(encode_packet(0x0999, b"?"))
    assert unknown == [DataReceived(0x0999, None, b"?")]


def test_send_raw_passes_framed_bytes_through() -> None:
    client, server = connect()
    server.send_raw(encode_packet(0x0120, b"map") + encode_packet(0x0120))
    assert client.receive_data(server.data_to_send()) == [
        DataReceived(0x0120, "getMap", b"map"),
        DataReceived(0x0120, "getMap", b""),
    ]


# -- shutdown ----------------------------------------------------------------------------------------


def test_client_shutdown() -> None:
    client, server = connect()
    client.shutdown()
    wire = client.data_to_send()
    assert wire == SHUTDOWN
    assert client.state is ClientState.CLOSED
    assert server.receive_data(wire) == [PeerShutdown()]
    assert server.state is ServerState.CLOSED
    client.shutdown()  # a second call sends nothing
    assert client.data_to_send() == b""


def test_server_shutdown() -> None:
    client, server = connect()
    server.shutdown()
    wire = server.data_to_send()
    assert wire == SHUTDOWN
    assert server.state is ServerState.CLOSED
    assert client.receive_data(wire + encode_packet(0x0108, b"late")) == [
        PeerShutdown(),
        Ignored(0x0108, "connection is closed"),
    ]
    assert client.state is ClientState.CLOSED
    server.send_data("updateNumbers", b"x")
    assert server.data_to_send() == b""


def test_server_shutdown_before_login_sends_nothing() -> None:
    server = make_server()
    server.data_to_send()
    server.shutdown()
    assert server.data_to_send() == b""
    assert server.state is ServerState.CLOSED


def test_client_shutdown_during_the_handshake() -> None:
    client = ClientConnection()
    client.receive_data(make_server().data_to_send())
    client.data_to_send()
    client.shutdown()
    assert client.data_to_send() == SHUTDOWN
