"""Editing the map draft on the map itself: select, move and turn goals and docks, place them, draw
forbidden lines and areas — with the pointer or a finger, as on paper.

The map edit window (``map_edit_window``) picks a :class:`Tool`; while a tool other than
:attr:`Tool.PAN` is on, a press on the map is the tool's, not a pan:

* **Select / move** — a click on an object selects it in the window's list (rename, delete there);
  a drag from a goal or dock moves it; Shift + drag from one turns it to face the pointer. A press on
  nothing pans the map as always.
* **Goal**, **Dock** — a click places one (named from the window's name field, else ``Goal 3``…);
  a drag from the point sets its heading.
* **Line**, **Area** — press at one end (corner), release at the other.

What a drag would do is drawn on the map while it lasts (the draft's objects with the change); on
release it becomes ONE draft edit (undo takes it back), and nothing is sent before Apply. The map's
own hit rule is :func:`rtmu.mapedit.hit.object_at`; a tool never sends anything to the robot.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from enum import Enum
from typing import Protocol

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402

from ..base.i18n import N_  # noqa: E402
from ..mapedit import MapDraft, MapObject  # noqa: E402
from ..mapedit.draft import DOCK, FORBIDDEN_AREA, FORBIDDEN_LINE, GOAL, GOAL_WITH_HEADING  # noqa: E402
from ..mapedit.hit import POINT_KINDS, object_at  # noqa: E402
from .mapview import MapStage  # noqa: E402
from .pose_pick import DRAG_MIN_PX, capture_drag  # noqa: E402

REACH_PX = 14.0
"""How near (screen pixels) a press must be to a goal, dock or line to take it: a fingertip's width."""


class Tool(Enum):
    """What a press on the map does while the map edit window is open; the value is its label."""

    PAN = N_("Pan")
    SELECT = N_("Select / move")
    GOAL = N_("Goal")
    DOCK = N_("Dock")
    LINE = N_("Line")
    AREA = N_("Area")


TOOL_TIPS = {
    Tool.PAN: N_("Presses on the map pan it; nothing is edited"),
    Tool.SELECT: N_("Click an object to select it; drag a goal or dock to move it; Shift + drag to turn it"),
    Tool.GOAL: N_("Click to place a goal; drag from the point for its heading"),
    Tool.DOCK: N_("Click to place a dock; drag from the point for its heading"),
    Tool.LINE: N_("Press at one end of a forbidden line, release at the other"),
    Tool.AREA: N_("Press at one corner of a forbidden area, release at the opposite one"),
}
CURSORS = {Tool.PAN: None, Tool.SELECT: "pointer"}
"""The pointer's shape per tool (the drawing tools: a crosshair)."""


class CanvasEditor(Protocol):
    """What the map asks of the map edit window (``MapEditWindow`` is one)."""

    draft: MapDraft | None

    def drawn_objects(self) -> tuple[MapObject, ...]:
        """Everything the map draws with the draft: the map's other objects and the draft's."""
        ...

    def run_edit(self, what: Callable[[MapDraft], object]) -> bool:
        """One draft edit; said and shown (False: refused, said why, the draft as it was)."""
        ...

    def select_object(self, obj: MapObject) -> None:
        """Select it in the list (a goal or dock by its name: it may have moved since)."""
        ...

    def name_for(self, stem: str) -> str:
        """The name a placed goal or dock gets (the window's name field, else a free ``stem N``)."""
        ...

    def refresh(self) -> None:
        """Show the draft as it is (ends a drag's preview)."""
        ...


class MapCanvasEdit:
    """See the module notes. One per map stage; the editor is attached while its window is open."""

    def __init__(self, stage: MapStage) -> None:
        self.stage = stage
        self.tool = Tool.PAN
        self.editor: CanvasEditor | None = None
        self._start: tuple[float, float] | None = None
        """The press, in mm (None: no press of the tool's under way)."""
        self._now: tuple[float, float] | None = None
        self._dragged = False
        self._taken: MapObject | None = None
        self._turning = False
        self.gesture = capture_drag(stage, self._begin, self._update, self._end)

    def attach(self, editor: CanvasEditor | None) -> None:
        """The window whose draft the map edits (None: its window closed; back to panning)."""
        self.editor = editor
        if editor is None:
            self.set_tool(Tool.PAN)

    def set_tool(self, tool: Tool) -> None:
        self.tool = tool
        self._forget()
        if tool in CURSORS:
            cursor = CURSORS[tool]
            self.stage.set_cursor_from_name(cursor) if cursor else self.stage.set_cursor(None)
        else:
            self.stage.set_cursor_from_name("crosshair")

    # -- the press and its drag -------------------------------------------------------------------
    def _begin(self, gesture: Gtk.GestureDrag, sx: float, sy: float) -> None:
        editor = self.editor
        if editor is None or editor.draft is None or self.tool is Tool.PAN:
            gesture.set_state(Gtk.EventSequenceState.DENIED)
            return
        where = self.stage.viewport.to_world(sx, sy)
        taken = None
        if self.tool is Tool.SELECT:
            taken = object_at(editor.draft.objects, *where, REACH_PX / self.stage.viewport.scale)
            if taken is None:  # nothing under the pointer: the map pans as always
                gesture.set_state(Gtk.EventSequenceState.DENIED)
                return
        gesture.set_state(Gtk.EventSequenceState.CLAIMED)
        modifiers = gesture.get_current_event_state()
        self._turning = bool(modifiers & Gdk.ModifierType.SHIFT_MASK)
        self._start, self._now, self._taken, self._dragged = where, where, taken, False

    def _update(self, _gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        if self._start is None or self.editor is None:
            return
        if math.hypot(dx, dy) < DRAG_MIN_PX and not self._dragged:
            return
        self._dragged = True
        scale = self.stage.viewport.scale
        self._now = (self._start[0] + dx / scale, self._start[1] - dy / scale)
        preview = self._preview()
        if preview is not None:
            self.stage.draft_objects = list(preview)
            self.stage.queue_draw()

    def _end(self, gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        self._update(gesture, dx, dy)
        editor, start, now, taken, dragged = self.editor, self._start, self._now, self._taken, self._dragged
        turning = self._turning
        self._forget()
        if editor is None or start is None or now is None:
            return
        select: MapObject | None = None
        if self.tool is Tool.SELECT and taken is not None:
            select = taken
            if dragged and taken.name and taken.type.lower() in POINT_KINDS:
                if turning:
                    editor.run_edit(lambda d: d.turn(taken.name, _bearing(start, now)))
                else:
                    editor.run_edit(lambda d: d.move(taken.name, *now))
        elif self.tool in (Tool.GOAL, Tool.DOCK):
            heading = _bearing(start, now) if dragged else None
            if self.tool is Tool.GOAL:
                name = editor.name_for("Goal")
                editor.run_edit(lambda d: d.add_goal(name, *start, heading))
            else:
                name = editor.name_for("Dock")
                editor.run_edit(lambda d: d.add_dock(name, *start, heading or 0.0))
        elif self.tool in (Tool.LINE, Tool.AREA) and dragged:
            add = MapDraft.add_forbidden_line if self.tool is Tool.LINE else MapDraft.add_forbidden_area
            editor.run_edit(lambda d: add(d, *start, *now))
        editor.refresh()  # the drag's preview ends: the draft as it now is
        if select is not None:
            editor.select_object(select)  # a goal or dock found by its name, where it is now

    def _preview(self) -> Sequence[MapObject] | None:
        """What the map shows while the drag lasts: the drawn objects with the change made."""
        editor, start, now, taken = self.editor, self._start, self._now, self._taken
        if editor is None or start is None or now is None:
            return None
        drawn = editor.drawn_objects()
        if self.tool is Tool.SELECT:
            if taken is None or taken.type.lower() not in POINT_KINDS:
                return None
            kind = GOAL_WITH_HEADING if taken.type.lower() == GOAL.lower() else taken.type
            moved = (
                replace(taken, type=kind, th=_bearing(start, now))
                if self._turning
                else replace(taken, x=now[0], y=now[1])
            )
            return [moved if o is taken else o for o in drawn]
        if self.tool in (Tool.GOAL, Tool.DOCK):
            kind = DOCK if self.tool is Tool.DOCK else GOAL_WITH_HEADING
            return [*drawn, MapObject(kind, start[0], start[1], _bearing(start, now), name="…")]
        kind = FORBIDDEN_LINE if self.tool is Tool.LINE else FORBIDDEN_AREA
        return [*drawn, MapObject(kind, 0.0, 0.0, 0.0, from_xy=start, to_xy=now)]

    def _forget(self) -> None:
        self._start = self._now = None
        self._taken, self._dragged, self._turning = None, False, False


def _bearing(start: tuple[float, float], end: tuple[float, float]) -> float:
    """Degrees from ``start`` towards ``end`` (the map's y points up, as ARIA's headings)."""
    return math.degrees(math.atan2(end[1] - start[1], end[0] - start[0]))
