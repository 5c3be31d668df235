"""A loopback TCP proxy whose later connections log in slowly: the guardian's login, held back.

The first connection through it (the driving process's own) flows at once; every later one (the
guardian's) gets no byte from the server until ``hold`` s after it was accepted, so its login takes
that long — the window that connected a moment ago is then already up, and a freeze in between is
exactly the case the guardian used to miss. Threads only; :meth:`close` ends them (bounded).
"""

from __future__ import annotations

import contextlib
import socket
import threading
import time


class SlowLogins:
    def __init__(self, port: int, hold: float) -> None:
        self.target = ("127.0.0.1", port)
        self.hold = hold
        self.accepted = 0
        self._socks: list[socket.socket] = []
        self._lock = threading.Lock()
        self._closed = threading.Event()
        self._listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._listener.bind(("127.0.0.1", 0))
        self._listener.listen(8)
        self._listener.settimeout(0.1)
        self._acceptor = threading.Thread(target=self._accept, name="slow-logins", daemon=True)

    @property
    def port(self) -> int:
        return int(self._listener.getsockname()[1])

    def __enter__(self) -> SlowLogins:
        self._acceptor.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _accept(self) -> None:
        while not self._closed.is_set():
            try:
                client, _ = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            try:
                server = socket.create_connection(self.target, timeout=5)
            except OSError:
                client.close()
                continue
            for sock in (client, server):
                sock.settimeout(None)
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                self._socks += [client, server]
                due = 0.0 if self.accepted == 0 else time.monotonic() + self.hold
                self.accepted += 1
            threading.Thread(target=self._pipe, args=(client, server, 0.0), daemon=True).start()
            threading.Thread(target=self._pipe, args=(server, client, due), daemon=True).start()

    def _pipe(self, src: socket.socket, dst: socket.socket, due: float) -> None:
        try:
            while True:
                data = src.recv(65536)
                if not data:
                    break
                wait = due - time.monotonic()
                if wait > 0:
                    time.sleep(wait)
                dst.sendall(data)
        except OSError:
            pass
        with contextlib.suppress(OSError):
            dst.shutdown(socket.SHUT_WR)

    def close(self) -> None:
        self._closed.set()
        self._listener.close()
        with self._lock:
            socks, self._socks = self._socks, []
        for sock in socks:
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
            sock.close()
        self._acceptor.join(2)
