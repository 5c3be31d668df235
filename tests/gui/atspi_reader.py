"""Read an application's accessibility tree through AT-SPI, as a screen reader does: a process of its own.

Run as ``python tests/gui/atspi_reader.py PID [--activate ACTION]… [--events SECONDS]`` (the venv's
Python, with the system's ``pyatspi`` linked in by ``scripts/setup.sh``). It finds the application
whose process is PID on the accessibility bus (``AT_SPI_BUS_ADDRESS``, else the one the session bus
names), runs each window ACTION as a screen reader user can, and prints one JSON object:
``{"nodes": [...]}``, each node ``{"path", "role", "name", "description", "states", "actions"}``
(``path`` is the child indices from the application down). With ``--events`` it then listens for that
many seconds and adds ``"events"``: every name and description change of the application's objects.

Why a process of its own: AT-SPI's calls block until the application answers, and the application
answers from its GTK main loop, which the test's own thread runs; in one process they would wait on
each other forever.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import pyatspi  # type: ignore[import-not-found]
from gi.repository import GLib  # type: ignore[import-untyped]

MAX_NODES = 20000
"""A window that exposes more than this is a broken tree (a cycle, a runaway list): said, not walked."""


def find_application(pid: int, timeout: float) -> Any:
    """The application of process ``pid`` on the desktop, waiting up to ``timeout`` s for it to appear."""
    deadline = time.monotonic() + timeout
    while True:
        desktop = pyatspi.Registry.getDesktop(0)
        for i in range(desktop.childCount):
            app = desktop.getChildAtIndex(i)
            try:
                if app is not None and app.get_process_id() == pid:
                    return app
            except GLib.Error:
                continue  # an application that went away meanwhile
        if time.monotonic() > deadline:
            raise SystemExit(f"no application of process {pid} on the accessibility bus")
        time.sleep(0.2)


def node(acc: Any, path: list[int]) -> dict[str, Any]:
    state = acc.getState()
    states = [pyatspi.stateToString(s) for s in state.getStates()]
    try:
        actions = acc.queryAction()
        action_names = [actions.getName(i) for i in range(actions.nActions)]
    except NotImplementedError:
        action_names = []
    return {
        "path": path,
        "role": acc.getRoleName(),
        "name": acc.name or "",
        "description": acc.description or "",
        "states": states,
        "actions": action_names,
    }


def walk(app: Any) -> list[dict[str, Any]]:
    nodes: list[dict[str, Any]] = []
    stack: list[tuple[Any, list[int]]] = [(app, [])]
    while stack:
        acc, path = stack.pop()
        if len(nodes) >= MAX_NODES:
            raise SystemExit(f"more than {MAX_NODES} accessible objects: a broken tree")
        try:
            nodes.append(node(acc, path))
            children = [(acc.getChildAtIndex(i), [*path, i]) for i in range(acc.childCount)]
        except GLib.Error as exc:  # an object destroyed while walked: noted, the walk goes on
            nodes.append({"path": path, "role": "gone", "name": "", "description": str(exc), "states": []})
            continue
        stack.extend(c for c in reversed(children) if c[0] is not None)
    return nodes


def listen(pid: int, seconds: float) -> list[dict[str, Any]]:
    """Name and description changes of ``pid``'s objects for ``seconds``, as a screen reader hears them."""
    heard: list[dict[str, Any]] = []

    def on_event(event: Any) -> None:
        try:
            source = event.source
            if source is None or source.get_process_id() != pid:
                return
            heard.append(
                {
                    "type": event.type,
                    "role": source.getRoleName(),
                    "name": source.name or "",
                    "value": str(event.any_data) if event.any_data is not None else "",
                    "at": time.monotonic(),
                }
            )
        except GLib.Error:
            pass

    types = ("object:property-change:accessible-name", "object:property-change:accessible-description")
    pyatspi.Registry.registerEventListener(on_event, *types)
    print(json.dumps({"listening": True}), flush=True)  # the test may now change what is shown
    loop = GLib.MainLoop()
    GLib.timeout_add(int(seconds * 1000), loop.quit)
    loop.run()
    pyatspi.Registry.deregisterEventListener(on_event, *types)
    return heard


def activate(app: Any, action: str) -> None:
    """Run the window action ``action`` (``win.dpad``) through the frame's AT-SPI Action interface, as
    a screen reader user can, then let the application settle (its answer comes on its main loop)."""
    for i in range(app.childCount):
        frame = app.getChildAtIndex(i)
        actions = frame.queryAction()
        for k in range(actions.nActions):
            if actions.getName(k) == action:
                actions.doAction(k)
                time.sleep(1.0)
                return
    raise SystemExit(f"no window of the application offers {action}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("pid", type=int)
    parser.add_argument("--timeout", type=float, default=30.0, help="how long to wait for the application")
    parser.add_argument("--events", type=float, default=0.0, metavar="SECONDS", help="then listen this long")
    parser.add_argument("--activate", action="append", default=[], metavar="ACTION", help="first run this")
    args = parser.parse_args(argv)
    app = find_application(args.pid, args.timeout)
    for action in args.activate:
        activate(app, action)
    nodes = walk(app)
    deadline = time.monotonic() + args.timeout
    while nodes[0]["role"] != "application" or len(nodes) < 2:  # registered, its tree not served yet
        if time.monotonic() > deadline:
            raise SystemExit(f"the application's tree could not be read: {nodes[:2]}")
        time.sleep(0.5)
        app = find_application(args.pid, args.timeout)
        nodes = walk(app)
    out: dict[str, Any] = {"nodes": nodes}
    if args.events > 0:
        out["events"] = listen(args.pid, args.events)
    print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
