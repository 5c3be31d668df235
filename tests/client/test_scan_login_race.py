"""A scan's start heard by broadcast is not undone by an older answer to the login's question.

At login the scan feed subscribes to ``mappingStatusBroadcast`` and asks ``mappingStatus`` once. A
robot that starts scanning meanwhile (another client pressed Scan) broadcasts the scan right behind
its answer, and both can arrive in one read: the broadcast is handled as it is read, the answer's
waiting question only a turn of the loop later. A scripted server on loopback sends exactly that —
the answer "no scan" and, in the same write, the broadcast of the scan's file — and the feed must
end up showing the scan (the fresh-machine run CI52 saw a second client miss a scan for a minute).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rtmu.client.runner import ClientRunner
from rtmu.model.observables import Phase, RobotModel
from rtmu.protocol.payloads.mapping import MappingStatus, MappingStatusBroadcast
from rtmu.values.target import Target

from .servers import SPECS, ServerThread, TestServer, in_one_write
from .uiqueue import UiQueue

MAPPING_SPECS = [
    ("mappingStart", "start a scan", "string", "ubyte", "Mapping", "RETURN_SINGLE"),
    ("mappingEnd", "end the scan", "none", "ubyte", "Mapping", "RETURN_SINGLE"),
    ("mappingStatus", "the scan running", "none", "string", "Mapping", "RETURN_SINGLE"),
    ("mappingStatusBroadcast", "the scan running", "none", "string", "Mapping", "RETURN_SINGLE"),
]


ANSWER_THEN_BROADCAST = in_one_write(
    ("mappingStatus", MappingStatus("").encode()),  # "no scan" — and, written with it,
    ("mappingStatusBroadcast", MappingStatusBroadcast("hall.2d").encode()),  # a scan has just started
)


@pytest.fixture
def server() -> Iterator[TestServer]:
    srv = TestServer([*SPECS, *MAPPING_SPECS])
    srv.handlers["mappingStatus"] = ANSWER_THEN_BROADCAST
    srv.handlers["mappingStatusBroadcast"] = lambda side, args: []  # a subscription: no answer now
    with ServerThread(srv) as running:
        yield running


def test_an_older_login_answer_does_not_undo_a_scan_heard_since(server: TestServer) -> None:
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post)
    runner.start()
    try:
        runner.connect(Target("127.0.0.1", server.port, profile="t")).result(10)
        ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED, 10)
        ui.wait_for(lambda: any(r.name == "mappingStatus" for r in server.received), 10)
        runner.call(lambda: runner.session.client.request_once("getSafeDrive"))  # type: ignore[union-attr]
        ui.drain()
        assert model.scan.value.file_name == "hall.2d", f"the scan was lost: {model.scan.value}"
        assert model.scan.value.scanning
    finally:
        runner.close()
