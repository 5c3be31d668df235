"""The robot's own status: pose, speeds, battery, status and mode words, safe drive and sonar.

The status stream (``updateNumbers`` + ``updateStrings``, or the old ``update``; read through
:mod:`rtmu.client.robot_status`, as the command line reads it) is also the
link's heartbeat: every status packet is told to the drive loop (:mod:`rtmu.client.drive_loop`),
whose health monitor declares the link stale when they stop.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable
from typing import ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.drive import SafeDrive
from ..protocol.payloads.drive import SetSafeDrive as SetSafeDrivePayload
from ..protocol.payloads.robot import BatteryInfo, ModeInfo, Update, UpdateNumbers, UpdateStrings
from ..values.intents import Intent, SetSafeDrive
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError, ClientTimeout
from .feed import Feed, FeedContext
from .robot_status import battery_fields, numbers_fields, strings_fields
from .subscriptions import Subscription

BATTERY_INFO_ATTEMPTS = 3
"""How many times ``batteryInfo`` is asked before the battery number is shown without its unit known."""


class StatusFeed(Feed):
    """Decodes the status stream into the published :class:`~rtmu.values.state.RobotState`."""

    handles: ClassVar[tuple[type[Intent], ...]] = (SetSafeDrive,)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.on_status: Callable[[float], None] = lambda at: None
        """Every status packet's arrival time: the session gives it to the drive loop's health."""
        self._battery_unit_known = True
        """False while ``batteryInfo`` has not said whether the battery number is volts or a state of
        charge: the number is not published until then (95.4 is no voltage)."""
        self._battery_held: float | None = None
        """The last battery number while its unit was not known yet: published once it is."""

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        period = self.ctx.config.status_interval_ms
        return (
            Subscription("updateNumbers", period, self._on_numbers),
            Subscription("updateStrings", -1, self._on_strings, needs="updateNumbers"),
            Subscription("update", period, self._on_update, unless="updateNumbers"),
            Subscription("getModeInfo", -1, self._on_mode_info),
            Subscription("sonarCurrent", self.ctx.config.sonar_interval_ms, self._on_sonar),
        )

    def connected(self, client: AriaClient) -> None:
        self._battery_unit_known = not client.supports("batteryInfo")
        self.ctx.spawn(self._fetch_infos(client), "status-infos")

    def handle(self, intent: Intent) -> None:
        assert isinstance(intent, SetSafeDrive)
        client = self.require("setSafeDrive")
        client.send(SetSafeDrivePayload(intent.on))
        if client.supports("getSafeDrive"):
            self.ctx.spawn(self._refresh_safe_drive(client), "safe-drive")

    # -- one-off questions after login -------------------------------------------------------
    async def _fetch_infos(self, client: AriaClient) -> None:
        timeout = self.ctx.config.reply_timeout
        with contextlib.suppress(ClientError, ProtocolError):
            try:
                if client.supports("batteryInfo"):
                    info = self.ctx.decode("batteryInfo", await self._ask_battery_info(client, timeout))
                    if isinstance(info, BatteryInfo):
                        self.ctx.robot_update(**battery_fields(info))
            finally:  # answered, refused or never answered: the number is shown, now and from then on
                if self.ctx.client is client and not self._battery_unit_known:
                    self._battery_unit_known = True
                    if self._battery_held is not None:
                        self.ctx.robot_update(battery_v=self._battery_held)
            if client.supports("getSafeDrive"):
                await self._refresh_safe_drive(client)

    async def _ask_battery_info(self, client: AriaClient, timeout: float) -> bytes:
        """``batteryInfo``'s reply, asked again after a timeout (a busy robot or laptop): an LD robot's
        state of charge shown as volts until the link ends is worse than a number shown late."""
        left = BATTERY_INFO_ATTEMPTS
        while True:
            try:
                return (await client.request_once("batteryInfo", timeout=timeout)).payload
            except ClientTimeout:
                left -= 1
                if not left:
                    raise

    async def _refresh_safe_drive(self, client: AriaClient) -> None:
        reply = await client.request_once("getSafeDrive", timeout=self.ctx.config.reply_timeout)
        self.on_safe_drive(reply.payload)

    def on_safe_drive(self, payload: bytes) -> None:
        """A ``getSafeDrive`` answer (also the drive loop's ping where it is the cheapest request)."""
        s = self.ctx.decode("getSafeDrive", payload)
        if isinstance(s, SafeDrive):
            self.ctx.robot_update(safe_drive=s.safe)

    # -- the stream --------------------------------------------------------------------------
    def _on_numbers(self, packet: Packet) -> None:
        numbers = self.ctx.decode(packet.name, packet.payload)
        if isinstance(numbers, UpdateNumbers):
            self._apply_numbers(numbers, packet.received_at)

    def _apply_numbers(self, n: UpdateNumbers, at: float) -> None:
        self._battery_held = n.battery
        self.ctx.robot_update(**numbers_fields(n, battery_known=self._battery_unit_known), numbers_at=at)
        self.on_status(at)

    def _on_strings(self, packet: Packet) -> None:
        s = self.ctx.decode(packet.name, packet.payload)
        if isinstance(s, UpdateStrings):
            self.ctx.robot_update(**strings_fields(s), strings_at=packet.received_at)

    def _on_update(self, packet: Packet) -> None:
        u = self.ctx.decode(packet.name, packet.payload)
        if isinstance(u, Update):
            self.ctx.robot_update(**strings_fields(u), strings_at=packet.received_at)
            self._apply_numbers(u.numbers, packet.received_at)

    def _on_mode_info(self, packet: Packet) -> None:
        m = self.ctx.decode(packet.name, packet.payload)
        if isinstance(m, ModeInfo):
            self.ctx.robot_update(
                mode_name=m.mode_name, mode_locked=m.locked, mode_will_unlock=m.will_unlock_if_requested
            )

    def _on_sonar(self, packet: Packet) -> None:
        readings = self.ctx.decode(packet.name, packet.payload)
        if readings is not None and hasattr(readings, "readings"):
            self.ctx.robot_update(sonar=tuple(readings.readings), sonar_at=packet.received_at)
