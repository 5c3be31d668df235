"""The fault proxy (tests/linkfaults.py) against a loopback echo server: each fault does what it says."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator

import pytest

from linkfaults import FAKE_HEADER, TO_CLIENT, TO_SERVER, FaultProxy


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
