"""``rtmu mapedit HOST[:PORT] EDIT…``: change the server's map live in one change set (``DESCRIPTION``)."""

from __future__ import annotations

import argparse
import math
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_NOT_HELD, EXIT_OK, EXIT_REFUSED, EXIT_USAGE, NETWORK
from ..base.i18n import N_, _
from ..base.textsafe import visible
from ..client.errors import NotSupported
from ..client.roles import Role
from ._common import add_connection_arguments, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient
    from ..mapedit import MapDraft, ObjectChanges

DESCRIPTION = N_("""Change the server's map live, in one change set (ARIA's ArMapChanger).

Edits, in any number and order (all go in ONE processMapChanges):

  --add-goal NAME --x MM --y MM [--th DEG]   a goal (with --th: a goal with heading)
  --add-dock NAME --x MM --y MM --th DEG     a charging dock facing DEG
  --remove NAME                              delete the goal, dock or home of that name
  --add-forbidden-line X1 Y1 X2 Y2           a line the robot must not cross (mm)
  --add-forbidden-area X1 Y1 X2 Y2           a rectangle the robot must not enter (opposite corners, mm)

--x, --y and --th belong to the --add-goal or --add-dock before them. The map is read first (the
edits are checked against it: a name already taken, a name not on the map), the change is sent
guarded by the map's id, and the map is read again afterwards to check that it holds the change.
--check-map instead asks the server to re-read its map file (checkMap).

Exit 0 only when the server's map, read again, holds the change. An edit that does not fit the map
is a usage error (nothing is sent); a refused change leaves the map as it was (the server's words
are printed); a server that takes no map changes, or has no map, does not offer it.
""")

EXITS = (*NETWORK, EXIT_REFUSED, EXIT_NOT_HELD)
MAX_EDITS = 10_000


def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


class _Edit(argparse.Action):
    """An edit, appended in command-line order to ``edits``."""

    def __call__(self, parser: Any, namespace: Any, values: Any, option_string: Any = None) -> None:
        edits = list(getattr(namespace, "edits", None) or [])
        kind = self.dest
        if kind in ("add_forbidden_line", "add_forbidden_area"):
            edits.append({"kind": kind, "coords": [_checked(parser, v, option_string) for v in values]})
        else:
            edits.append({"kind": kind, "name": values})
        namespace.edits = edits


def _checked(parser: Any, text: str, option: str) -> float:
    try:
        return _number(text)
    except argparse.ArgumentTypeError as exc:
        parser.error(f"{option}: {exc}")
    raise AssertionError  # pragma: no cover - parser.error exits


class _Coordinate(argparse.Action):
    """``--x``/``--y``/``--th``: a coordinate of the ``--add-goal``/``--add-dock`` before it."""

    def __call__(self, parser: Any, namespace: Any, values: Any, option_string: Any = None) -> None:
        edits: list[dict[str, Any]] = getattr(namespace, "edits", None) or []
        last: dict[str, Any] | None = edits[-1] if edits else None
        if last is None or last["kind"] not in ("add_goal", "add_dock"):
            parser.error(f"{option_string} belongs after an --add-goal NAME or --add-dock NAME")
            return
        if self.dest in last:
            parser.error(f"{option_string} given twice for {last['name']!r}")
        last[self.dest] = values


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "mapedit",
        help=_("change the server's map live: add or remove goals, docks, forbidden lines and areas"),
        description=_(DESCRIPTION),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json", action="store_true", help=_("one JSON object: what was sent and what the server did")
    )
    p.add_argument(
        "--add-goal",
        dest="add_goal",
        action=_Edit,
        metavar="NAME",
        help=_("add a goal (then --x --y [--th])"),
    )
    p.add_argument(
        "--add-dock", dest="add_dock", action=_Edit, metavar="NAME", help=_("add a dock (then --x --y --th)")
    )
    p.add_argument(
        "--x", dest="x", action=_Coordinate, type=_number, metavar="MM", help=_("x of the goal or dock")
    )
    p.add_argument(
        "--y", dest="y", action=_Coordinate, type=_number, metavar="MM", help=_("y of the goal or dock")
    )
    p.add_argument(
        "--th",
        dest="th",
        action=_Coordinate,
        type=_number,
        metavar="DEG",
        help=_("heading of the goal or dock"),
    )
    p.add_argument(
        "--remove", dest="remove", action=_Edit, metavar="NAME", help=_("delete the object of this name")
    )
    p.add_argument(
        "--add-forbidden-line",
        dest="add_forbidden_line",
        action=_Edit,
        nargs=4,
        metavar=("X1", "Y1", "X2", "Y2"),
        help=_("add a forbidden line from (X1, Y1) to (X2, Y2), in mm"),
    )
    p.add_argument(
        "--add-forbidden-area",
        dest="add_forbidden_area",
        action=_Edit,
        nargs=4,
        metavar=("X1", "Y1", "X2", "Y2"),
        help=_("add a forbidden area between the corners (X1, Y1) and (X2, Y2), in mm"),
    )
    p.add_argument(
        "--check-map",
        action="store_true",
        help=_("ask the server to re-read its map file (checkMap) instead"),
    )
    p.set_defaults(handler=handle, edits=[])


def apply_edits(draft: MapDraft, edits: list[dict[str, Any]]) -> None:
    """Every edit into ``draft`` (DraftError names the first that does not fit)."""
    from ..mapedit import DraftError

    for e in edits:
        kind = e["kind"]
        if kind in ("add_goal", "add_dock"):
            missing = [k for k in ("x", "y") + (("th",) if kind == "add_dock" else ()) if k not in e]
            if missing:
                what = "goal" if kind == "add_goal" else "dock"
                raise DraftError(f"the {what} {e['name']!r} needs " + ", ".join(f"--{m}" for m in missing))
            if kind == "add_goal":
                draft.add_goal(e["name"], e["x"], e["y"], e.get("th"))
            else:
                draft.add_dock(e["name"], e["x"], e["y"], e["th"])
        elif kind == "remove":
            draft.delete(e["name"])
        elif kind == "add_forbidden_line":
            draft.add_forbidden_line(*e["coords"])
        else:
            draft.add_forbidden_area(*e["coords"])


def handle(args: argparse.Namespace) -> int:
    from ..client.config_care import check_map

    edits: list[dict[str, Any]] = args.edits or []
    if args.check_map and edits:
        print(_("rtmu mapedit: --check-map goes alone, without edits"), file=sys.stderr)
        return EXIT_USAGE
    if not args.check_map and not edits:
        print(
            _("rtmu mapedit: nothing to do: give an edit (--add-goal, --remove, …) or --check-map"),
            file=sys.stderr,
        )
        return EXIT_USAGE
    if len(edits) > MAX_EDITS:
        print(
            _("rtmu mapedit: at most {MAX_EDITS} edits at once").format(MAX_EDITS=MAX_EDITS), file=sys.stderr
        )
        return EXIT_USAGE

    async def body(client: AriaClient) -> int:
        if args.check_map:
            changed = await check_map(client, args.timeout)
            if args.json:
                print_json({"map_updated": changed})
            else:
                print(
                    _("the map was read again: it had changed")
                    if changed
                    else _("no mapUpdated: the file had not changed")
                )
            return EXIT_OK
        return await _edit(client, edits, args)

    return run_with_client("mapedit", args, body, role=Role.OBSERVER)  # the map, never motion


async def _edit(client: AriaClient, edits: list[dict[str, Any]], args: argparse.Namespace) -> int:
    from ..client.map_changes import (
        ChangeWatch,
        map_id,
        not_holding,
        object_change_set,
        offers_map_changes,
        send_changes,
    )
    from ..client.mapload import download_map
    from ..mapedit import DraftError, MapDraft

    if not offers_map_changes(client):
        raise NotSupported("processMapChanges", "this server takes no live map changes (processMapChanges)")
    guard = await map_id(client, args.timeout)
    before = await download_map(client, timeout=args.timeout)
    if before.data is None:
        raise NotSupported("getMap", "the server has no map to change")
    draft = MapDraft(before.data.objects)
    try:
        apply_edits(draft, edits)
    except DraftError as exc:
        print(_("rtmu mapedit: {visible}").format(visible=visible(str(exc))), file=sys.stderr)
        return EXIT_USAGE
    change = draft.change()
    if change.empty:
        _report(args, change, None, [], "nothing to change: the map already looks like that")
        return EXIT_OK
    watch = ChangeWatch()
    watch.subscribe(client)
    verdict = await send_changes(
        client, object_change_set(change, before.data), watch, guard=guard, timeout=args.timeout
    )
    if not verdict.applied:
        _report(args, change, verdict, [], "")
        print(_("rtmu mapedit: {visible}").format(visible=visible(verdict.words)), file=sys.stderr)
        return EXIT_REFUSED
    after = await download_map(client, timeout=args.timeout)
    missing = not_holding(after.data.objects if after.data is not None else [], change)
    _report(args, change, verdict, missing, "")
    if missing:
        print(
            "rtmu mapedit: the server said it applied the change, but its map does not hold it: "
            + visible("; ".join(missing)),
            file=sys.stderr,
        )
        return EXIT_NOT_HELD
    return EXIT_OK


def _report(
    args: argparse.Namespace, change: ObjectChanges, verdict: Any, missing: list[str], note: str
) -> None:
    from ..mapedit import describe

    if args.json:
        print_json(
            {
                "removed": [describe(o) for o in change.removed],
                "added": [describe(o) for o in change.added],
                "applied": verdict.applied if verdict is not None else None,
                "status": verdict.status if verdict is not None else None,
                "words": verdict.words if verdict is not None else note,
                "map_updated": verdict.map_updated if verdict is not None else False,
                "holds": verdict is not None and verdict.applied and not missing,
                "missing": missing,
            }
        )
        return
    if note:
        print(note, flush=True)
        return
    if verdict is not None and verdict.applied and not missing:
        for obj in change.removed:
            if not any(o.name and o.name == obj.name for o in change.added):
                print(_("removed {visible}").format(visible=visible(describe(obj))))
        for obj in change.added:
            print(_("added {visible}").format(visible=visible(describe(obj))))
        sys.stdout.flush()
