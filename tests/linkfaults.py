"""A fault-injecting TCP proxy for tests: a real loopback link whose faults the test switches at will.

Put it between a client (the window, ``rtmu drive``) and a real server (the simulator)::

    with FaultProxy("127.0.0.1", sim.port) as proxy:
        ...connect the client to 127.0.0.1:proxy.port...
        t = proxy.mute(TO_CLIENT)          # server→client silent (bytes are held, as TCP would)
        proxy.restore()                    # everything flows again, held bytes first
        proxy.delay(0.4)                   # +400 ms each way (800 ms round trip)
        proxy.inject(FAKE_HEADER)          # bytes toward the client, in stream order
        proxy.reset()                      # RST to both ends (SO_LINGER 0)

Every fault method returns the ``time.monotonic()`` at which it took effect (``fault_at``), so a
test or bench can measure how long the client took to react as seen by the server. Threads only
(two per direction per connection, plus the acceptor); buffers are bounded (a full buffer stops
reading, which is back-pressure as over TCP); :meth:`close` ends every thread within a second.
"""

from __future__ import annotations

import collections
import random
import socket
import struct
import threading
import time
from collections.abc import Callable
from typing import Literal

Direction = Literal["to_client", "to_server"]
TO_CLIENT: Direction = "to_client"
TO_SERVER: Direction = "to_server"
BOTH: tuple[Direction, ...] = (TO_CLIENT, TO_SERVER)

FAKE_HEADER = bytes.fromhex("0F0C007D")
"""ArNetworking sync bytes + a length of 32 000: a header announcing a packet that never comes."""
GARBAGE = random.Random(15).randbytes(1024)
"""1 KiB of line noise (fixed seed): no valid packet in it."""
MAX_BUFFER = 4 * 1024 * 1024
READ_CHUNK = 65536


class _Pipe:
    """One direction of one connection: a reader thread queues (due time, bytes), a writer sends them."""

    def __init__(self, proxy: FaultProxy, direction: Direction, src: socket.socket, dst: socket.socket):
        self.proxy = proxy
        self.direction = direction
        self.src = src
        self.dst = dst
        self.queue: collections.deque[tuple[float, bytes]] = collections.deque()
        self.queued = 0
        self.cond = threading.Condition()
        self.done = False
        self.threads = [
            threading.Thread(target=self._read, name=f"linkfaults-read-{direction}", daemon=True),
            threading.Thread(target=self._write, name=f"linkfaults-write-{direction}", daemon=True),
        ]
        for t in self.threads:
            t.start()

    def put(self, data: bytes) -> None:
        tap = self.proxy.tap
        if tap is not None:  # before it is queued: a fault the tap sets applies to what follows
            tap(self.direction, data)
        with self.cond:
            self.queue.append((time.monotonic() + self.proxy.delays[self.direction], data))
            self.queued += len(data)
            self.cond.notify_all()

    def _read(self) -> None:
        try:
            while not self.done:
                with self.cond:
                    while self.queued > MAX_BUFFER and not self.done:
                        self.cond.wait(0.1)
                data = self.src.recv(READ_CHUNK)
                if not data:
                    break
                self.put(data)
        except OSError:
            pass
        self.finish()

    def _write(self) -> None:
        try:
            while True:
                with self.cond:
                    while True:
                        if self.done and not self.queue:
                            return
                        if self.queue and self.direction not in self.proxy.muted:
                            due = self.queue[0][0]
                            wait = due - time.monotonic()
                            if wait <= 0:
                                _, data = self.queue.popleft()
                                self.queued -= len(data)
                                self.cond.notify_all()
                                break
                            self.cond.wait(min(wait, 0.1))
                        elif self.done and self.direction in self.proxy.muted:
                            return
                        else:
                            self.cond.wait(0.1)
                self.dst.sendall(data)
        except OSError:
            pass
        finally:
            self.finish()

    def wake(self) -> None:
        with self.cond:
            self.cond.notify_all()

    def finish(self) -> None:
        with self.cond:
            self.done = True
            self.cond.notify_all()


class _Link:
    def __init__(self, proxy: FaultProxy, client: socket.socket, server: socket.socket) -> None:
        self.client = client
        self.server = server
        self.pipes = {
            TO_SERVER: _Pipe(proxy, TO_SERVER, client, server),
            TO_CLIENT: _Pipe(proxy, TO_CLIENT, server, client),
        }

    def close(self, *, rst: bool = False) -> None:
        for pipe in self.pipes.values():
            pipe.finish()
            pipe.queue.clear()
        for sock in (self.client, self.server):
            try:
                if rst:
                    sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                    # Wake the reader thread blocked in recv() (shutting reads sends nothing): until that
                    # call returns it holds the socket, and the close below would not reset anything.
                    sock.shutdown(socket.SHUT_RD)
                else:
                    sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            sock.close()

    def join(self, timeout: float) -> None:
        end = time.monotonic() + timeout
        for pipe in self.pipes.values():
            for t in pipe.threads:
                t.join(max(0.0, end - time.monotonic()))


class FaultProxy:
    """Listens on 127.0.0.1 (ephemeral port), forwards each connection to ``target``; see the module notes."""

    def __init__(self, host: str, port: int) -> None:
        self.target = (host, port)
        self.muted: set[Direction] = set()
        self.delays: dict[Direction, float] = {TO_CLIENT: 0.0, TO_SERVER: 0.0}
        self.fault_at: float | None = None
        """``time.monotonic()`` when the last fault took effect (None: none yet)."""
        self.connections = 0
        """Connections accepted so far (a reconnect shows up here)."""
        self.server_ports: list[int] = []
        """Our local port of each connection to the target: the client's address as the server sees it."""
        self.tap: Callable[[Direction, bytes], None] | None = None
        """``tap(direction, data)`` for every chunk read, before it is forwarded (its reader's thread)."""
        self._links: list[_Link] = []
        self._lock = threading.Lock()
        self._listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._listener.bind(("127.0.0.1", 0))
        self._listener.listen(8)
        self._listener.settimeout(0.1)
        self._closed = threading.Event()
        self._acceptor = threading.Thread(target=self._accept, name="linkfaults-accept", daemon=True)

    @property
    def port(self) -> int:
        return int(self._listener.getsockname()[1])

    def start(self) -> FaultProxy:
        self._acceptor.start()
        return self

    def __enter__(self) -> FaultProxy:
        return self.start()

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
                server.settimeout(None)
            except OSError:
                client.close()
                continue
            client.settimeout(None)
            for sock in (client, server):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                if self._closed.is_set():
                    client.close()
                    server.close()
                    return
                self._links = [link for link in self._links if not all(p.done for p in link.pipes.values())]
                # Counted before the link starts forwarding: a client whose echo came back must see it.
                self.connections += 1
                self.server_ports.append(int(server.getsockname()[1]))
                self._links.append(_Link(self, client, server))

    def _applied(self) -> float:
        with self._lock:
            for link in self._links:
                for pipe in link.pipes.values():
                    pipe.wake()
        self.fault_at = time.monotonic()
        return self.fault_at

    # -- faults --------------------------------------------------------------------------------
    def mute(self, *directions: Direction) -> float:
        """Hold every byte going ``directions`` (default: server→client) until :meth:`restore`."""
        self.muted.update(directions or (TO_CLIENT,))
        return self._applied()

    def delay(self, seconds: float, *directions: Direction) -> float:
        """Delay bytes going ``directions`` (default: both) by ``seconds`` (bytes read from now on)."""
        for d in directions or BOTH:
            self.delays[d] = seconds
        return self._applied()

    def inject(self, data: bytes, direction: Direction = TO_CLIENT) -> float:
        """Slip ``data`` into the stream toward ``direction`` on every open connection, in order."""
        with self._lock:
            links = list(self._links)
        for link in links:
            link.pipes[direction].put(data)
        self.fault_at = time.monotonic()
        return self.fault_at

    def reset(self) -> float:
        """Abort every open connection with an RST to both ends (new connections still work)."""
        with self._lock:
            links, self._links = self._links, []
        self.fault_at = time.monotonic()
        for link in links:
            link.close(rst=True)
        return self.fault_at

    def restore(self) -> None:
        """No mute, no delay: held bytes flow again in order."""
        self.muted.clear()
        self.delays = {TO_CLIENT: 0.0, TO_SERVER: 0.0}
        at = self.fault_at
        self._applied()
        self.fault_at = at

    def close(self) -> None:
        """Stop accepting, close every connection, join the threads (bounded)."""
        self._closed.set()
        self._listener.close()
        with self._lock:
            links, self._links = self._links, []
        for link in links:
            link.close()
        if self._acceptor.is_alive():
            self._acceptor.join(1.0)
        for link in links:
            link.join(1.0)
