"""Server popups and the server's own commands end to end: runner, session and model over loopback.

Against the real-time simulator: a popup arrives as typed state (title, message, buttons as sent),
an answer reaches the simulator as popupClicked and the server's popupClose removes it with a
Kind.SERVER notice, a timeout closes it, a reconnect restores the open ones (popupList), and a
flood stays bounded and costs the UI thread a handful of updates. Commands: listed with their
descriptions, only those the user may run, run with and without an argument.
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from rtmu.base.notices import Kind, Notice
from rtmu.client.custom_commands import MAX_ARGUMENT, CustomCommand, list_commands
from rtmu.client.popups import MAX_MESSAGE, MAX_OPEN
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import Phase, RobotModel
from rtmu.protocol.payloads.commands import CommandEntry, CommandList
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import AnswerPopup, ListServerCommands, RunServerCommand
from rtmu.values.state import PopupsChanged, StateChange
from rtmu.values.target import Target
from simulators import simulator

from .uiqueue import UiQueue, eventually

USERS = "UserInfoVersion1\nuser alice secret1 all\nuser bob pw2 RobotInfo Movement Stop CustomCommands\n"


class Rig:
    def __init__(self, port: int, user: str = "", password: str = "") -> None:
        self.model, self.ui = RobotModel(), UiQueue()
        self.notices: list[Notice] = []
        self.published: list[StateChange] = []
        self.runner = ClientRunner(self.model, post=self.ui.post)
        self.runner.on_notice = self.notices.append
        self.runner.on_publish = self.published.append
        self.runner.start()
        self.port, self.user, self.password = port, user, password
        self.connect()

    def connect(self) -> None:
        self.runner.connect(Target("127.0.0.1", self.port, self.user, self.password, profile="t")).result(10)
        self.wait(lambda: self.model.connection.value.phase is Phase.CONNECTED)

    def wait(self, predicate: Any, timeout: float = 10.0) -> None:
        self.ui.wait_for(predicate, timeout)

    @property
    def popups(self) -> Any:
        return self.model.popups.value

    def server_texts(self) -> list[str]:
        return [n.text for n in self.notices if n.kind is Kind.SERVER]


sim = simulator(scope="module")


@pytest.fixture
def rig(sim: SimThread) -> Iterator[Rig]:
    sim.call(lambda: sim.server.world.popups.clear())
    r = Rig(sim.port)
    try:
        yield r
    finally:
        r.runner.close()


def raise_popup(sim: SimThread, **kw: Any) -> int:
    kw.setdefault("buttons", ("Yes", "No", "Later"))
    popup = sim.call(lambda: sim.server.world.create_popup(kw.pop("title"), kw.pop("message"), **kw))
    return int(popup.id)


def test_popup_arrives_is_answered_and_closes_with_the_servers_words(sim: SimThread, rig: Rig) -> None:
    pid = raise_popup(sim, title="Dock <b>now</b>?", message="A & B", kind=4, default_button=1)
    rig.wait(lambda: any(p.popup_id == pid for p in rig.popups.open))
    (card,) = [p for p in rig.popups.open if p.popup_id == pid]
    assert (card.title, card.message, card.icon) == ("Dock <b>now</b>?", "A & B", 4)  # as sent, not parsed
    assert card.buttons == ("Yes", "No", "Later") and card.default_button == 1
    assert rig.popups.offered

    rig.runner.send(AnswerPopup(pid, 2)).result(5)
    eventually(lambda: (pid, 2) in sim.call(lambda: list(sim.server.world.popup_clicks)), timeout=5)
    rig.wait(lambda: all(p.popup_id != pid for p in rig.popups.open))
    rig.wait(lambda: any("Later pressed" in t for t in rig.server_texts()))


def test_server_closes_a_popup_on_timeout_with_its_timeout_text(sim: SimThread, rig: Rig) -> None:
    pid = raise_popup(sim, title="Short", message="gone soon", timeout=0.5, timeout_text="Nobody answered")
    rig.wait(lambda: any(p.popup_id == pid for p in rig.popups.open))
    rig.wait(lambda: not any(p.popup_id == pid for p in rig.popups.open), timeout=5)
    rig.wait(lambda: "Short: Nobody answered" in rig.server_texts())


def test_a_reconnect_restores_the_open_popups_from_popup_list(sim: SimThread, rig: Rig) -> None:
    pid = raise_popup(sim, title="Still open", message="after a reconnect")
    rig.wait(lambda: any(p.popup_id == pid for p in rig.popups.open))
    rig.runner.disconnect().result(5)
    rig.wait(lambda: not rig.popups.open)
    rig.connect()
    rig.wait(lambda: [p.title for p in rig.popups.open] == ["Still open"])


def test_a_flood_is_bounded_and_coalesced(sim: SimThread, rig: Rig) -> None:
    sim.call(lambda: sim.server.world.flood_popups(1000, 2.0))
    rig.wait(lambda: rig.popups.dropped > 0, timeout=10)
    assert len(rig.popups.open) <= MAX_OPEN
    eventually(lambda: sim.call(lambda: sim.server.world.popup_flood) is None, timeout=10)
    made = sim.call(lambda: sim.server.world._next_popup_id)
    changes = sum(isinstance(c, PopupsChanged) for c in rig.published)
    assert made > 1500
    assert changes < made / 3, f"{changes} updates for {made} popups: not coalesced"
    # The flood closes itself (2 s timeouts): nothing open, nothing counted as dropped any more.
    rig.wait(lambda: not rig.popups.open and rig.popups.dropped == 0, timeout=10)


def test_long_server_text_is_cut() -> None:
    from rtmu.client.popups import popup_info
    from rtmu.protocol.payloads.popup import PopupCreate

    info = popup_info(PopupCreate(1, "", "t" * 10_000, "m" * 100_000, 9, ("x" * 500, "", "")), 0.0)
    assert len(info.message) == MAX_MESSAGE and info.message.endswith("…")
    assert info.icon == 0 and len(info.buttons[0]) <= 40


# -- commands -------------------------------------------------------------------------------------


def test_commands_are_listed_with_descriptions_and_run(sim: SimThread, rig: Rig) -> None:
    catalogue = rig.runner.send(ListServerCommands()).result(10)
    by_name = {c.name: c for c in catalogue.commands}
    assert not by_name["ResetTripOdometer"].takes_argument
    assert by_name["SimulatorSetBattery"].takes_argument
    assert "battery" in by_name["SimulatorSetBattery"].description
    assert (
        rig.runner.send(
            RunServerCommand(
                by_name["SimulatorSetBattery"].name, "11.5", by_name["SimulatorSetBattery"].takes_argument
            )
        ).result(10)
        is True
    )
    assert sim.call(lambda: sim.server.world.body.battery_v) == pytest.approx(11.5)
    sim.call(lambda: setattr(sim.server.world.body, "odometer_mm", 5000.0))
    assert (
        rig.runner.send(
            RunServerCommand(
                by_name["ResetTripOdometer"].name, None, by_name["ResetTripOdometer"].takes_argument
            )
        ).result(10)
        is True
    )
    assert sim.call(lambda: sim.server.world.body.odometer_mm) < 100


def test_a_string_command_raises_a_popup(sim: SimThread, rig: Rig) -> None:
    cmd = CustomCommand("SimulatorPopup", "", True)
    rig.runner.send(RunServerCommand(cmd.name, "Asked|by a command|Go,Stay|0", cmd.takes_argument)).result(10)
    rig.wait(lambda: any(p.title == "Asked" for p in rig.popups.open))
    (card,) = [p for p in rig.popups.open if p.title == "Asked"]
    assert card.buttons == ("Go", "Stay", "")


def test_an_over_long_argument_is_refused_before_sending(rig: Rig) -> None:
    cmd = CustomCommand("SimulatorPopup", "", True)
    with pytest.raises(ValueError):
        rig.runner.send(RunServerCommand(cmd.name, "x" * (MAX_ARGUMENT + 1), True)).result(10)


def test_commands_a_user_may_not_run_are_not_listed(tmp_path: Path) -> None:
    users = tmp_path / "users.txt"
    users.write_text(USERS)
    with SimThread(SimConfig(port=0, users_path=users)) as sim:
        alice = Rig(sim.port, "alice", "secret1")
        bob = Rig(sim.port, "bob", "pw2")
        try:
            everything = {c.name for c in alice.runner.send(ListServerCommands()).result(10).commands}
            limited = {c.name for c in bob.runner.send(ListServerCommands()).result(10).commands}
        finally:
            alice.runner.close()
            bob.runner.close()
    assert "safeRatioDrivingDisable" in everything  # group UnsafeMovement
    assert "safeRatioDrivingDisable" not in limited
    assert "SimulatorSetBattery" in limited


def test_the_client_hides_listed_commands_missing_from_the_users_data_list() -> None:
    """ARIA's own lists name every command; only the data list is filtered by the user's groups."""
    listed = CommandList((CommandEntry("LogActions", "logs"), CommandEntry("GyroDisable", "no gyro")))

    async def request_once(name: str, timeout: float) -> Any:
        return SimpleNamespace(payload=listed.encode() if name == "listCommands" else b"\0\0")

    offered = {"listCommands", "LogActions"}
    client = SimpleNamespace(supports=offered.__contains__, request_once=request_once)
    catalogue = asyncio.run(list_commands(client))  # type: ignore[arg-type]
    assert [c.name for c in catalogue.commands] == ["LogActions"]
    assert catalogue.hidden == 1
