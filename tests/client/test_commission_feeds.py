"""The commissioning intents end to end: runner, session, feeds and model against the simulator.

What the window asks for files, scans, configuration care and map changes goes the one way every
intent goes (``runner.send``), and comes back as typed state (``ScanChanged``, ``TransfersChanged``)
or as the feed's answer: a listing, a finished download (streamed, progress published), an upload,
a delete, a scan started / tagged / stopped (heard by a second client too), factory values and a
reset, a map switched, a goal added in one change set. The controller's guard refuses a goal while
scanning and still lets STOP out.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from rtmu.base.notices import Notice
from rtmu.client.download import LocalFileError
from rtmu.client.remote_files import Refused
from rtmu.client.runner import ClientRunner
from rtmu.control.controller import Controller
from rtmu.control.scan_rule import scan_refusal
from rtmu.mapedit import MapDraft
from rtmu.model.observables import (
    ConnectionState,
    LinkHealth,
    LinkLevel,
    MapPhase,
    OperatorState,
    Phase,
    RobotModel,
)
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.values.commission import ScanState
from rtmu.values.intents import (
    ApplyMapChanges,
    DeleteFile,
    DownloadFile,
    FetchConfigDefaults,
    GotoGoal,
    ListFiles,
    ResetConfig,
    SetConfig,
    StartScan,
    Stop,
    StopScan,
    SwitchMap,
    TagScanLoop,
    TurnBy,
    UploadFile,
)
from rtmu.values.state import StateChange, TransfersChanged
from rtmu.values.target import Target
from simulators import running

from .fakeclock import FakeClock
from .fakes import FakeView, RecordingLink
from .uiqueue import UiQueue


class Rig:
    def __init__(self, port: int) -> None:
        self.model, self.ui = RobotModel(), UiQueue()
        self.notices: list[Notice] = []
        self.published: list[StateChange] = []
        self.runner = ClientRunner(self.model, post=self.ui.post)
        self.runner.on_notice = self.notices.append
        self.runner.on_publish = self.published.append
        self.runner.start()
        self.runner.connect(Target("127.0.0.1", port, "", "", profile="t")).result(10)
        self.wait(lambda: self.model.connection.value.phase is Phase.CONNECTED)

    def wait(self, predicate: Any, timeout: float = 20.0) -> None:
        self.ui.wait_for(predicate, timeout)

    def ask(self, intent: Any, timeout: float = 30.0) -> Any:
        return self.runner.send(intent).result(timeout)


@pytest.fixture
def files(tmp_path: Path) -> Path:
    root = tmp_path / "robot"
    (root / "maps").mkdir(parents=True)
    (root / "big.bin").write_bytes(bytes(range(256)) * 8192)  # 2 MB: many chunks
    (root / "maps" / "Other.map").write_bytes(project_map("office.map").read_bytes())
    return root


@pytest.fixture
def sim(files: Path) -> Iterator[SimThread]:
    with running(files_dir=files, map_path=project_map("office.map")) as s:
        yield s


@pytest.fixture
def rig(sim: SimThread) -> Iterator[Rig]:
    r = Rig(sim.port)
    try:
        yield r
    finally:
        r.runner.close()


def test_list_download_upload_delete_through_intents(rig: Rig, files: Path, tmp_path: Path) -> None:
    listing = rig.ask(ListFiles(""))
    names = {e.name: e for e in listing.entries}
    assert names["maps"].is_folder and names["big.bin"].size == 2 * 1024 * 1024
    local = tmp_path / "big-copy.bin"
    done = rig.ask(DownloadFile("big.bin", str(local), size=names["big.bin"].size))
    assert done.size == 2 * 1024 * 1024 and local.read_bytes() == (files / "big.bin").read_bytes()
    transfers = [c.value for c in rig.published if isinstance(c, TransfersChanged)]
    assert any(t.active and t.active[0].remote == "big.bin" for t in transfers)
    assert not transfers[-1].active  # a finished transfer leaves
    rig.wait(lambda: not rig.model.transfers.value.active)

    # an existing local file is never overwritten unless asked
    local.write_bytes(b"mine")
    with pytest.raises(LocalFileError, match="already exists"):
        rig.ask(DownloadFile("big.bin", str(local)))
    assert local.read_bytes() == b"mine"

    rig.ask(UploadFile(str(local), "maps/mine.txt"))
    assert (files / "maps" / "mine.txt").read_bytes() == b"mine"
    rig.ask(DeleteFile("maps/mine.txt"))
    assert not (files / "maps" / "mine.txt").exists()
    with pytest.raises(Refused):
        rig.ask(DeleteFile("maps/never-there.txt"))


def test_scan_start_loop_stop_is_published_and_guards_motion(rig: Rig, sim: SimThread) -> None:
    rig.wait(lambda: rig.model.scan.value.offered)
    other = Rig(sim.port)  # a second client hears the scan through the broadcast
    try:
        file_name = rig.ask(StartScan("hall"))
        assert file_name.endswith(".2d")
        rig.wait(lambda: rig.model.scan.value.scanning)
        other.wait(lambda: other.model.scan.value.file_name == file_name)
        assert rig.model.scan.value.since is not None
        refusal = scan_refusal(GotoGoal("Goal1"), rig.model.scan.value)
        assert refusal is not None and "not while scanning" in refusal
        assert scan_refusal(Stop(), rig.model.scan.value) is None  # STOP never waits for a rule
        assert scan_refusal(StopScan(), rig.model.scan.value) is None
        rig.ask(TagScanLoop(start=True))
        rig.ask(TagScanLoop(start=False))
        rig.ask(StopScan())
        rig.wait(lambda: not rig.model.scan.value.scanning)
        assert rig.model.scan.value.last_file == file_name
        other.wait(lambda: not other.model.scan.value.scanning)
    finally:
        other.runner.close()
    assert scan_refusal(GotoGoal("Goal1"), ScanState()) is None


def test_factory_values_and_a_reset(rig: Rig) -> None:
    factory = rig.ask(FetchConfigDefaults())
    timeout = factory.get("Teleop", "Timeout")
    assert timeout is not None
    assert rig.ask(SetConfig({"Teleop": {"Timeout": "0.7"}})).accepted
    answer = rig.ask(ResetConfig({"Teleop": {"Timeout": timeout}}))
    assert not answer.error


def test_switch_map_to_a_file_on_the_robot_and_a_refused_one(rig: Rig) -> None:
    rig.wait(lambda: rig.model.map.value.state is MapPhase.READY)
    first = rig.model.map.value.generation
    assert rig.ask(SwitchMap("maps/Other.map")) is True
    rig.wait(lambda: rig.model.map.value.generation > first and rig.model.map.value.state is MapPhase.READY)
    with pytest.raises(Refused, match="did not take"):
        rig.ask(SwitchMap("maps/missing.map"))


def test_a_goal_added_in_one_change_set(rig: Rig) -> None:
    rig.wait(lambda: rig.model.map.value.state is MapPhase.READY)
    shown = rig.model.map.value
    assert shown.data is not None
    draft = MapDraft(shown.data.objects)
    draft.add_goal("Commissioned", 1000.0, 500.0, 90.0)
    change = draft.change()
    verdict = rig.ask(ApplyMapChanges(change.removed, change.added, shown.generation))
    assert verdict.applied, verdict
    rig.wait(lambda: "Commissioned" in rig.model.navigation.value.goals)


def test_the_controller_refuses_autonomous_motion_while_scanning_but_stop_and_held_drive_go() -> None:
    clock, model, view = FakeClock(), RobotModel(), FakeView()
    link = RecordingLink(clock)
    ctl = Controller(model, OperatorState(), link, view, clock=clock)
    offers = frozenset({"ratioDrive", "stop", "turnByAngle", "gotoGoal", "mappingStart", "mappingEnd"})
    model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272, offers=offers))
    model.health.set(LinkHealth(LinkLevel.OK))
    model.scan.set(ScanState(offered=True, name="hall", file_name="hall.2d", since=0.0))
    assert ctl.ask(GotoGoal("Goal1")) is None and ctl.ask(TurnBy(90)) is None
    assert not any(c[0] in ("goto_goal", "command") for c in link.calls)
    assert any("not while scanning for a map (hall.2d)" in text for _level, text in view.notices)
    ctl.press("forward")  # the operator's own hands still drive
    assert link.lease.view().live
    ctl.stop()
    assert ("stop",) in link.calls and not link.lease.view().live
    ctl.ask(StopScan())
    assert ("send", StopScan()) in link.calls
    model.scan.set(ScanState(offered=True, last_file="hall.2d"))
    ctl.ask(GotoGoal("Goal1"))
    assert ("goto_goal", "Goal1") in link.calls


def test_a_scan_running_before_login_is_told_as_such(sim: SimThread) -> None:
    first = Rig(sim.port)
    try:
        first.ask(StartScan("early"))
    finally:
        first.runner.close()
    late = Rig(sim.port)  # the subscription's first answer and the status answer both say it runs
    try:
        late.wait(lambda: late.model.scan.value.scanning)
        assert late.model.scan.value.file_name == "early.2d" and late.model.scan.value.since is None
        late.ask(StopScan())
        late.wait(lambda: late.model.scan.value.last_file == "early.2d")
    finally:
        late.runner.close()
