"""One robot status as ``rtmu status``, ``rtmu drive`` and ``rtmu fleet`` print it: its JSON object, its line,
and the one request that fetches it (split from :mod:`._common`, which is about connecting and ending)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..client.connection import AriaClient


STATUS_KEYS = ("x", "y", "th", "vel", "rot_vel", "battery_v", "status", "mode")
"""The documented keys of a status object: mm, mm, degrees, mm/s, deg/s, volts, text, text. A robot
that reports state of charge gives ``battery_pct`` (percent) in place of ``battery_v``."""


def status_object(numbers: Any, status: str, mode: str, *, soc: bool = False) -> dict[str, Any]:
    """One status as the JSON object ``rtmu status`` and ``rtmu drive`` print.

    ``soc``: the server's ``batteryInfo`` says the battery figure is percent of charge, not volts.
    """
    return {
        "x": numbers.x,
        "y": numbers.y,
        "th": numbers.th,
        "vel": numbers.vel,
        "rot_vel": numbers.rot_vel,
        "battery_pct" if soc else "battery_v": numbers.battery,
        "status": status,
        "mode": mode,
    }


def status_line(obj: dict[str, Any]) -> str:
    """The human line of one status: numbers as the operator's language writes them (the JSON object
    keeps plain numbers)."""
    from ..base.i18n import _
    from ..base.textsafe import visible
    from ..base.units import quantity

    soc = "battery_pct" in obj
    battery = quantity(obj["battery_pct"], "%") if soc else quantity(obj["battery_v"], "V", 1)
    return _("x={x}  y={y}  th={th}  vel={vel}  rot={rot}  battery={battery}  {status} ({mode})").format(
        x=quantity(obj["x"], "mm"),
        y=quantity(obj["y"], "mm"),
        th=quantity(obj["th"], "deg"),
        vel=quantity(obj["vel"], "mm/s"),
        rot=quantity(obj["rot_vel"], "deg/s"),
        battery=battery,
        status=visible(obj["status"]),
        mode=visible(obj["mode"]),
    )


async def battery_is_soc(client: AriaClient, timeout: float) -> bool:
    """True when ``batteryInfo`` says the battery figures are state of charge (percent)."""
    from ..protocol.payloads.robot import BatteryInfo

    if not client.supports("batteryInfo"):
        return False
    info = (await client.request_once("batteryInfo", timeout=timeout)).decode()
    return isinstance(info, BatteryInfo) and info.state_of_charge


async def fetch_status(client: AriaClient, timeout: float) -> dict[str, Any]:
    """One status from ``updateNumbers`` + ``updateStrings`` (or the old ``update``)."""
    from ..protocol.payloads.robot import Update, UpdateNumbers, UpdateStrings

    if client.supports("updateNumbers"):
        numbers = (await client.request_once("updateNumbers", timeout=timeout)).decode()
        assert isinstance(numbers, UpdateNumbers)
        status = mode = ""
        if client.supports("updateStrings"):
            strings = (await client.request_once("updateStrings", timeout=timeout)).decode()
            assert isinstance(strings, UpdateStrings)
            status, mode = strings.status, strings.mode
        return status_object(numbers, status, mode, soc=await battery_is_soc(client, timeout))
    if client.supports("update"):
        update = (await client.request_once("update", timeout=timeout)).decode()
        assert isinstance(update, Update)
        soc = await battery_is_soc(client, timeout)
        return status_object(update.numbers, update.status, update.mode, soc=soc)
    raise no_status(client)


def no_status(client: AriaClient) -> Exception:
    """Why there is no robot status: ARIA's central server has robots, not a status of its own."""
    from ..client.diagnosis import central_server_words
    from ..client.errors import NotSupported

    if client.supports("clientList"):
        return NotSupported("updateNumbers", central_server_words(f"{client.host}:{client.port}"))
    return NotSupported("updateNumbers", "this server offers no robot status (updateNumbers or update)")
