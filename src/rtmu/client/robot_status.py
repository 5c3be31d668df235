"""The robot's status payloads as :class:`~rtmu.values.state.RobotState` fields — one reading for all.

The window's status stream (:class:`~rtmu.client.status_feed.StatusFeed`) and the command line
(``rtmu status``, ``rtmu drive``, ``rtmu fleet``) read ``updateNumbers``, ``updateStrings``, the
old ``update`` and ``batteryInfo`` through these functions, so a pose, a battery figure or its unit
means the same in both; the command line only formats the resulting ``RobotState``.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable, Container
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from ..protocol.payloads.robot import BatteryInfo, Update, UpdateNumbers, UpdateStrings
from ..values.state import RobotState
from .errors import MalformedReply, NotSupported

if TYPE_CHECKING:
    from .connection import AriaClient


def numbers_fields(n: UpdateNumbers, *, battery_known: bool = True) -> dict[str, Any]:
    """An ``updateNumbers`` (or ``update``'s numbers): pose, speeds, battery and temperature.

    ``battery_known`` False: ``batteryInfo`` has not said yet whether the battery number is volts or a
    state of charge, so it is left out (95.4 is no voltage)."""
    return {
        "x": float(n.x),
        "y": float(n.y),
        "th": float(n.th),
        "vel": float(n.vel),
        "rot_vel": float(n.rot_vel),
        "lat_vel": float(n.lat_vel),
        "battery_v": n.battery if battery_known else None,
        "temperature": float(n.temperature) if n.temperature_known else None,
    }


def strings_fields(s: UpdateStrings | Update) -> dict[str, Any]:
    """The status and mode words (and ``updateStrings``' extended status)."""
    fields: dict[str, Any] = {"status": s.status, "mode": s.mode}
    if isinstance(s, UpdateStrings):
        fields["extended_status"] = s.extended_status
    return fields


def battery_fields(info: BatteryInfo) -> dict[str, Any]:
    """``batteryInfo``: the warning and shutdown levels, and whether the figure is a state of charge."""
    return {
        "battery_low": info.low_battery,
        "battery_shutdown": info.shutdown,
        "battery_is_soc": info.state_of_charge,
    }


async def battery_info(client: AriaClient, timeout: float) -> BatteryInfo | None:
    """The server's ``batteryInfo`` (None when it offers none)."""
    if not client.supports("batteryInfo"):
        return None
    info = (await client.request_once("batteryInfo", timeout=timeout)).decode()
    return info if isinstance(info, BatteryInfo) else None


StatusAsk = Callable[[str], Awaitable[object]]
"""One reply asked for now and decoded; whatever is not the data's payload type counts as unread."""


async def read_status(ask: StatusAsk, offers: Container[str]) -> RobotState | None:
    """One status from what the server lists: ``batteryInfo``, then ``updateNumbers`` +
    ``updateStrings``, or the old ``update`` — the one choice ``rtmu status``, ``doctor`` and ``why``
    make alike. None when no pose could be read (not listed, or its reply did not decode): each
    caller says that its own way (doctor a failed step, why a note, status an error)."""
    robot = RobotState()
    if "batteryInfo" in offers:
        info = await ask("batteryInfo")
        if isinstance(info, BatteryInfo):
            robot = replace(robot, **battery_fields(info))
    if "updateNumbers" in offers:
        numbers = await ask("updateNumbers")
        if not isinstance(numbers, UpdateNumbers):
            return None
        robot = replace(robot, **numbers_fields(numbers))
        if "updateStrings" in offers:
            strings = await ask("updateStrings")
            if isinstance(strings, UpdateStrings):
                robot = replace(robot, **strings_fields(strings))
        return robot
    if "update" in offers:
        update = await ask("update")
        if isinstance(update, Update):
            return replace(robot, **numbers_fields(update.numbers), **strings_fields(update))
    return None


async def fetch_robot_state(client: AriaClient, timeout: float) -> RobotState:
    """One status asked for at once (:func:`read_status`). :class:`NotSupported` (:func:`no_status`)
    from a server with no status; :class:`MalformedReply` when its status does not decode."""

    async def ask(name: str) -> object:
        return (await client.request_once(name, timeout=timeout)).decode()

    robot = await read_status(ask, client.datalist)
    if robot is not None:
        return robot
    if client.supports("updateNumbers") or client.supports("update"):
        raise MalformedReply("the server's status reply does not decode as a robot status")
    raise no_status(client)


def no_status(client: AriaClient) -> NotSupported:
    """Why there is no robot status: ARIA's central server has robots, not a status of its own."""
    from .diagnosis import central_server_words

    if client.supports("clientList"):
        return NotSupported("updateNumbers", central_server_words(f"{client.host}:{client.port}"))
    return NotSupported("updateNumbers", "this server offers no robot status (updateNumbers or update)")
