"""A central server that lists a very big site: thousands of robots, reached at a few simulators' ports.

ARIA's central server lists every robot switched to it. A site of hundreds or thousands cannot be
simulated robot by robot on one machine, yet a window must stay responsive when a central server
lists that many; so :class:`ListingCentral` (the real :class:`~rtmu.sim.central.CentralServer` on its
operators' port) lists ``count`` named robots whose forwarded ports are those of a few real
simulators, in turn. Like ARIA's, its ``clientList`` holds as many as one packet does; the rest follow
at once as ``clientAdded`` broadcasts, one per robot. For tests and ``bench``
(:class:`ListingCentralThread`: on a thread of its own).
"""

from __future__ import annotations

from ..protocol.events import RequestOnce, RequestReceived
from ..protocol.fields import FieldWriter
from ..protocol.packet import MAX_PAYLOAD, encode_packet
from ..protocol.payloads.central import CentralEntry, ClientAdded, ClientList
from .central import OPERATOR_DATA, CentralConfig, CentralServer
from .loop_thread import LoopThread
from .peers import Operator


class ListingCentral(CentralServer):
    """See the module notes: robots ``robot1`` … ``robot<count>``, at ``ports`` in turn."""

    def __init__(self, count: int, ports: list[int], config: CentralConfig | None = None) -> None:
        super().__init__(config or CentralConfig(host="127.0.0.1", port=0, robot_port=0))
        if not ports:
            raise ValueError("a listing central server needs at least one port to list robots at")
        self.entries = [
            CentralEntry("", ports[i % len(ports)], f"robot{i + 1}", "", "127.0.0.1") for i in range(count)
        ]
        self.lists_sent = 0
        self.held = self._fitting()
        """How many robots the list's one packet holds (the rest are announced one by one)."""

    def _fitting(self) -> int:
        size = 2  # the count
        for n, entry in enumerate(self.entries):
            size += len(entry.write(FieldWriter()).bytes())
            if size > MAX_PAYLOAD:
                return n
        return len(self.entries)

    def robots(self) -> list[CentralEntry]:
        return list(self.entries)

    def client_list(self) -> bytes:
        return ClientList(tuple(self.entries[: self.held])).encode()

    def _on_operator(self, op: Operator, event: object) -> None:
        super()._on_operator(op, event)
        asked = isinstance(event, RequestOnce) or (isinstance(event, RequestReceived) and event.new)
        if asked and getattr(event, "name", "") == ClientList.DATA_NAME:
            self.lists_sent += 1
            self._announce_the_rest(op)

    def _announce_the_rest(self, op: Operator) -> None:
        """The robots the list's one packet could not hold, as ``clientAdded`` to this operator."""
        number = OPERATOR_DATA.number(ClientAdded.DATA_NAME)
        if number is None or number not in op.subscriptions:
            return
        op.write(b"".join(encode_packet(number, ClientAdded(e).encode()) for e in self.entries[self.held :]))


class ListingCentralThread(LoopThread):
    """A :class:`ListingCentral` on a thread and loop of its own: ``with ListingCentralThread(…) as c:``."""

    what = "the listing central server"
    thread_name = "rtmu-listing-central"

    def __init__(self, count: int, ports: list[int]) -> None:
        super().__init__()
        self.count = count
        self.ports = ports
        self.central: ListingCentral | None = None

    async def _open(self) -> None:
        self.central = ListingCentral(self.count, self.ports)
        await self.central.start()

    @property
    def port(self) -> int:
        assert self.central is not None
        return self.central.port

    def __enter__(self) -> ListingCentralThread:
        self._start_loop()
        return self

    def __exit__(self, *exc: object) -> None:
        if self.running and self.central is not None:
            central = self.central
            self.call(lambda: central.kill())
        self._halt()
