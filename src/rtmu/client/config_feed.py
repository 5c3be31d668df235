"""The server's configuration (ArConfig) for a client: fetch it, change values, follow others' changes.

Shared by ``rtmu config`` and the window's configuration page (through the session). Which
configuration API a robot has is told plainly (:func:`config_api`): ARIA's ArConfig, Omron LD's
``getConfigValues`` family (protocol 6MTX robots list it instead of ArConfig's; its layouts are not
public, so RTMU cannot show or edit it yet — :class:`ForeignConfig` says so, and ``rtmu call`` reads
it raw), or none. Of ArConfig, the newest ``getConfigBySections*`` the server lists is asked for; its
packets are joined into sections (a big section comes in parts). Everything is bounded: at most
:data:`MAX_PARAMS` parameters and :data:`MAX_SECTIONS` sections are kept, texts are cut, and the
reply itself is bounded in packets and bytes by the connection.

:class:`ConfigFeed` counts ``configUpdated`` broadcasts (another client changed something) and
tells a listener, so a page can fetch again without losing its own unsaved edits.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Container, Iterable
from dataclasses import dataclass, replace
from enum import Enum
from typing import Any, ClassVar

from ..base.exit_codes import EXIT_FOREIGN_CONFIG
from ..base.i18n import N_, Said
from ..protocol.errors import ProtocolError
from ..protocol.payloads.base import Side, payload_type_for
from ..protocol.payloads.config import (
    ConfigParam,
    ConfigRequest,
    ConfigSectionPacket,
    LastEditablePriority,
    ParamType,
    Priority,
    SetConfig,
    SetConfigReply,
)
from ..values.intents import FetchConfig, Intent
from ..values.intents import SetConfig as SetConfigIntent
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError, MalformedReply, NotSupported
from .feed import Feed, FeedContext
from .subscriptions import Subscription

VERSIONS = ("getConfigBySectionsV4", "getConfigBySectionsV3", "getConfigBySectionsV2", "getConfigBySections")
"""Newest first: the first the server lists is used."""
MAX_PARAMS = 100_000
MAX_SECTIONS = 10_000
MAX_TEXT = 2_000
"""Names, descriptions and values longer than this are cut (ARIA's own buffers are 1–32 KB)."""
MAX_REPLY_BYTES = 32 << 20
MAX_REPLY_PACKETS = 20_000


@dataclass(frozen=True, slots=True)
class ConfigSection:
    name: str
    comment: str
    params: tuple[ConfigParam, ...]
    category: str = ""


@dataclass(frozen=True, slots=True)
class ServerConfig:
    """A whole configuration as fetched, with the last priority the server lets a user edit."""

    sections: tuple[ConfigSection, ...] = ()
    last_editable: int = Priority.EXPERT
    source: str = ""
    """The data it came from (``getConfigBySectionsV4`` …)."""
    cut: int = 0
    """Parameters left out because the configuration was larger than :data:`MAX_PARAMS`."""

    def find(self, section: str, name: str) -> ConfigParam | None:
        """A parameter by section and name (case-insensitive, as ARIA compares them)."""
        for s in self.sections:
            if s.name.lower() == section.lower():
                for p in s.params:
                    if p.name.lower() == name.lower():
                        return p
        return None

    @property
    def param_count(self) -> int:
        """The parameters (a separator between them is none)."""
        return sum(1 for s in self.sections for p in s.params if p.kind is not ParamType.SEPARATOR)

    def editable(self, param: ConfigParam) -> bool:
        return param.priority <= self.last_editable


def _cut(text: str) -> str:
    return text if len(text) <= MAX_TEXT else text[: MAX_TEXT - 1] + "…"


def _bounded(p: ConfigParam) -> ConfigParam:
    fits = max(len(p.name), len(p.description), len(p.display_hint), len(p.extra)) <= MAX_TEXT
    if fits and not p.children and not (isinstance(p.value, str) and len(p.value) > MAX_TEXT):
        return p  # the common case: nothing to cut, no copy
    value = _cut(p.value) if isinstance(p.value, str) else p.value
    children = tuple(_bounded(c) for c in p.children[:1000])
    return replace(
        p,
        name=_cut(p.name),
        description=_cut(p.description),
        value=value,
        display_hint=_cut(p.display_hint),
        extra=_cut(p.extra),
        children=children,
    )


def offers_config(client: AriaClient) -> str | None:
    """The config data this server lists (newest first), or None."""
    return next((name for name in VERSIONS if client.supports(name)), None)


class ConfigApi(Enum):
    """Which configuration a robot offers, in the words an operator reads."""

    ARCONFIG = "ARIA's ArConfig"
    OMRON_LD = "Omron LD's"
    NONE = "none"


LD_CONFIG_DATA = ("getConfigValues", "setConfigValues", "updateConfigValues", "configExpandedSectionList")
"""What LD robots with protocol 6MTX list for their configuration (and no ``getConfigBySections*``)."""


def config_api(listed: Container[str]) -> ConfigApi:
    """The configuration API of a server whose data list is ``listed`` (ArConfig wins where both are)."""
    if any(name in listed for name in (*VERSIONS, SetConfig.DATA_NAME)):
        return ConfigApi.ARCONFIG
    if any(name in listed for name in LD_CONFIG_DATA):
        return ConfigApi.OMRON_LD
    return ConfigApi.NONE


class ForeignConfig(ClientError):
    """The robot's configuration is one RTMU cannot show or edit yet (an LD robot's); nothing was sent."""

    exit_code = EXIT_FOREIGN_CONFIG
    kind = "unsupported"

    def __init__(self, api: ConfigApi, listed: tuple[str, ...]) -> None:
        self.api = api
        self.listed = listed
        first = listed[0] if listed else "getConfigValues"
        super().__init__(
            Said(
                N_(
                    "this robot's configuration is {api} ({listed}), whose layouts are not public: RTMU "
                    "cannot show or edit it yet (rtmu call HOST {first} shows the robot's raw reply)"
                ),
                api=api.value,
                listed=", ".join(listed),
                first=first,
            )
        )


def foreign_config(client: AriaClient) -> ForeignConfig | None:
    """The :class:`ForeignConfig` to raise for this server, or None when its configuration is ArConfig
    or it has none."""
    if config_api(client.datalist) is not ConfigApi.OMRON_LD:
        return None
    return ForeignConfig(ConfigApi.OMRON_LD, tuple(n for n in LD_CONFIG_DATA if client.supports(n)))


def assemble(packets: list[ConfigSectionPacket], last_editable: int, source: str) -> ServerConfig:
    """Join section packets (parts of one section follow each other) into bounded sections."""
    sections: list[ConfigSection] = []
    kept, dropped = 0, 0
    for packet in packets:
        if packet.end:
            continue
        room = max(0, MAX_PARAMS - kept)
        params = tuple(_bounded(p) for p in packet.params[:room])
        dropped += len(packet.params) - len(params)
        kept += len(params)
        if sections and packet.index > 1 and sections[-1].name == packet.name:
            last = sections[-1]
            sections[-1] = replace(last, params=last.params + params)
        elif len(sections) < MAX_SECTIONS:
            sections.append(
                ConfigSection(_cut(packet.name), _cut(packet.comment), params, _cut(packet.category))
            )
        else:
            dropped += len(params)
    return ServerConfig(tuple(sections), last_editable, source, dropped)


async def fetch_config(client: AriaClient, timeout: float) -> ServerConfig:
    """The whole configuration; ForeignConfig for an LD robot's, NotSupported when the server offers none."""
    name = offers_config(client)
    if name is None:
        foreign = foreign_config(client)
        if foreign is not None:
            raise foreign
        raise NotSupported(
            "getConfigBySectionsV4", "this server offers no configuration (getConfigBySections)"
        )
    last_editable = int(Priority.EXPERT)
    if client.supports(LastEditablePriority.DATA_NAME):
        answer = (await client.request_once(LastEditablePriority.DATA_NAME, timeout=timeout)).decode()
        if isinstance(answer, LastEditablePriority):
            last_editable = int(Priority.of(answer.priority))
    what: str | ConfigRequest = (
        ConfigRequest(Priority.FACTORY, last_editable) if name == VERSIONS[0] else name
    )
    reply = await client.request_once(
        what, timeout=timeout, max_packets=MAX_REPLY_PACKETS, max_bytes=MAX_REPLY_BYTES
    )
    # Thousands of parameters take a tenth of a second or more: not on the network loop.
    return await asyncio.get_running_loop().run_in_executor(
        None, decode_config, name, reply.payloads, last_editable
    )


def decode_config(name: str, payloads: tuple[bytes, ...], last_editable: int) -> ServerConfig:
    """A ``getConfigBySections*`` reply's payloads as one bounded configuration (MalformedReply if bad)."""
    cls = payload_type_for(name, Side.REPLY)
    assert cls is not None and issubclass(cls, ConfigSectionPacket)
    try:
        packets = [cls.decode(p) for p in payloads]
    except ProtocolError as exc:
        raise MalformedReply(f"{name} did not decode: {exc}") from None
    return assemble(packets, last_editable, name)


async def set_config(
    client: AriaClient, changes: dict[str, dict[str, str]], timeout: float
) -> SetConfigReply:
    """Send ``{section: {parameter: value text}}`` in one ``setConfig``; the server's answer."""
    if not client.supports(SetConfig.DATA_NAME):
        foreign = foreign_config(client)
        if foreign is not None:
            raise foreign
        raise NotSupported(
            SetConfig.DATA_NAME, "this server does not let its configuration be changed (setConfig)"
        )
    answer = (await client.request_once(SetConfig.of(changes), timeout=timeout)).decode()
    if not isinstance(answer, SetConfigReply):
        raise MalformedReply("setConfig did not answer with a string")
    return replace(answer, error=_cut(answer.error))


class ConfigFeed(Feed):
    """Fetches and changes the configuration; ``configUpdated`` broadcasts are counted and passed to a
    listener (network loop)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (FetchConfig, SetConfigIntent)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.updates = 0
        self.listener: Callable[[], None] | None = None
        """Called on the network loop after each broadcast (the runner posts it to the UI thread)."""

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        return (Subscription("configUpdated", -1, self.on_updated),)

    def handle(self, intent: Intent) -> Any:
        client = self.require()
        timeout = self.ctx.config.reply_timeout
        if isinstance(intent, SetConfigIntent):
            changes = {section: dict(values) for section, values in intent.changes.items()}
            return set_config(client, changes, timeout)
        return fetch_config(client, timeout)

    def on_updated(self, packet: Packet) -> None:
        self.updates += 1
        listener = self.listener
        if listener is not None:
            listener()


def check_value(param: ConfigParam, text: str) -> str:
    """Why ``text`` cannot be this parameter's value ("" when it can), judged by its type and limits.

    The server has the last word (it may refuse for reasons of its own); this only lets a page
    say at once what is certainly wrong.
    """
    raw = text.strip()
    if param.kind is ParamType.BOOL:
        return (
            ""
            if raw.lower() in ("true", "false", "1", "0", "yes", "no", "on", "off")
            else "not true or false"
        )
    if param.kind in (ParamType.INT, ParamType.DOUBLE):
        try:
            number = int(raw) if param.kind is ParamType.INT else float(raw)
        except ValueError:
            return "not a whole number" if param.kind is ParamType.INT else "not a number"
        if number != number:
            return "not a number"
        if param.minimum is not None and number < param.minimum:
            return f"below the minimum of {param.minimum:g}"
        if param.maximum is not None and number > param.maximum:
            return f"above the maximum of {param.maximum:g}"
        return ""
    if param.kind is ParamType.STRING:
        if param.choices and raw not in param.choices:
            return "not one of " + ", ".join(param.choices)
        return "" if len(text) <= MAX_TEXT else f"longer than {MAX_TEXT} characters"
    return "cannot be changed here"


def changed_values(old: ServerConfig, new: ServerConfig) -> list[tuple[str, str, str]]:
    """``(section, name, new value text)`` of every parameter whose value differs (or is new)."""
    before = {(s.name, p.name): p.value for s in old.sections for p in s.params}
    out: list[tuple[str, str, str]] = []
    for s in new.sections:
        for p in s.params:
            if p.kind is not ParamType.SEPARATOR and before.get((s.name, p.name), object()) != p.value:
                out.append((s.name, p.name, p.value_text()))
    return out


def names_param(error: str, section: str, name: str) -> bool:
    """Whether a ``setConfig`` answer is about this parameter (ARIA-style ``Section/Name: why``)."""
    return error.lower().startswith(f"{section}/{name}:".lower())
