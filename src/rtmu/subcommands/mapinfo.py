"""``rtmu mapinfo FILE [--json]``: what an ARIA map holds, and where its header disagrees with its data."""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from typing import TYPE_CHECKING, Any

from rtmu.base.exit_codes import EXIT_BAD_FILE, EXIT_OK, EXIT_SIGPIPE, EXIT_USAGE
from rtmu.base.textsafe import visible

from ..base.i18n import _

if TYPE_CHECKING:
    from rtmu.mapfile import Bounds, MapData

EXITS = (EXIT_OK, EXIT_USAGE, EXIT_BAD_FILE, EXIT_SIGPIPE)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "mapinfo",
        help=_("summarise an ARIA .map file (counts, bounds, objects)"),
        description=_(
            "Summarise an ARIA .map file: category, counts found and claimed by the header, bounds, "
            "resolution, map objects by type, goal names and unknown header keywords."
        ),
    )
    parser.add_argument("file", metavar="FILE", help=_("the .map file"))
    parser.add_argument("--json", action="store_true", help=_("print one JSON object instead of text"))
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from rtmu.mapfile import MapFormatError, read_map

    try:
        data = read_map(args.file)
    except MapFormatError as exc:
        print(_("rtmu mapinfo: {visible}").format(visible=visible(str(exc))), file=sys.stderr)
        return EXIT_USAGE if isinstance(exc.__cause__, OSError) else EXIT_BAD_FILE  # missing, or not a map
    summary = summarise(data)
    if args.json:
        print(json.dumps(summary))
    else:
        # Map file text is untrusted: escape control characters line by line.
        print("\n".join(visible(line) for line in render_text(summary).split("\n")))
    return EXIT_OK


def summarise(data: MapData) -> dict[str, Any]:
    from rtmu.mapfile import split_keyword

    """Everything ``mapinfo`` reports, as plain JSON-ready values."""
    scans = []
    for scan in data.scans:
        scans.append(
            {
                "name": scan.name,
                "points": len(scan.points),
                "claimed_points": scan.claimed.num_points,
                "lines": len(scan.segments),
                "claimed_lines": scan.claimed.num_lines,
                "point_bounds": _box(scan.point_bounds()),
                "claimed_point_bounds": _box(scan.claimed.point_bounds),
                "line_bounds": _box(scan.line_bounds()),
                "claimed_line_bounds": _box(scan.claimed.line_bounds),
                "resolution": scan.resolution,
            }
        )
    home = data.home()
    unknown = [split_keyword(line)[0] for line in data.unknown_lines]
    return {
        "file": data.source,
        "category": data.category,
        "points": data.num_points,
        "claimed_points": data.claimed.num_points,
        "lines": data.num_lines,
        "claimed_lines": data.claimed.num_lines,
        "bounds": _box(data.bounds()),
        "resolution": data.resolution,
        "scans": scans,
        "objects": len(data.objects),
        "objects_by_type": dict(Counter(obj.type for obj in data.objects)),
        "goals": data.goal_names(),
        "home": None if home is None else {"x": home.x, "y": home.y, "th": home.th},
        "map_info": len(data.map_info),
        "unknown_keywords": sorted(set(unknown)),
        "unknown_lines": len(data.unknown_lines),
        "skipped_lines": data.skipped_lines,
        "warnings": data.warning_count,
    }


def render_text(summary: dict[str, Any]) -> str:
    """The summary for people, in the operator's language and numbers (``--json`` keeps the plain form);
    the map's own words — its file name, category, goal and object type names — as written in it."""
    from ..base.i18n import ngettext, number
    from ..base.units import quantity

    def claim(found: int, claimed: int | None) -> str:
        if claimed is None:
            return _("{found} (header: none)").format(found=number(found))
        if claimed == found:
            return _("{found} (header: {claimed})").format(found=number(found), claimed=number(claimed))
        return _("{found} (header: {claimed})  <- header is stale").format(
            found=number(found), claimed=number(claimed)
        )

    def box(value: list[int] | None) -> str:
        if value is None:
            return _("none")
        x1, y1, x2, y2 = (number(v) for v in value)
        return f"({x1}, {y1}) .. ({x2}, {y2})"

    def header(value: list[int] | None) -> str:
        return _("(header: {bounds})").format(bounds=box(value))

    rows: list[tuple[str, str]] = [(_("file"), summary["file"]), (_("category"), summary["category"])]
    for scan in summary["scans"]:
        title = f" [{scan['name']}]" if scan["name"] else ""
        resolution = _("none") if scan["resolution"] is None else quantity(scan["resolution"], "mm")
        rows += [
            (_("points") + title, claim(scan["points"], scan["claimed_points"])),
            (_("lines") + title, claim(scan["lines"], scan["claimed_lines"])),
            (
                _("point bounds") + title,
                f"{box(scan['point_bounds'])}  {header(scan['claimed_point_bounds'])}",
            ),
            (_("line bounds") + title, f"{box(scan['line_bounds'])}  {header(scan['claimed_line_bounds'])}"),
            (_("resolution") + title, resolution),
        ]
    rows.append((_("bounds"), box(summary["bounds"])))
    by_type = ", ".join(
        f"{name} {number(count)}" for name, count in sorted(summary["objects_by_type"].items())
    )
    rows.append((_("objects"), number(summary["objects"]) + (f" ({by_type})" if by_type else "")))
    goals = summary["goals"]
    rows.append(
        (_("goals"), number(len(goals)) + (": " + ", ".join(json.dumps(g) for g in goals) if goals else ""))
    )
    home = summary["home"]
    where = (
        _("none")
        if home is None
        else "x={x} y={y} th={th}".format(x=number(home["x"]), y=number(home["y"]), th=number(home["th"]))
    )
    rows.append((_("home"), where))
    unknown = summary["unknown_keywords"]
    listed = f": {' '.join(unknown)}" if unknown else ""
    rows.append((_("unknown lines"), number(summary["unknown_lines"]) + listed))
    if summary["skipped_lines"] or summary["warnings"]:
        skipped = ngettext(
            "{warnings} ({count} data line skipped)",
            "{warnings} ({count} data lines skipped)",
            summary["skipped_lines"],
        ).format(warnings=number(summary["warnings"]), count=number(summary["skipped_lines"]))
        rows.append((_("warnings"), skipped))
    width = max(len(label) for label, _value in rows) + 1
    lines = [f"{label + ':':<{width}} {value}" for label, value in rows]
    return "\n".join(lines)


def _box(bounds: Bounds | None) -> list[int] | None:
    return None if bounds is None else list(bounds)
