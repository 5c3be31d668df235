"""The bridge is safe to leave running: who may connect, who may drive, and what a late client sees.

Real parts throughout: the simulator on loopback, a real session, the bridge's own WebSocket
server, and the standard ``websockets`` client (:mod:`.foxglove_client`) sending the headers a
browser, a rebinding page or another host would send.
"""

from __future__ import annotations

import socket
import time

import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from rtmu.recorder import topics
from rtmu.recorder.bridge import Bridge
from rtmu.recorder.bridge_drive import HANDOVER
from rtmu.recorder.foxglove_gate import Gate, loopback_only

from .foxglove_client import OLD_SUBPROTOCOL, SUBPROTOCOL, FoxgloveClient, twist
from .test_bridge import bridged, stream


def refused(url: str, **kwargs: object) -> tuple[int, str]:
    """The HTTP status and body a handshake was refused with (the test fails if it was accepted)."""
    with pytest.raises(InvalidStatus) as caught, FoxgloveClient(url, **kwargs) as client:  # type: ignore[arg-type]
        client.until(lambda: bool(client.server_info), 3)
    response = caught.value.response
    return response.status_code, response.body.decode()


def accepted(url: str, **kwargs: object) -> FoxgloveClient:
    client = FoxgloveClient(url, **kwargs)  # type: ignore[arg-type]
    client.__enter__()
    client.until(lambda: bool(client.server_info), 5)
    return client


def test_a_foreign_origin_is_refused_foxglove_and_allowed_origins_are_not() -> None:
    told: list[str] = []
    bridge = Bridge(port=0, gate=Gate.make(allow_origins=["http://localhost:8080/"]))
    bridge.server.on_refused = told.append
    bridge.start()
    try:
        status, body = refused(bridge.url, origin="https://evil.example")
        assert status == 403 and "https://evil.example" in body and "--allow-origin" in body
        assert told and "evil.example" in told[-1]
        assert refused(bridge.url, origin="null")[0] == 403  # a sandboxed frame of any page
        for origin in ("https://app.foxglove.dev", "http://localhost:8080", None):  # None: no browser
            client = accepted(bridge.url, origin=origin)
            client.__exit__(None, None, None)
        assert bridge.server.refused == 2
    finally:
        bridge.close()


def test_a_foreign_host_header_dns_rebinding_is_refused() -> None:
    bridge = Bridge(port=0).start()
    try:
        for name in ("evil.example", "attacker.localhost.evil.example"):
            sock = socket.create_connection(("127.0.0.1", bridge.port), timeout=5)
            with pytest.raises(InvalidStatus) as caught:  # the browser was pointed at evil.example:PORT
                connect(f"ws://{name}:{bridge.port}", sock=sock, subprotocols=[SUBPROTOCOL], open_timeout=5)  # type: ignore[list-item]
            assert caught.value.response.status_code == 403
            assert "DNS rebinding" in caught.value.response.body.decode()
        for name in ("localhost", "127.0.0.1", socket.gethostname()):
            sock = socket.create_connection(("127.0.0.1", bridge.port), timeout=5)
            with connect(f"ws://{name}:{bridge.port}", sock=sock, subprotocols=[SUBPROTOCOL], open_timeout=5):  # type: ignore[list-item]
                pass
    finally:
        bridge.close()


def test_both_subprotocols_are_spoken_and_a_client_offering_neither_is_told() -> None:
    with bridged(drive=False) as (_sim, _runner, bridge, _stops):
        for offered in (SUBPROTOCOL, OLD_SUBPROTOCOL):
            with FoxgloveClient(bridge.url, subprotocol=offered) as client:
                assert client.ws is not None and client.ws.subprotocol == offered
                client.until(lambda: bool(client.server_info))
                client.subscribe(topics.POSE)
                client.until(lambda: bool(client.of(topics.POSE)), 5)
        status, body = refused(bridge.url, subprotocol="chat")
        assert status == 400 and "foxglove.sdk.v1" in body and "foxglove.websocket.v1" in body


def test_a_late_subscriber_gets_the_parked_robots_pose_and_tf_at_once() -> None:
    """Kept, not waited for: the first pose and TF it gets were logged before it subscribed."""
    with bridged(drive=False) as (sim, _runner, bridge, _stops):
        logged: dict[str, list[int]] = {topics.POSE: [], topics.TF: []}
        bridge.on_logged = lambda topic, at: logged[topic].append(at) if topic in logged else None
        sim.call(lambda: sim.server.world.ratio_drive(40.0, 0.0, 40.0))  # type: ignore[union-attr]
        time.sleep(0.5)
        sim.call(lambda: sim.server.world.stop())  # type: ignore[union-attr]
        end = time.monotonic() + 10
        while True:  # parked: no pose has gone out for a second
            count = len(logged[topics.POSE])
            time.sleep(1.0)
            if count and len(logged[topics.POSE]) == count:
                break
            assert time.monotonic() < end, "the robot never came to rest"
        with FoxgloveClient(bridge.url) as client:
            client.until(lambda: topics.TF in client.channels and topics.POSE in client.channels)
            client.subscribe(topics.POSE, topics.TF)
            client.until(lambda: bool(client.of(topics.POSE) and client.of(topics.TF)), 10)
            for topic in (topics.POSE, topics.TF):
                # The one logged before it came, not one logged since (none was: the robot is parked).
                assert client.of(topic)[0].log_time == logged[topic][-1], topic
            assert len(logged[topics.POSE]) == count, "a new pose was logged: the test proved nothing"


def test_a_drive_bridge_refuses_a_client_without_its_token_and_drives_with_it() -> None:
    with bridged(drive=True) as (sim, _runner, bridge, _stops):
        assert bridge.gate.token and "token=" in bridge.url
        bare = f"ws://127.0.0.1:{bridge.port}"
        status, body = refused(bare)
        assert status == 401 and "token" in body
        assert refused(f"{bare}/?token=guessed")[0] == 401
        start = sim.snapshot()
        with FoxgloveClient(bridge.url) as client:
            client.until(lambda: bool(client.server_info))
            assert "clientPublish" in client.server_info["capabilities"]
            client.advertise(1, "/cmd_vel")
            stream(client, twist(0.6), hz=10, seconds=1.2)
            assert sim.snapshot().trans_ratio > 0 and sim.snapshot().x > start.x + 50


def test_two_publishers_one_drives_the_other_is_told_and_never_mixed_in() -> None:
    with (
        bridged(drive=True) as (sim, _runner, bridge, _stops),
        FoxgloveClient(bridge.url) as first,
        FoxgloveClient(bridge.url) as second,
    ):
        for client in (first, second):
            client.until(lambda: bool(client.server_info))  # noqa: B023
            client.advertise(1, "/cmd_vel")
        first.publish(1, twist(0.6))
        first.pump(0.1)
        ratios: list[float] = []
        end = time.monotonic() + 2.0
        while time.monotonic() < end:  # both stream at 10 Hz: forward from one, backward from the other
            first.publish(1, twist(0.6))
            second.publish(1, twist(-0.6))
            first.pump(0.05)
            second.pump(0.05)
            ratios.append(sim.snapshot().trans_ratio)
        assert max(ratios) > 0, "the first client drove"
        assert min(ratios) >= 0, "the second client's messages reached the robot"
        assert bridge.arbiter is not None and bridge.arbiter.refused >= 10
        assert any("another Foxglove client" in s["message"] for s in second.statuses)
        assert not any("another Foxglove client" in s["message"] for s in first.statuses)
        # The first goes quiet: after the handover the second may drive.
        second.pump(HANDOVER + 0.3)
        stream(second, twist(-0.6), hz=10, seconds=1.0)
        assert sim.snapshot().trans_ratio < 0


def test_what_a_bind_address_exposes() -> None:
    assert loopback_only("127.0.0.1") and loopback_only("::1") and loopback_only("localhost")
    assert loopback_only("127.0.0.2")
    assert not loopback_only("0.0.0.0") and not loopback_only("::") and not loopback_only("192.168.1.5")
    assert not loopback_only("robot-laptop.lan")
