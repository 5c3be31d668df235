"""The lab: the fault proxy (tests/linkfaults.py) against a loopback echo server — each fault and Wi-Fi
profile does what it says — and the CPU-load generator (tests/cpuload.py)."""

from __future__ import annotations

import socket
import struct
import threading
import time
from collections.abc import Iterator

import pytest

from cpuload import CpuLoad, niceness, wait_busy
from linkfaults import (
    BUSY_WIFI,
    FAKE_HEADER,
    GOOD_WIFI,
    LOSSY_WIFI,
    PROFILES,
    RTO_MIN,
    TO_CLIENT,
    TO_SERVER,
    FaultProxy,
    WifiProfile,
)


@pytest.fixture
def proxy() -> Iterator[FaultProxy]:
    server = socket.create_server(("127.0.0.1", 0))

    def echo() -> None:
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            threading.Thread(target=_echo, args=(conn,), daemon=True).start()

    threading.Thread(target=echo, daemon=True).start()
    with FaultProxy("127.0.0.1", server.getsockname()[1]) as p:
        yield p
    server.close()


def _echo(conn: socket.socket) -> None:
    with conn:
        try:
            while data := conn.recv(4096):
                conn.sendall(data)
        except OSError:
            pass


def _client(proxy: FaultProxy) -> socket.socket:
    sock = socket.create_connection(("127.0.0.1", proxy.port), timeout=5)
    sock.sendall(b"hi")
    assert sock.recv(16) == b"hi"
    return sock


def _quiet(sock: socket.socket, seconds: float = 0.3) -> bool:
    sock.settimeout(seconds)
    try:
        sock.recv(16)
    except TimeoutError:
        return True
    finally:
        sock.settimeout(5)
    return False


def test_a_side_that_closes_is_seen_closing_through_the_proxy(proxy: FaultProxy) -> None:
    """The client's FIN reaches the echo server, which closes too: its FIN comes back (a client that
    logs out is gone at the server, as over a plain link)."""
    with _client(proxy) as sock:
        sock.shutdown(socket.SHUT_WR)
        assert sock.recv(16) == b""  # the server's close, within the socket's 5 s


def test_a_side_that_resets_is_seen_closing_through_the_proxy() -> None:
    """A peer that ends with an RST — a killed process with unread bytes, as a killed window with the
    robot's status waiting — is gone at the server too: before, the proxy's reader took the reset for an
    error of its own and the server kept that login for as long as the proxy lived."""
    server = socket.create_server(("127.0.0.1", 0))
    ended = threading.Event()

    def serve() -> None:
        conn, _ = server.accept()
        with conn:
            conn.settimeout(10)
            try:
                conn.sendall(b"status that nobody reads")
                while conn.recv(4096):
                    pass
            except OSError:
                pass
            ended.set()

    threading.Thread(target=serve, daemon=True).start()
    with FaultProxy("127.0.0.1", server.getsockname()[1]) as proxy:
        sock = socket.create_connection(("127.0.0.1", proxy.port), timeout=5)
        assert sock.recv(6, socket.MSG_PEEK) == b"status"  # bytes wait unread: a close is a reset
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        sock.close()
        assert ended.wait(5), "the server still holds the connection its client reset"
    server.close()


def test_later_held_holds_each_later_connection_and_never_the_first(proxy: FaultProxy) -> None:
    proxy.later_held = 1.0
    with (
        _client(proxy) as first,  # the first flows at once (_client reads its echo)
        socket.create_connection(("127.0.0.1", proxy.port), timeout=5) as later,
    ):
        later.sendall(b"hi")
        assert _quiet(later, 0.5), "a later connection's bytes came before its hold ended"
        first.sendall(b"go")
        assert first.recv(16) == b"go", "the first connection was held too"
        assert later.recv(16) == b"hi"  # then it flows (within recv's 5 s)


@pytest.mark.parametrize("directions", [(TO_CLIENT,), (TO_SERVER,), (TO_CLIENT, TO_SERVER)])
def test_mute_holds_bytes_and_restore_delivers_them_in_order(
    proxy: FaultProxy, directions: tuple[str, ...]
) -> None:
    with _client(proxy) as sock:
        proxy.mute(*directions)  # type: ignore[arg-type]
        sock.sendall(b"abc")
        assert _quiet(sock)
        proxy.restore()
        got = b""
        while len(got) < 3:
            got += sock.recv(16)
        assert got == b"abc"


def test_delay_each_way(proxy: FaultProxy) -> None:
    with _client(proxy) as sock:
        proxy.delay(0.2)
        sock.sendall(b"x")
        assert _quiet(sock, 0.3)  # 0.4 s round trip: nothing after 0.3 s…
        assert sock.recv(16) == b"x"  # …then the echo


def test_inject_reaches_the_client_only(proxy: FaultProxy) -> None:
    with _client(proxy) as sock:
        proxy.inject(FAKE_HEADER)
        assert sock.recv(16) == FAKE_HEADER


def test_reset_sends_an_rst_and_new_connections_still_work(proxy: FaultProxy) -> None:
    sock = _client(proxy)
    proxy.reset()
    time.sleep(0.1)
    with pytest.raises(ConnectionResetError):
        sock.sendall(b"y")
        sock.recv(16)
    sock.close()
    _client(proxy).close()
    assert proxy.connections == 2


def test_close_ends_every_thread() -> None:
    before = {t.name for t in threading.enumerate()}
    with FaultProxy("127.0.0.1", 9) as p:
        assert p.port
    time.sleep(0.05)
    assert not [t for t in threading.enumerate() if t.name.startswith("linkfaults") and t.name not in before]


def _echoed(sock: socket.socket, sent: bytes, timeout: float = 5.0) -> bytes:
    got = b""
    sock.settimeout(timeout)
    while len(got) < len(sent):
        got += sock.recv(65536)
    return got


def test_a_hold_delays_one_direction_then_delivers_everything_in_order(proxy: FaultProxy) -> None:
    with _client(proxy) as sock:
        proxy.hold(0.4, TO_CLIENT)
        sock.sendall(b"abc")
        assert _quiet(sock, 0.2)  # held…
        assert _echoed(sock, b"abc") == b"abc"  # …then delivered
        assert proxy.stalls[-1][1:] == (0.4, (TO_CLIENT,))


def test_a_roam_holds_both_directions(proxy: FaultProxy) -> None:
    with _client(proxy) as sock:
        at = proxy.roam(0.5)
        assert proxy.fault_at == at
        sock.sendall(b"r")
        assert _quiet(sock, 0.3)
        assert _echoed(sock, b"r") == b"r"
        assert proxy.held_until[TO_SERVER] == proxy.held_until[TO_CLIENT] == pytest.approx(at + 0.5)


def test_a_wifi_profile_stalls_and_jitters_but_loses_and_reorders_nothing(proxy: FaultProxy) -> None:
    storm = WifiProfile("storm", stall_rate=20, stall_min=0.01, stall_max=0.03, jitter=0.01, loss_rate=5)
    with _client(proxy) as sock:
        proxy.play(storm, seed=3)
        sent = b"".join(i.to_bytes(2, "big") for i in range(400))
        for i in range(0, len(sent), 8):
            sock.sendall(sent[i : i + 8])
            time.sleep(0.002)
        assert _echoed(sock, sent, timeout=10) == sent
        proxy.restore()
    assert len(proxy.stalls) >= 3  # ~25 a second for the ~1 s the bytes took
    assert any(seconds == pytest.approx(RTO_MIN) for _at, seconds, _d in proxy.stalls)  # a loss
    assert {p.name for p in (GOOD_WIFI, BUSY_WIFI, LOSSY_WIFI)} == set(PROFILES)


def test_cpu_load_spins_at_its_niceness_and_always_ends() -> None:
    with CpuLoad(count=2, nice=19, seconds=30) as load:
        assert wait_busy(load)
        assert [niceness(p.pid) for p in load.procs] == [19, 19]
        pids = [p.pid for p in load.procs]
    assert all(niceness(pid) is None for pid in pids)  # ended with the block
    short = CpuLoad(count=1, nice=19, seconds=0.3).start()  # …and by itself, however it is left
    try:
        short.procs[0].wait(10)
    finally:
        short.stop()
    with pytest.raises(ValueError):
        CpuLoad(nice=-5)
    with pytest.raises(ValueError):
        CpuLoad(seconds=0)


def test_garble_turns_a_direction_into_noise_of_the_same_length(proxy: FaultProxy) -> None:
    with _client(proxy) as sock:
        proxy.garble(TO_CLIENT)
        sent = b"\x0f\x0c" * 100
        sock.sendall(sent)
        got = _echoed(sock, sent)
        assert len(got) == len(sent) and got != sent and b"\x0f\x0c" not in got
        proxy.restore()
        sock.sendall(b"ok")
        assert _echoed(sock, b"ok") == b"ok"


def test_a_stalling_header_is_a_real_header_then_noise(proxy: FaultProxy) -> None:
    with _client(proxy) as sock:
        proxy.stalling_header()
        assert _echoed(sock, FAKE_HEADER) == FAKE_HEADER
        sock.sendall(b"abcd")
        assert _echoed(sock, b"abcd") != b"abcd"
