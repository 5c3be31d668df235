"""The server's status strings end to end: runner, session, ``client.server_strings`` and the model.

A server whose strings feed no Wi-Fi gauge is asked for ``getStrings`` only while the details
table watches (the server sees the REQUEST on opening and the REQUESTSTOP on closing). The
simulator's strings arrive labelled, and its Wi-Fi items keep the gauges fed whether or not the
table is open. Hostile lists — 10 000 items, 20 000-character labels, markup, values without labels,
a label list that changes — stay bounded and never stop the session.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from rtmu.client.runner import ClientRunner
from rtmu.client.server_strings import INTERVAL_MS, MAX_ITEMS, MAX_TEXT
from rtmu.model.observables import Phase, RobotModel
from rtmu.package_data import project_map
from rtmu.protocol.payloads.strings import StringItem, Strings, StringsInfo
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.handlers import STRING_ITEMS
from rtmu.values.intents import WatchStrings
from rtmu.values.target import Target

from .servers import SPECS, ServerThread, TestServer
from .uiqueue import UiQueue

OFFICE = project_map("office.map")
STRING_SPECS = [
    ("getStringsInfo", "labels", "none", "labels", "NavigationInfo", "RETURN_SINGLE"),
    ("getStrings", "values", "none", "strings", "NavigationInfo", "RETURN_SINGLE"),
]


class Rig:
    def __init__(self, port: int) -> None:
        self.model, self.ui = RobotModel(), UiQueue()
        self.runner = ClientRunner(self.model, post=self.ui.post)
        self.runner.start()
        self.runner.connect(Target("127.0.0.1", port, "", "", profile="t")).result(10)
        self.wait(lambda: self.model.connection.value.phase is Phase.CONNECTED)

    def wait(self, predicate: Any, timeout: float = 10.0) -> None:
        self.ui.wait_for(predicate, timeout)

    @property
    def robot(self) -> Any:
        return self.model.robot.value

    def settle(self) -> None:
        self.runner.sync()
        self.ui.drain()


@pytest.fixture
def rig_on() -> Iterator[Any]:
    rigs: list[Rig] = []

    def make(port: int) -> Rig:
        rigs.append(Rig(port))
        return rigs[-1]

    yield make
    for r in rigs:
        r.runner.close()


def _server(labels: tuple[str, ...], values: tuple[str, ...]) -> TestServer:
    server = TestServer(SPECS + STRING_SPECS)
    server.handlers["getStringsInfo"] = lambda s, a: [
        StringsInfo(tuple(StringItem(label, 10) for label in labels)).encode()
    ]
    server.handlers["getStrings"] = lambda s, a: [Strings(values).encode()]
    return server


def _kinds(server: TestServer, name: str) -> list[str]:
    return [r.kind for r in server.received if r.name == name]


def test_getstrings_is_asked_only_while_the_table_is_open(rig_on: Any) -> None:
    server = _server(("CPU Use", "Mode"), ("12%", "Drive"))
    with ServerThread(server) as srv:
        rig = rig_on(srv.port)
        rig.wait(lambda: "getStringsInfo" in srv.names())
        rig.settle()
        assert _kinds(srv, "getStrings") == []  # nobody reads them: the robot is not asked
        assert rig.robot.server_strings == ()
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: rig.robot.server_strings == (("CPU Use", "12%"), ("Mode", "Drive")))
        assert _kinds(srv, "getStrings") == [f"request {INTERVAL_MS}"]
        rig.runner.send(WatchStrings(False)).result(5)
        rig.wait(lambda: rig.robot.server_strings == ())
        rig.wait(lambda: _kinds(srv, "getStrings") == [f"request {INTERVAL_MS}", "stop"])


def test_simulator_strings_are_labelled_and_wifi_is_fed_without_the_table(rig_on: Any) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        rig = rig_on(sim.port)
        rig.wait(lambda: rig.robot.wifi_quality is not None)  # the gauge needs no open table
        assert rig.robot.server_strings == ()
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: len(rig.robot.server_strings) == len(STRING_ITEMS))
        assert [label for label, _ in rig.robot.server_strings] == [label for label, _ in STRING_ITEMS]
        values = dict(rig.robot.server_strings)
        assert values["Motor Packet Count"] == "10" and values["CPU Use"].strip().endswith("%")
        published = int(values["Wireless Link Quality"])  # 0–70, as Linux reads it; the window's is %
        assert rig.robot.wifi_quality == round(published * 100 / 70)
        rig.runner.send(WatchStrings(False)).result(5)
        rig.wait(lambda: rig.robot.server_strings == ())
        quality = rig.robot.wifi_quality
        assert quality is not None  # the gauge keeps its subscription


def test_ten_thousand_strings_and_huge_labels_stay_bounded(rig_on: Any) -> None:
    labels = tuple(f"s{i}" for i in range(3000))  # as many as one packet holds
    server = _server(labels, tuple("v" for _ in labels))
    with ServerThread(server) as srv:
        rig = rig_on(srv.port)
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: len(rig.robot.server_strings) == MAX_ITEMS)
        assert rig.robot.server_strings_more == len(labels) - MAX_ITEMS
        assert rig.robot.server_strings[0] == ("s0", "v")

    huge = ("L" * 20000, "<b>bold</b> & <i>", "\x1b[2Jclear")
    server = _server(huge, ("V" * 9000, "<span>x</span>", "ok", "a value without a label"))
    with ServerThread(server) as srv:
        rig = rig_on(srv.port)
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: len(rig.robot.server_strings) == 3)
        (l1, v1), (l2, v2), (l3, v3) = rig.robot.server_strings
        assert len(l1) == len(v1) == MAX_TEXT and l1.endswith("…")
        assert (l2, v2) == ("<b>bold</b> & <i>", "<span>x</span>")  # text, never markup
        assert (l3, v3) == ("\x1b[2Jclear", "ok")  # the table shows text; terminals escape it themselves


def test_ten_thousand_empty_labels_fit_one_packet_and_stay_bounded(rig_on: Any) -> None:
    server = _server(tuple("" for _ in range(10_000)), tuple("" for _ in range(10_000)))
    with ServerThread(server) as srv:
        rig = rig_on(srv.port)
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: rig.robot.server_strings_more == 10_000 - MAX_ITEMS)
        assert len(rig.robot.server_strings) == MAX_ITEMS
        assert rig.model.connection.value.phase is Phase.CONNECTED


def test_an_added_item_is_picked_up_and_garbage_values_are_ignored(rig_on: Any) -> None:
    state = {"labels": ("A",), "values": ("1",)}
    server = TestServer(SPECS + STRING_SPECS)
    server.handlers["getStringsInfo"] = lambda s, a: [
        StringsInfo(tuple(StringItem(x, 5) for x in state["labels"])).encode()
    ]
    server.handlers["getStrings"] = lambda s, a: [Strings(state["values"]).encode()]
    with ServerThread(server) as srv:
        rig = rig_on(srv.port)
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: rig.robot.server_strings == (("A", "1"),))
        state["labels"], state["values"] = ("A", "B"), ("1", "2")  # ARIA broadcasts the new list; we re-read
        rig.wait(lambda: rig.robot.server_strings == (("A", "1"), ("B", "2")))
        server.handlers["getStrings"] = lambda s, a: [b"no terminating zero"]
        rig.settle()
        rig.wait(lambda: _kinds(srv, "getStrings").count(f"request {INTERVAL_MS}") == 1)
        assert rig.model.connection.value.phase is Phase.CONNECTED
        assert rig.robot.server_strings == (("A", "1"), ("B", "2"))  # the last good values stay


def test_an_open_table_asks_again_after_a_reconnect(rig_on: Any) -> None:
    server = _server(("CPU Use",), ("12%",))
    thread = ServerThread(server)
    with thread as srv:
        rig = rig_on(srv.port)
        rig.runner.send(WatchStrings(True)).result(5)
        rig.wait(lambda: rig.robot.server_strings == (("CPU Use", "12%"),))
        thread.call(lambda: srv.kill(srv.sides[0]))  # the link drops; the session reconnects by itself
        rig.wait(lambda: len(srv.sides) == 2 and rig.model.connection.value.phase is Phase.CONNECTED, 15)
        rig.wait(lambda: any(r.side == 1 and r.name == "getStrings" for r in srv.received), 10)
        rig.wait(lambda: rig.robot.server_strings == (("CPU Use", "12%"),))
        assert [r.kind for r in srv.received if r.name == "getStrings" and r.side == 1] == [
            f"request {INTERVAL_MS}"
        ]
