"""Scanning for a map in the window: start, tag loops, stop — and the scan the robot says is running.

The requests are :mod:`.scan`'s (the ones ``rtmu scan`` sends). This feed follows
``mappingStatusBroadcast`` for the whole connection (asking ``mappingStatus`` once at login), so the
window hears a scan another client started or stopped, and publishes it as a
:class:`~rtmu.values.state.ScanChanged`: the banner shows it and the controller's guard refuses
everything that would move the robot on its own while it runs. A name from the robot that is not
one plain file name is ignored (and counted), never shown or downloaded.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable
from dataclasses import replace
from typing import Any, ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.mapping import MappingStatusBroadcast
from ..values.commission import ScanState
from ..values.intents import Intent, StartScan, StopScan, TagScanLoop
from ..values.state import ScanChanged
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError
from .feed import Feed, FeedContext
from .scan import ScanStatus, scan_status, scan_unavailable, start_scan, stop_scan, tag_loop
from .subscriptions import Subscription


class ScanFeed(Feed):
    """See the module notes (network loop only); ``value`` is the scan as last published."""

    handles: ClassVar[tuple[type[Intent], ...]] = (StartScan, StopScan, TagScanLoop)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.value = ScanState()
        self.bad_names = 0
        self._login = False
        self._heard_count = 0
        """Statuses heard on the subscription so far: an answer asked for before one of them is older news."""

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        return (Subscription(MappingStatusBroadcast.DATA_NAME, -1, self._heard),)

    def connected(self, client: AriaClient) -> None:
        self._login = True  # the first status heard tells what ran before this connection
        missing = scan_unavailable(client)
        self._set(ScanState(offered="scan" not in missing))
        if "scan_status" not in missing:
            self.ctx.spawn(self._ask(client), "scan-status")

    def disconnected(self) -> None:
        self._set(ScanState())

    async def _ask(self, client: AriaClient) -> None:
        heard = self._heard_count
        with contextlib.suppress(ClientError):  # the broadcast still tells us later; no status is no scan
            status = await scan_status(client, timeout=self.ctx.config.reply_timeout)
            # A status heard on the subscription while this waited is newer news, not older: it came
            # after the question on the same link — and may have been read with this very answer, which
            # only reaches here a turn of the loop later. Every change after it is broadcast.
            if self._heard_count == heard:
                self._status(status, at_login=True)

    def _heard(self, packet: Packet) -> None:
        try:
            status = ScanStatus(MappingStatusBroadcast.decode(packet.payload).name)
        except ProtocolError:
            self.bad_names += 1
            return
        if status.name:  # the files' rules load with the first scan named, not with every launch
            from .remote_files import UnsafeName

            try:
                status.file_name  # noqa: B018 -- a name that cannot be a file is not taken
            except UnsafeName:
                self.bad_names += 1
                return
        self._heard_count += 1
        self._status(status)

    def _status(self, status: ScanStatus, *, at_login: bool = False) -> None:
        """The robot said which scan runs (a status answer names the scan, a broadcast its file)."""
        at_login, self._login = at_login or self._login, False  # (a subscription's first answer too)
        old = self.value
        if status.file_name == old.file_name:
            return
        if not status.scanning:
            self._set(replace(old, name="", file_name="", since=None, last_file=old.file_name))
            return
        since = None if at_login else self.ctx.clock()
        self._set(replace(old, name=status.name, file_name=status.file_name, since=since))

    def _set(self, value: ScanState) -> None:
        self.value = value
        self.ctx.publish(ScanChanged(value))

    def handle(self, intent: Intent) -> Any:
        client = self.require()
        if isinstance(intent, StartScan):
            return self._start(client, intent.name)
        if isinstance(intent, StopScan):
            return self._stop(client)
        assert isinstance(intent, TagScanLoop)
        return tag_loop(client, start=intent.start, timeout=self.ctx.config.reply_timeout)

    async def _start(self, client: AriaClient, name: str) -> str:
        file_name = await start_scan(client, name, timeout=self.ctx.config.reply_timeout)
        self._login = False  # started here and now, whatever was heard before
        self._status(ScanStatus(file_name))  # the broadcast says the same, later
        return file_name

    async def _stop(self, client: AriaClient) -> str:
        running = self.value.file_name
        file_name = await stop_scan(client, timeout=self.ctx.config.reply_timeout) or running
        if self.value.scanning:
            self._set(replace(self.value, name="", file_name="", since=None, last_file=file_name))
        elif file_name and not self.value.last_file:
            self._set(replace(self.value, last_file=file_name))
        return file_name
