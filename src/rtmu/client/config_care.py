"""Configuration care for a client: factory values and what differs from them, reset, reload.

Shared by ``rtmu config`` and (later) the window's configuration page. ``getConfigDefaults`` is only
offered by a server started with a defaults file; without it nothing here pretends to know the
factory values (:class:`NotSupported` says so). A reset sends the factory values of one parameter
(``setConfigParam`` when the server has it) or of a whole section (one ``setConfig``): the server
checks them as it checks any value, and its own words are the answer. Values are compared by type —
ARIA prints doubles with six significant digits, so ``0.333333`` is the factory ``1/3``.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
from dataclasses import dataclass

from ..protocol.payloads.config import ConfigParam, ConfigUpdated, ParamType, SetConfigReply
from ..protocol.payloads.configcare import (
    CheckMap,
    ConfigDefaults,
    ConfigDefaultsRequest,
    ReloadConfig,
    SetConfigParam,
    SetConfigParamReply,
)
from .call_values import Packet
from .config_feed import MAX_PARAMS, MAX_TEXT, ServerConfig, set_config
from .connection import AriaClient
from .errors import ClientTimeout, MalformedReply, NotSupported

DEFAULTS = ConfigDefaultsRequest.DATA_NAME
RELATIVE_TOLERANCE = 1e-6
"""Doubles this close count as equal (ARIA's ``%g`` keeps six significant digits)."""


@dataclass(frozen=True, slots=True)
class FactoryValues:
    """``getConfigDefaults``: the factory value text of each parameter, by (section, name) in lower case."""

    values: dict[tuple[str, str], str]
    cut: int = 0
    """Pairs left out (more than :data:`MAX_PARAMS`, or longer than :data:`MAX_TEXT`)."""

    def get(self, section: str, name: str) -> str | None:
        return self.values.get((section.lower(), name.lower()))


@dataclass(frozen=True, slots=True)
class Difference:
    """A parameter whose value is not its factory value."""

    section: str
    name: str
    value: str
    default: str
    editable: bool


def offers_defaults(client: AriaClient) -> bool:
    return client.supports(DEFAULTS)


async def fetch_defaults(client: AriaClient, timeout: float, section: str = "") -> FactoryValues:
    """The factory values (of one section, or all); NotSupported when the server keeps none."""
    if not offers_defaults(client):
        raise NotSupported(
            DEFAULTS,
            "this server offers no factory values (getConfigDefaults: ARIA offers it only when started "
            "with a defaults file)",
        )
    answer = (await client.request_once(ConfigDefaultsRequest(section), timeout=timeout)).decode()
    if not isinstance(answer, ConfigDefaults):
        raise MalformedReply("getConfigDefaults did not answer with pairs of strings")
    values: dict[tuple[str, str], str] = {}
    cut = 0
    for sec, name, value in answer.by_section():
        if len(values) >= MAX_PARAMS or max(len(sec), len(name), len(value)) > MAX_TEXT:
            cut += 1
            continue
        values.setdefault((sec.lower(), name.lower()), value)
    return FactoryValues(values, cut)


def same_value(param: ConfigParam, text: str) -> bool:
    """Whether ``text`` (as ARIA writes a value) is the parameter's current value."""
    if param.kind is ParamType.BOOL:
        low = text.strip().lower()
        return (low in ("true", "1", "yes", "on")) == bool(param.value)
    if param.kind in (ParamType.INT, ParamType.DOUBLE):
        try:
            number = float(text)
        except ValueError:
            return False
        current = float(param.value or 0)
        if not (math.isfinite(number) and math.isfinite(current)):
            return number == current
        return math.isclose(number, current, rel_tol=RELATIVE_TOLERANCE, abs_tol=1e-9)
    return text == ("" if param.value is None else str(param.value))


def differences(config: ServerConfig, factory: FactoryValues) -> list[Difference]:
    """Every parameter with a factory value that it does not have, in the configuration's order."""
    out: list[Difference] = []
    for s in config.sections:
        for p in s.params:
            if p.kind in (ParamType.SEPARATOR, ParamType.LIST):
                continue
            default = factory.get(s.name, p.name)
            if default is not None and not same_value(p, default):
                out.append(Difference(s.name, p.name, p.value_text(), default, config.editable(p)))
    return out


def reset_targets(config: ServerConfig, factory: FactoryValues, target: str) -> dict[str, dict[str, str]]:
    """``{section: {parameter: factory value}}`` for ``SECTION/PARAM`` or a whole ``SECTION``.

    Only parameters whose value differs; a name the configuration or the factory values lack, or a
    read-only parameter that differs, raises ValueError saying which.
    """
    section_names = {s.name.lower(): s for s in config.sections}
    whole = section_names.get(target.strip().lower())
    if whole is not None:
        wanted = [
            (whole.name, p) for p in whole.params if p.kind not in (ParamType.SEPARATOR, ParamType.LIST)
        ]
    else:
        sec, slash, name = target.rpartition("/")
        if not slash:
            raise ValueError(f"no section {target!r} in the configuration (give SECTION or SECTION/PARAM)")
        found = config.find(sec.strip(), name.strip())
        if found is None:
            raise ValueError(f"no parameter {target!r} in the configuration")
        section = section_names[sec.strip().lower()]
        wanted = [(section.name, found)]
    changes: dict[str, dict[str, str]] = {}
    for sec, p in wanted:
        default = factory.get(sec, p.name)
        if default is None:
            if whole is None:
                raise ValueError(f"the server has no factory value for {sec}/{p.name}")
            continue
        if same_value(p, default):
            continue
        if not config.editable(p):
            raise ValueError(f"{sec}/{p.name} is read-only here and cannot be reset")
        changes.setdefault(sec, {})[p.name] = default
    return changes


async def reset(
    client: AriaClient, changes: dict[str, dict[str, str]], timeout: float
) -> SetConfigReply | SetConfigParamReply:
    """Send factory values: one parameter through ``setConfigParam`` when offered, else ``setConfig``."""
    single = len(changes) == 1 and sum(len(v) for v in changes.values()) == 1
    if single and client.supports(SetConfigParam.DATA_NAME):
        answer = (await client.request_once(SetConfigParam.of(changes), timeout=timeout)).decode()
        if not isinstance(answer, SetConfigParamReply):
            raise MalformedReply("setConfigParam did not answer with a section and an error string")
        return answer
    return await set_config(client, changes, timeout)


CLOSED_CHECK = 0.25
"""Seconds between looks at the connection while waiting for a broadcast."""


class Broadcasts:
    """Counts one broadcast (``configUpdated``, ``mapUpdated``) on a command's own connection."""

    def __init__(self, client: AriaClient, name: str) -> None:
        self.count = 0
        self._event = asyncio.Event()
        self._client = client
        self.name = name
        if client.supports(name):
            client.request(name, -1, self._on)

    def _on(self, packet: Packet) -> None:
        self.count += 1
        self._event.set()

    async def next(self, timeout: float) -> bool:
        """True once another one came within ``timeout`` s; False when none did. A connection that
        ends meanwhile raises its error: "none came" must not be said of a link that was lost."""
        start = self.count
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        while self.count == start:
            if self._client.closed_error is not None:
                raise self._client.closed_error
            left = deadline - loop.time()
            if left <= 0:
                return False
            self._event.clear()
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(min(left, CLOSED_CHECK)):
                    await self._event.wait()
        return True


async def reload_config(client: AriaClient, timeout: float) -> None:
    """``reloadConfig`` (no reply), then wait for its ``configUpdated``; ClientTimeout if none comes."""
    if not client.supports(ReloadConfig.DATA_NAME):
        raise NotSupported(ReloadConfig.DATA_NAME, "this server cannot be told to reload its configuration")
    updates = Broadcasts(client, ConfigUpdated.DATA_NAME)
    client.send(ReloadConfig())
    if client.supports(ConfigUpdated.DATA_NAME) and not await updates.next(timeout):
        raise ClientTimeout(f"reloadConfig was sent but no configUpdated came within {timeout:g} s")


async def check_map(client: AriaClient, timeout: float) -> bool:
    """``checkMap`` (no reply); True when ``mapUpdated`` came within ``timeout`` s (the file had changed)."""
    if not client.supports(CheckMap.DATA_NAME):
        raise NotSupported(CheckMap.DATA_NAME, "this server cannot be told to re-read its map (checkMap)")
    updates = Broadcasts(client, "mapUpdated")
    client.send(CheckMap())
    return await updates.next(timeout)


MAP_SECTION, MAP_PARAM = "Files", "Map"
"""Where ARIA's map handler (ARNL, ``ArServerHandlerMap``) keeps the map file it loads."""


def map_param_problem(config: ServerConfig) -> str:
    """Why this configuration cannot switch the robot's map ("" when its ``Files/Map`` can be set)."""
    param = config.find(MAP_SECTION, MAP_PARAM)
    if param is None:
        return (
            "this server's configuration has no Files/Map parameter (ARNL's map file), so it cannot be "
            "told to load another map"
        )
    if not config.editable(param):
        return "this server's Files/Map parameter is above the priority this user may edit"
    return ""
