"""A fault-injecting TCP proxy for tests: a real loopback link whose faults the test switches at will.

Put it between a client (the window, ``rtmu drive``) and a real server (the simulator)::

    with FaultProxy("127.0.0.1", sim.port) as proxy:
        ...connect the client to 127.0.0.1:proxy.port...
        t = proxy.mute(TO_CLIENT)          # server→client silent (bytes are held, as TCP would)
        proxy.restore()                    # everything flows again, held bytes first
        proxy.delay(0.4)                   # +400 ms each way (800 ms round trip)
        proxy.inject(FAKE_HEADER)          # bytes toward the client, in stream order
        proxy.reset()                      # RST to both ends (SO_LINGER 0)

``FaultProxy(host, port, later_held=1.5)`` holds the server's bytes to every connection after the first
for 1.5 s from its accept: a second login (the window's guardian, beside the window) comes late.

Every fault method returns the ``time.monotonic()`` at which it took effect (``fault_at``), so a
test or bench can measure how long the client took to react as seen by the server. Threads only
(two per direction per connection, plus the acceptor); buffers are bounded (a full buffer stops
reading, which is back-pressure as over TCP); a side that closes (or resets) is seen closing once its
last byte is through; :meth:`close` ends every thread within a second.

Real Wi-Fi loses nothing a TCP stream can see, but holds it: 802.11 retries, background scans and
contention stall a direction for tens to hundreds of ms now and then, and a lost segment costs a
retransmission timeout (Linux: at least 200 ms, doubled per loss in a row). :meth:`play` plays a
:class:`WifiProfile` — stalls at a Poisson rate with lengths drawn from a range, per-chunk jitter,
loss bursts as retransmission stalls — until :meth:`restore`; :meth:`roam` is a 1–2 s gap in both
directions, as when a robot moves between access points. Stalls hold bytes, in order, never drop
them; :attr:`stalls` lists what was played (start, seconds, directions), seeded, so a run repeats.
"""

from __future__ import annotations

import collections
import random
import socket
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
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
RTO_MIN = 0.2
"""Linux's minimum TCP retransmission timeout: what one lost segment costs a stream."""


@dataclass(frozen=True)
class WifiProfile:
    """How a Wi-Fi link holds a stream (see the module notes); rates are per second, lengths in s."""

    name: str
    stall_rate: float = 0.0
    """Stalls per second (Poisson)."""
    stall_min: float = 0.0
    stall_max: float = 0.0
    stall_directions: tuple[Direction, ...] = (TO_CLIENT,)
    jitter: float = 0.0
    """Each chunk is delayed by 0…``jitter`` s more (order kept)."""
    loss_rate: float = 0.0
    """Loss bursts per second (Poisson), either direction: 1…``loss_burst`` segments lost in a row."""
    loss_burst: int = 1

    def loss_stall(self, lost: int) -> float:
        """The retransmission stall ``lost`` segments in a row cost (the timeout doubles each time)."""
        return RTO_MIN * (2**lost - 1)


GOOD_WIFI = WifiProfile("good", stall_rate=0.1, stall_min=0.05, stall_max=0.15, jitter=0.005)
"""The issue's "good Wi-Fi": the server→client direction held 50–150 ms about every 10 s."""
BUSY_WIFI = WifiProfile("busy", stall_rate=1 / 3, stall_min=0.1, stall_max=0.3, jitter=0.02)
"""The issue's "busy Wi-Fi": held 100–300 ms about every 3 s, and 0–20 ms jitter on every chunk."""
LOSSY_WIFI = WifiProfile("lossy", jitter=0.01, loss_rate=0.2, loss_burst=1)
"""One lost segment about every 5 s in either direction: a 200 ms retransmission stall each."""
PROFILES = {p.name: p for p in (GOOD_WIFI, BUSY_WIFI, LOSSY_WIFI)}


class _Pipe:
    """One direction of one connection: a reader thread queues (due time, bytes), a writer sends them."""

    def __init__(
        self,
        proxy: FaultProxy,
        direction: Direction,
        src: socket.socket,
        dst: socket.socket,
        held_until: float = 0.0,
    ):
        self.proxy = proxy
        self.held_until = held_until
        """This pipe's own hold (``time.monotonic()``), beside the proxy's for its direction."""
        self.direction = direction
        self.src = src
        server_side = src if direction == TO_CLIENT else dst
        self.server_port = int(server_side.getsockname()[1])
        """Our port toward the server: the client's address as the server sees it (for the trace)."""
        self.dst = dst
        self.queue: collections.deque[tuple[float, bytes, bool, float]] = collections.deque()
        self.queued = 0
        self.cond = threading.Condition()
        self.done = False
        self.ended = False
        """The source closed its side (EOF): once every byte read is out, so does the destination."""
        self.threads = [
            threading.Thread(target=self._read, name=f"linkfaults-read-{direction}", daemon=True),
            threading.Thread(target=self._write, name=f"linkfaults-write-{direction}", daemon=True),
        ]
        for t in self.threads:
            t.start()

    def put(self, data: bytes, *, raw: bool = False) -> None:
        tap = self.proxy.tap
        if tap is not None and not raw:  # before it is queued: a fault the tap sets applies to what follows
            tap(self.direction, data)
        clean = not raw
        if not raw and self.direction in self.proxy.garbled:
            data = self.proxy.noise(len(data))
            clean = False
        with self.cond:
            read_at = time.monotonic()
            due = read_at + self.proxy.delays[self.direction] + self.proxy.chunk_jitter()
            if self.queue:
                due = max(due, self.queue[-1][0])  # jitter never reorders a stream
            self.queue.append((due, data, clean, read_at))
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
                    self.ended = not self.done  # the peer's own close, not ours (reset, close)
                    break
                self.put(data)
        except OSError:  # a reset (a peer that closed with bytes unread) is the peer's close too: passed
            self.ended = not self.done  # on, else the far end kept a session nobody was behind
        self.finish()

    def _write(self) -> None:
        try:
            while True:
                with self.cond:
                    while True:
                        if self.done and not self.queue:
                            if self.ended:  # as TCP does: the peer's FIN after its last byte
                                self.dst.shutdown(socket.SHUT_WR)
                            return
                        if self.queue and self.direction not in self.proxy.muted:
                            held = max(self.proxy.held_until[self.direction], self.held_until)
                            due = max(self.queue[0][0], held)
                            wait = due - time.monotonic()
                            if wait <= 0:
                                _, data, clean, read_at = self.queue.popleft()
                                self.queued -= len(data)
                                self.cond.notify_all()
                                break
                            self.cond.wait(min(wait, 0.1))
                        elif self.done and self.direction in self.proxy.muted:
                            return
                        else:
                            self.cond.wait(0.1)
                self.dst.sendall(data)
                if clean:
                    self.proxy.delivered_at[self.direction] = self.proxy.clock()
                trace = self.proxy.trace
                if trace is not None:
                    written = time.monotonic()
                    trace.append((self.direction, self.server_port, read_at, due, written, len(data)))
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
    def __init__(
        self, proxy: FaultProxy, client: socket.socket, server: socket.socket, held_until: float = 0.0
    ) -> None:
        self.client = client
        self.server = server
        self.pipes = {
            TO_SERVER: _Pipe(proxy, TO_SERVER, client, server),
            TO_CLIENT: _Pipe(proxy, TO_CLIENT, server, client, held_until),
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

    def __init__(
        self, host: str, port: int, *, clock: Callable[[], float] = time.monotonic, later_held: float = 0.0
    ) -> None:
        self.target = (host, port)
        self.later_held = later_held
        """Seconds the server's bytes to each connection after the first wait from its accept (its login
        comes that much later; :meth:`restore` leaves this alone)."""
        self.clock = clock
        """Stamps :attr:`delivered_at` (a test passes the simulator's clock)."""
        self.delivered_at: dict[Direction, float | None] = {TO_CLIENT: None, TO_SERVER: None}
        """When the last of the server's own bytes (not injected, not garbled) went out each way."""
        self.muted: set[Direction] = set()
        self.delays: dict[Direction, float] = {TO_CLIENT: 0.0, TO_SERVER: 0.0}
        self.garbled: set[Direction] = set()
        """Directions whose bytes are replaced by line noise of the same length (:meth:`garble`)."""
        self._noise = random.Random(16)
        self.held_until: dict[Direction, float] = {TO_CLIENT: 0.0, TO_SERVER: 0.0}
        """Bytes going each way wait until this ``time.monotonic()`` (a stall or a roam)."""
        self.stalls: list[tuple[float, float, tuple[Direction, ...]]] = []
        """What :meth:`play` and :meth:`roam` held: (start, seconds, directions)."""
        self._profile: WifiProfile | None = None
        self._jitter_rng = random.Random(0)
        self._player: threading.Thread | None = None
        self._playing = threading.Event()
        self.fault_at: float | None = None
        """``time.monotonic()`` when the last fault took effect (None: none yet)."""
        self.connections = 0
        """Connections accepted so far (a reconnect shows up here)."""
        self.server_ports: list[int] = []
        """Our local port of each connection to the target: the client's address as the server sees it."""
        self.trace: list[tuple[Direction, int, float, float, float, int]] | None = None
        """A list to fill (None: no tracing): per chunk forwarded, (direction, :attr:`server_ports` entry,
        read, due, written, bytes) — ``time.monotonic()`` times: when the proxy read it, when the profile
        meant it to go, when it went. ``written - due`` is the proxy's own lateness."""
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
                held_until = (
                    time.monotonic() + self.later_held if self.connections and self.later_held else 0.0
                )
                self.connections += 1
                self.server_ports.append(int(server.getsockname()[1]))
                self._links.append(_Link(self, client, server, held_until))

    def _applied(self) -> float:
        self._wake()
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
            link.pipes[direction].put(data, raw=True)
        self.fault_at = time.monotonic()
        return self.fault_at

    def garble(self, *directions: Direction) -> float:
        """From now on replace every byte going ``directions`` (default: server→client) by noise."""
        self.garbled.update(directions or (TO_CLIENT,))
        return self._applied()

    def noise(self, n: int) -> bytes:
        return self._noise.randbytes(n).replace(b"\x0f\x0c", b"\x0f\x0d")  # never a sync pair

    def stalling_header(self) -> float:
        """A fake header that holds the stream: nothing valid follows it (the rest is garbled)."""
        at = self.inject(FAKE_HEADER)
        self.garble(TO_CLIENT)
        self.fault_at = at
        return at

    def hold(self, seconds: float, *directions: Direction) -> float:
        """Hold every byte going ``directions`` (default: both) for ``seconds`` from now, in order."""
        now = time.monotonic()
        directions = directions or BOTH
        for d in directions:
            self.held_until[d] = max(self.held_until[d], now + seconds)
        self.stalls.append((now, seconds, tuple(directions)))
        self._wake()
        return now

    def roam(self, seconds: float = 1.5) -> float:
        """A robot moving between access points: nothing in either direction for ``seconds``."""
        self.fault_at = self.hold(seconds, *BOTH)
        return self.fault_at

    def play(self, profile: WifiProfile, seed: int = 0) -> None:
        """Play ``profile`` (stalls, jitter, loss stalls) from now until :meth:`restore` or :meth:`close`."""
        self.stop_playing()
        self._profile = profile
        self._jitter_rng = random.Random(seed + 1)
        self._playing.set()
        rng = random.Random(seed)
        self._player = threading.Thread(
            target=self._play, args=(profile, rng), name=f"linkfaults-{profile.name}", daemon=True
        )
        self._player.start()

    def _play(self, profile: WifiProfile, rng: random.Random) -> None:
        rate = profile.stall_rate + profile.loss_rate
        while rate > 0 and self._playing.is_set() and not self._closed.is_set():
            wait = rng.expovariate(rate)
            end = time.monotonic() + wait
            while self._playing.is_set() and time.monotonic() < end:
                time.sleep(min(0.05, max(0.0, end - time.monotonic())))
            if not self._playing.is_set():
                return
            if rng.random() * rate < profile.stall_rate:
                length = rng.uniform(profile.stall_min, profile.stall_max)
                self.hold(length, *profile.stall_directions)
            else:
                length = profile.loss_stall(rng.randint(1, max(1, profile.loss_burst)))
                self.hold(length, rng.choice(BOTH))
            # The next stall starts after this one ends: stalls never merge into a longer one
            # than the profile says (the gaps between them are Poisson).
            end = time.monotonic() + length
            while self._playing.is_set() and time.monotonic() < end:
                time.sleep(min(0.05, max(0.0, end - time.monotonic())))

    def stop_playing(self) -> None:
        """End a :meth:`play` (stalls under way run out; no new ones start)."""
        self._playing.clear()
        self._profile = None
        player, self._player = self._player, None
        if player is not None and player is not threading.current_thread():
            player.join(1.0)

    def chunk_jitter(self) -> float:
        profile = self._profile
        if profile is None or profile.jitter <= 0:
            return 0.0
        return self._jitter_rng.uniform(0.0, profile.jitter)

    def _wake(self) -> None:
        with self._lock:
            links = list(self._links)
        for link in links:
            for pipe in link.pipes.values():
                pipe.wake()

    def reset(self) -> float:
        """Abort every open connection with an RST to both ends (new connections still work)."""
        with self._lock:
            links, self._links = self._links, []
        self.fault_at = time.monotonic()
        for link in links:
            link.close(rst=True)
        return self.fault_at

    def restore(self) -> None:
        """No mute, no delay, no profile, no stall: held bytes flow again in order."""
        self.stop_playing()
        self.garbled.clear()
        self.muted.clear()
        self.delays = {TO_CLIENT: 0.0, TO_SERVER: 0.0}
        self.held_until = {TO_CLIENT: 0.0, TO_SERVER: 0.0}
        at = self.fault_at
        self._applied()
        self.fault_at = at

    def close(self) -> None:
        """Stop accepting, close every connection, join the threads (bounded)."""
        self._closed.set()
        self.stop_playing()
        self._listener.close()
        with self._lock:
            links, self._links = self._links, []
        for link in links:
            link.close()
        if self._acceptor.is_alive():
            self._acceptor.join(1.0)
        for link in links:
            link.join(1.0)
