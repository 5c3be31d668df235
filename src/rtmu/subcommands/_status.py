"""One robot status as ``rtmu status``, ``rtmu drive`` and ``rtmu fleet`` print it: its JSON object and its
line. The status itself is the client's :class:`~rtmu.values.state.RobotState`, read from the payloads by
:mod:`rtmu.client.robot_status` as the window reads it; this module only formats it."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..client.connection import AriaClient
    from ..values.state import RobotState


STATUS_KEYS = ("x", "y", "th", "vel", "rot_vel", "battery_v", "status", "mode")
"""The documented keys of a status object: mm, mm, degrees, mm/s, deg/s, volts, text, text. A robot
that reports state of charge gives ``battery_pct`` (percent) in place of ``battery_v``."""


def _whole(value: float) -> float | int:
    """The wire's whole numbers stay whole in the JSON and the line (``x=1200 mm``, not ``1200.0``)."""
    return int(value) if float(value).is_integer() else value


def status_object(robot: RobotState) -> dict[str, Any]:
    """One status as the JSON object ``rtmu status`` and ``rtmu drive`` print (``battery_pct`` in place
    of ``battery_v`` when the server's ``batteryInfo`` says the figure is a state of charge)."""
    return {
        "x": _whole(robot.x),
        "y": _whole(robot.y),
        "th": _whole(robot.th),
        "vel": _whole(robot.vel),
        "rot_vel": _whole(robot.rot_vel),
        "battery_pct" if robot.battery_is_soc else "battery_v": robot.battery_v,
        "status": robot.status,
        "mode": robot.mode,
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


async def fetch_status(client: AriaClient, timeout: float) -> dict[str, Any]:
    """One status, asked for at once (:func:`rtmu.client.robot_status.fetch_robot_state`), as its object."""
    from ..client.robot_status import fetch_robot_state

    return status_object(await fetch_robot_state(client, timeout))
