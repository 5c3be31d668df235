"""The robot's status payloads as :class:`~rtmu.values.state.RobotState` fields — one reading for all.

The window's status stream (:class:`~rtmu.client.status_feed.StatusFeed`) and the command line
(``rtmu status``, ``rtmu drive``, ``rtmu fleet``) read ``updateNumbers``, ``updateStrings``, the
old ``update`` and ``batteryInfo`` through these functions, so a pose, a battery figure or its unit
means the same in both; the command line only formats the resulting ``RobotState``.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

from ..protocol.payloads.robot import BatteryInfo, Update, UpdateNumbers, UpdateStrings
from ..values.state import RobotState
from .errors import NotSupported

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


async def fetch_robot_state(client: AriaClient, timeout: float) -> RobotState:
    """One status asked for at once: ``batteryInfo``, then ``updateNumbers`` + ``updateStrings`` (or
    the old ``update``). :class:`NotSupported` (:func:`no_status`) from a server with no status."""
    robot = RobotState()
    info = await battery_info(client, timeout)
    if info is not None:
        robot = replace(robot, **battery_fields(info))
    if client.supports("updateNumbers"):
        numbers = (await client.request_once("updateNumbers", timeout=timeout)).decode()
        assert isinstance(numbers, UpdateNumbers)
        robot = replace(robot, **numbers_fields(numbers))
        if client.supports("updateStrings"):
            strings = (await client.request_once("updateStrings", timeout=timeout)).decode()
            assert isinstance(strings, UpdateStrings)
            robot = replace(robot, **strings_fields(strings))
        return robot
    if client.supports("update"):
        update = (await client.request_once("update", timeout=timeout)).decode()
        assert isinstance(update, Update)
        return replace(robot, **numbers_fields(update.numbers), **strings_fields(update))
    raise no_status(client)


def no_status(client: AriaClient) -> NotSupported:
    """Why there is no robot status: ARIA's central server has robots, not a status of its own."""
    from .diagnosis import central_server_words

    if client.supports("clientList"):
        return NotSupported("updateNumbers", central_server_words(f"{client.host}:{client.port}"))
    return NotSupported("updateNumbers", "this server offers no robot status (updateNumbers or update)")
