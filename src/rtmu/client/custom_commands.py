"""The server's own commands (protocol §4.10): list them, run one, and learn that the server took it.

``listCommands`` / ``listStringCommands`` name commands that are themselves data names; ARIA's
lists name every command the server has, while its data list shows a user only what their groups
allow, so a command is offered here only when it is in both. Running one is a request-once with
no reply (a string command carries one string argument). Because ARIA handles a client's packets
in order, a reply to a cheap request sent right after proves the server has taken the command —
that, or its silence, is all a client can report. Everything here is bounded: at most
:data:`MAX_COMMANDS` entries, names and descriptions cut, arguments at most :data:`MAX_ARGUMENT`.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
from typing import Any, ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.commands import CommandList, StringCommandArgs
from ..values.intents import Intent, ListServerCommands, RunServerCommand
from .connection import AriaClient
from .errors import ClientTimeout, NotSupported, ProtocolFault
from .feed import Feed
from .health import ping_data

LIST_SOURCES: tuple[tuple[str, bool], ...] = (
    ("listCommands", False),
    ("listStringCommands", True),
    ("customListCommands", False),
    ("customListStringCommands", True),
)
"""(list data, its commands take an argument): ARIA's two lists, and "custom" lists where a server
adds them (same layout)."""
MAX_COMMANDS = 500
MAX_NAME = 128
MAX_DESCRIPTION = 1000
MAX_ARGUMENT = 1000
"""ARIA copies a string command's argument into a 1024-byte buffer."""


@dataclass(frozen=True, slots=True)
class CustomCommand:
    name: str
    """Its data name: what is sent to run it."""
    description: str
    takes_argument: bool


@dataclass(frozen=True, slots=True)
class CommandCatalogue:
    commands: tuple[CustomCommand, ...] = ()
    hidden: int = 0
    """Listed by the server but not offered to this user (its groups), so not shown."""
    cut: int = 0
    """Beyond :data:`MAX_COMMANDS`: not shown."""

    def find(self, name: str) -> CustomCommand | None:
        return next((c for c in self.commands if c.name == name), None)


def offers_commands(client: AriaClient) -> bool:
    return any(client.supports(name) for name, _ in LIST_SOURCES)


async def list_commands(client: AriaClient, timeout: float = 5.0) -> CommandCatalogue:
    """Every command this user may run, from each list the server offers; NotSupported if none."""
    sources = [(name, arg) for name, arg in LIST_SOURCES if client.supports(name)]
    if not sources:
        raise NotSupported("listCommands", "this server offers no command list (listCommands)")
    found: dict[str, CustomCommand] = {}
    hidden = cut = 0
    for name, takes_argument in sources:
        reply = await client.request_once(name, timeout=timeout)
        try:
            listed = CommandList.decode(reply.payload)
        except ProtocolError as exc:
            raise ProtocolFault(f"the server's {name} reply is malformed: {exc}") from None
        for entry in listed.commands:
            if entry.name in found:
                continue
            if not entry.name or len(entry.name) > MAX_NAME or not client.supports(entry.name):
                hidden += 1
            elif len(found) >= MAX_COMMANDS:
                cut += 1
            else:
                description = entry.description
                if len(description) > MAX_DESCRIPTION:
                    description = description[: MAX_DESCRIPTION - 1] + "…"
                found[entry.name] = CustomCommand(entry.name, description, takes_argument)
    return CommandCatalogue(tuple(found.values()), hidden, cut)


def send_command(client: AriaClient, command: CustomCommand, argument: str | None = None) -> None:
    """Send it once (no reply comes); NotSupported when this user's data list lacks it."""
    if not client.supports(command.name):
        raise NotSupported(command.name)
    if command.takes_argument:
        text = argument or ""
        if len(text) > MAX_ARGUMENT:
            raise ValueError(f"the argument is longer than {MAX_ARGUMENT} characters")
        client.send(command.name, StringCommandArgs(text))
    else:
        client.send(command.name)


async def taken(client: AriaClient, timeout: float = 5.0) -> bool:
    """True once the server has answered a request sent after the command (so it has handled it);
    False when it stays silent for ``timeout`` s or offers nothing to ask."""
    name = ping_data(client.datalist)
    if name is None:
        await client.flush(timeout)
        return False
    with contextlib.suppress(ClientTimeout):
        await client.request_once(name, timeout=timeout)
        return True
    return False


async def run_command(
    client: AriaClient, command: CustomCommand, argument: str | None = None, timeout: float = 5.0
) -> bool:
    """:func:`send_command`, then :func:`taken`: did the server take it within ``timeout`` s?"""
    send_command(client, command, argument)
    return await taken(client, timeout)


class CommandsFeed(Feed):
    """The session's share: list the commands, run one (a command may drive: the guard ends a held
    drive first, as for every intent that moves the robot)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (ListServerCommands, RunServerCommand)

    def handle(self, intent: Intent) -> Any:
        client = self.require()
        timeout = self.ctx.config.reply_timeout
        if isinstance(intent, RunServerCommand):
            command = CustomCommand(intent.name, "", intent.string)
            return run_command(client, command, intent.argument, timeout)
        return list_commands(client, timeout)
