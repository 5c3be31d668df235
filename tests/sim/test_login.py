"""The handshake over real loopback sockets: open login, ARIA user files, and every refusal reason."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from rtmu.protocol.client_connection import ClientState
from rtmu.protocol.commands import ClientType
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.catalogue import build_catalogue
from testdata import CAPTURES

from .wire import WireClient, captured_datalist, run

USERS = "UserInfoVersion1\nuser alice secret1 all\nuser bob pw2 RobotInfo Movement Stop\n"


def users_file(tmp_path: Path) -> Path:
    p = tmp_path / "users.txt"
    p.write_text(USERS)
    return p


async def _login(cfg: SimConfig, **client) -> WireClient:
    server = SimServer(cfg)
    await server.start()
    c = WireClient(**client)
    try:
        await c.open(server.port)
        if c.rejected is not None:
            await c.until(lambda: c.eof)  # the server closes after a refusal
        return c
    finally:
        await c.close(goodbye=False)
        await server.stop()


def test_open_server_accepts_anyone_and_lists_serverdemo_data():
    c = run(_login(SimConfig(port=0, realtime=False), user="whoever", password="x"))
    assert c.conn.state is ClientState.CONNECTED
    names = [e.name for e in c.conn.datalist]
    # serverDemo's built-ins come first, numbered from 256, in ARIA's order.
    assert names[:7] == [
        "identSetSelfIdentifier",
        "identSetHereGoal",
        "requestOnceReturnIsAlwaysTcp",
        "idleProcessingPending",
        "requestClientRestart",
        "startRequestTransaction",
        "endRequestTransaction",
    ]
    assert c.conn.datalist.number("identSetSelfIdentifier") == 256
    for needed in ("updateNumbers", "ratioDrive", "getMap", "getMapBinary", "sendVideo", "getPictureCam1"):
        assert needed in c.conn.datalist
    rd = c.conn.datalist.entry("ratioDrive")
    assert rd.command_group == "Movement" and rd.flags == "RETURN_NONE"
    assert rd.argument_description.startswith("double: transRatio (0,100)")
    assert c.conn.datalist.entry("getMap").flags == "RETURN_UNTIL_EMPTY"
    assert c.conn.datalist.entry("setSafeDrive").command_group == "UnsafeMovement"


def test_data_list_matches_serverdemo_capture_for_shared_names():
    """Every name we share with the captured serverDemo carries its exact texts, group and flags."""
    captured = captured_datalist(CAPTURES / "clientCommandLister-serverDemoMap.pcap")
    assert len(captured) == 114
    c = run(_login(SimConfig(port=0, realtime=False)))
    ours = c.conn.datalist
    shared = [e for e in ours if e.name in captured]
    assert len(shared) >= 60
    for e in shared:
        theirs = captured.entry(e.name)
        assert (e.description, e.argument_description, e.return_description) == (
            theirs.description,
            theirs.argument_description,
            theirs.return_description,
        ), e.name
        assert (e.command_group, e.flags) == (theirs.command_group, theirs.flags), e.name
    # Same relative order as serverDemo registered them.
    order = [captured.number(e.name) for e in shared]
    assert order == sorted(order)


OWN_WORDS = {
    "SimulatorResetPose",
    "SimulatorLowBattery",
    "SimulatorRecharge",
    "SimulatorSetBattery",
    "SimulatorPopup",
    "SimulatorPopupFlood",
    "SimulatorVideo320x240",
    "SimulatorVideo640x480",
    "popupCreate",
    "popupClose",
    "popupClicked",
    "popupList",
}
# SHA-256 prefixes of the texts in ARIA's (GPL) popup handler source, which no capture carries: the
# catalogue once had them word for word. Digests, so the test does not carry the texts either.
ARIA_POPUP_SOURCE_TEXTS = {
    "51292fa01b26c56b",
    "12f81e9d98ad5be2",
    "eeee65e85183546a",
    "3e4df4c408e83f16",
    "723f69e5ce38b48b",
    "d5162f1cda6c2bf1",
    "210cc8b51275c533",
    "8078d62be7894fe8",
    "fd1776d8405a4f91",
}


def test_texts_not_in_a_capture_are_our_own():
    """Captured wire texts may be served as recorded; anything else must not be ARIA's source text."""
    captured = captured_datalist(CAPTURES / "clientCommandLister-serverDemoMap.pcap")
    ours = build_catalogue(camera=True)
    assert {e.name for e in ours if e.name not in captured} == OWN_WORDS
    for e in ours:
        if e.name in OWN_WORDS:
            for text in (e.description, e.argument_description, e.return_description):
                assert hashlib.sha256(text.encode()).hexdigest()[:16] not in ARIA_POPUP_SOURCE_TEXTS, e.name


def test_no_camera_removes_video_and_camera_data():
    c = run(_login(SimConfig(port=0, realtime=False, camera=False)))
    names = {e.name for e in c.conn.datalist}
    assert not names & {"sendVideo", "videoSize", "getPictureCam1", "getCameraList", "SimulatorVideo640x480"}
    assert "updateNumbers" in names


def test_user_file_accepts_good_password_and_hides_other_groups(tmp_path):
    cfg = SimConfig(port=0, realtime=False, users_path=users_file(tmp_path))
    alice = run(_login(cfg, user="alice", password="secret1"))
    assert alice.conn.state is ClientState.CONNECTED
    bob = run(_login(cfg, user="BOB", password="pw2"))  # user names are case-insensitive
    assert bob.conn.state is ClientState.CONNECTED
    bob_names = {e.name for e in bob.conn.datalist}
    assert {"updateNumbers", "ratioDrive", "stop"} <= bob_names
    assert not bob_names & {"getMap", "setSafeDrive", "sendVideo", "listCommands"}
    assert all(e.command_group in ("", "RobotInfo", "Movement", "Stop") for e in bob.conn.datalist)
    assert len(bob_names) < len({e.name for e in alice.conn.datalist})


@pytest.mark.parametrize(
    ("user", "password"),
    [("alice", "wrong"), ("mallory", "secret1"), ("al-ice", "secret1"), ("", "")],
)
def test_user_file_refuses_with_reason_1(tmp_path, user, password):
    cfg = SimConfig(port=0, realtime=False, users_path=users_file(tmp_path))
    c = run(_login(cfg, user=user, password=password))
    assert c.rejected is not None and c.rejected.reason == 1 and c.rejected.text == ""
    assert c.conn.state is ClientState.REJECTED and c.eof


def test_reason_2_central_server():
    c = run(_login(SimConfig(port=0, realtime=False, central_server="10.0.0.9")))
    assert c.rejected is not None and (c.rejected.reason, c.rejected.text) == (2, "10.0.0.9")


def test_reason_4_protocol_version():
    c = run(_login(SimConfig(port=0, realtime=False, protocol_version="5.0"), protocol_version="4.2"))
    assert c.rejected is not None and c.rejected.reason == 4
    assert "protocol version does not match" in c.rejected.text
    ok = run(_login(SimConfig(port=0, realtime=False, protocol_version="5.0"), protocol_version="5.0"))
    assert ok.conn.state is ClientState.CONNECTED


def test_reason_5_too_many_clients():
    async def scenario() -> WireClient:
        server = SimServer(SimConfig(port=0, realtime=False, max_clients=1))
        await server.start()
        first = await WireClient().open(server.port)
        second = await WireClient().open(server.port)
        await second.until(lambda: second.eof)
        assert first.conn.state is ClientState.CONNECTED
        await first.close()
        await second.close(goodbye=False)
        await server.stop()
        return second

    c = run(scenario())
    assert c.rejected is not None and c.rejected.reason == 5
    assert "maximum number of allowed connections (which is 1)" in c.rejected.text


def test_reason_6_client_type():
    c = run(
        _login(
            SimConfig(port=0, realtime=False, client_type=int(ClientType.REAL)),
            client_type=ClientType.SIMULATED,
        )
    )
    assert c.rejected is not None and c.rejected.reason == 6


def test_server_introduction_has_fresh_keys_and_no_udp():
    async def scenario() -> list:
        server = SimServer(SimConfig(port=0, realtime=False))
        await server.start()
        intros = []
        for _ in range(3):
            c = await WireClient().open(server.port)
            intros.append(c.conn.introduction)
            await c.close()
        await server.stop()
        return intros

    intros = run(scenario())
    assert all(i.version_tag == "alpha" and i.udp_port == 0 for i in intros)
    assert len({i.password_key for i in intros}) == 3
    assert len({i.auth_key for i in intros}) == 3
    assert all(all("0" <= ch <= "y" for ch in i.password_key) for i in intros)


def test_same_seed_does_not_repeat_login_keys():
    """Keys come from the OS, not ``--seed``: a restarted server must not reuse a recorded login's key."""

    async def first_intro():
        server = SimServer(SimConfig(port=0, realtime=False, seed=1))
        await server.start()
        c = await WireClient().open(server.port)
        intro = c.conn.introduction
        await c.close()
        await server.stop()
        return intro

    a, b = run(first_intro()), run(first_intro())
    assert a.password_key != b.password_key
    assert (a.auth_key, a.intro_key) != (b.auth_key, b.intro_key)
