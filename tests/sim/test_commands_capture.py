"""The server's own commands as a real ARIA server lists them (serverDemo's captured data list).

No capture holds a ``listCommands`` reply or a popup, so these tests hold the client and the
simulator to what the captured data list does show: commands are data of group CustomCommands with
no reply, a string command's argument is described as ``string: argumentToCommand``, and a listed
command is offered only where the data list (filtered per user by ARIA) names it.
"""

from __future__ import annotations

import asyncio
from types import SimpleNamespace
from typing import Any

from rtmu.client.custom_commands import list_commands, offers_commands
from rtmu.protocol.payloads.commands import CommandEntry, CommandList, StringCommandList
from rtmu.sim.catalogue import STRING_COMMANDS, custom_commands
from testdata import CAPTURES

from .wire import captured_datalist

CAPTURE = CAPTURES / "clientCommandLister-serverDemoMap.pcap"
STRING_ARG = "string: argumentToCommand"


def captured_commands() -> dict[str, Any]:
    return {e.name: e for e in captured_datalist(CAPTURE) if e.command_group == "CustomCommands"}


def test_captured_commands_are_custom_commands_with_no_reply_and_string_ones_say_so() -> None:
    found = captured_commands()
    assert found["listCommands"].flags == found["listStringCommands"].flags == "RETURN_SINGLE"
    commands = {n: e for n, e in found.items() if not n.startswith("list")}
    assert len(commands) == 27 and all(e.flags == "RETURN_NONE" for e in commands.values())
    strings = {n for n, e in commands.items() if e.argument_description == STRING_ARG}
    assert strings == {"MicroControllerCommand", "MicroControllerMotionCommand"}
    assert all(e.argument_description == "none" for n, e in commands.items() if n not in strings)


def test_the_simulator_describes_its_commands_as_aria_does() -> None:
    captured = captured_commands()
    for name, _description, args, _returns, group, flags in custom_commands(camera=True):
        assert flags == "RETURN_NONE", name
        assert args == (STRING_ARG if name in STRING_COMMANDS else "none"), name
        if name in captured:  # serverDemo's own commands: the same group and argument as captured
            assert (group, args) == (captured[name].command_group, captured[name].argument_description)


def test_the_client_offers_only_what_the_captured_data_list_names() -> None:
    datalist = captured_datalist(CAPTURE)
    names = {e.name for e in datalist}
    simple = [CommandEntry(n, "") for n in ("LogActions", "GyroDisable", "NotOnThisServer")]
    strings = [CommandEntry("MicroControllerCommand", "com: <command>\ncomInt: <command> <int>")]
    replies = {
        "listCommands": CommandList(tuple(simple)).encode(),
        "listStringCommands": StringCommandList(tuple(strings)).encode(),
    }

    async def request_once(name: str, timeout: float) -> Any:
        return SimpleNamespace(payload=replies[name])

    client = SimpleNamespace(supports=names.__contains__, request_once=request_once)
    assert offers_commands(client)  # type: ignore[arg-type]
    catalogue = asyncio.run(list_commands(client))  # type: ignore[arg-type]
    assert [(c.name, c.takes_argument) for c in catalogue.commands] == [
        ("LogActions", False), ("GyroDisable", False), ("MicroControllerCommand", True),
    ]  # fmt: skip
    assert catalogue.hidden == 1
    assert "popupCreate" not in names  # serverDemo has no popup handler: the window shows no cards
