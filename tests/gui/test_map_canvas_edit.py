"""Editing the map draft on the map itself, with the real pointer: place, move, turn, select, draw, delete.

Real window, real simulator, real X input (xdotool presses, drags, Shift). The map edit window's tools
(``ui/map_canvas_edit``) turn presses on the map into draft edits: a goal placed by a click with its
heading dragged, moved by a drag, turned by Shift + drag, selected by a click; a forbidden line and an
area drawn; a selected line deleted; a press on nothing with Select still pans the map. Nothing reaches
the robot before Apply (its goals and mode are checked on the way); Apply sends it all, and the robot's
map then holds it. Space stops the robot while a drawing tool is on.
"""

from __future__ import annotations

from rtmu.mapedit import MapObject
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.ui.map_canvas_edit import Tool
from rtmu.ui.map_edit_window import MapEditWindow
from simulators import simulator

from .harness import Gui, idle, pump
from .stop_paths import StopCycle
from .test_config_page import click
from .test_map_edit_window import open_window

sim = simulator(map_path=project_map("office.map"), seed=1)
CORRIDOR = (6500.0, 6000.0)
"""A free point of the office map, in the map's left half (the edit window is moved off it)."""


class Pointer:
    """Presses and drags on the map stage in the stage's own pixels, as real X input."""

    def __init__(self, gui: Gui) -> None:
        from gi.repository import GdkX11

        self.gui, self.stage = gui, gui.stage
        self.xid = str(GdkX11.X11Surface.get_xid(gui.window.get_surface()))

    def at(self, wx: float, wy: float) -> tuple[int, int]:
        """Window pixels of the world point (mm)."""
        from gi.repository import Graphene

        sx, sy = self.stage.viewport.to_screen(wx, wy)
        native = self.stage.get_native()
        ok, point = self.stage.compute_point(native, Graphene.Point().init(sx, sy))
        assert ok
        dx, dy = native.get_surface_transform()
        return round(point.x + dx), round(point.y + dy)

    def drag(self, start: tuple[int, int], by: tuple[int, int], *, shift: bool = False) -> None:
        (x, y), (dx, dy) = start, by
        gui = self.gui
        gui.xdotool("mousemove", "--window", self.xid, str(x), str(y))
        idle(0.2)  # under a bare X server the first press after the pointer entered is the enter
        if shift:
            gui.xdotool("keydown", "shift")
        try:
            gui.xdotool("mousedown", "1")
            if dx or dy:
                gui.xdotool("mousemove", "--window", self.xid, str(x + dx // 3), str(y + dy // 3))
                gui.xdotool("mousemove", "--window", self.xid, str(x + dx), str(y + dy))
            idle(0.1)
            gui.xdotool("mouseup", "1")
        finally:
            if shift:
                gui.xdotool("keyup", "shift")
        idle(0.2)

    @property
    def mm(self) -> float:
        """One pixel, in mm at the current zoom."""
        return 1.0 / self.stage.viewport.scale


def named(w: MapEditWindow, name: str) -> MapObject:
    assert w.draft is not None
    found = w.draft.find(name)
    assert found is not None, f"no {name!r} in the draft: {[o.name for o in w.draft.objects]}"
    return found


def kinds(w: MapEditWindow, kind: str) -> list[MapObject]:
    assert w.draft is not None
    return [o for o in w.draft.objects if o.type == kind]


def test_the_map_tools_edit_the_draft_and_apply_sends_it(gui: Gui, sim: SimThread) -> None:
    from gi.repository import GdkX11

    w = open_window(gui)
    gui.xdotool("windowmove", "--sync", str(GdkX11.X11Surface.get_xid(w.get_surface())), "640", "0")
    idle(0.3)
    pointer = Pointer(gui)
    assert all(b.get_sensitive() for b in w.tool_buttons.values())
    lines_before, areas_before = len(kinds(w, "ForbiddenLine")), len(kinds(w, "ForbiddenArea"))

    # a goal: a click at the point, dragged up for its heading (90°)
    click(gui, w.tool_buttons[Tool.GOAL])
    pump(lambda: gui.window.commissioning.canvas_edit.tool is Tool.GOAL, 3, "the Goal tool")  # type: ignore[union-attr]
    p0 = pointer.at(*CORRIDOR)
    pointer.drag(p0, (0, -60))
    pump(lambda: w.draft is not None and w.draft.find("Goal 1") is not None, 5, "the placed goal")
    goal = named(w, "Goal 1")
    tolerance = 3 * pointer.mm
    assert abs(goal.x - CORRIDOR[0]) <= tolerance and abs(goal.y - CORRIDOR[1]) <= tolerance, goal
    assert goal.type == "GoalWithHeading" and abs(goal.th - 90) <= 2, goal
    assert "Goal 1" not in gui.model.navigation.value.goals  # a draft changes nothing on the robot
    gui.shot("goal-placed")

    # moved by a drag with Select, then turned by Shift + drag
    click(gui, w.tool_buttons[Tool.SELECT])
    pointer.drag(pointer.at(goal.x, goal.y), (80, 0))
    pump(lambda: abs(named(w, "Goal 1").x - (goal.x + 80 * pointer.mm)) <= tolerance, 5, "the goal moved")
    moved = named(w, "Goal 1")
    assert abs(moved.y - goal.y) <= tolerance
    pointer.drag(pointer.at(moved.x, moved.y), (0, 60), shift=True)  # towards the bottom: -90°
    pump(lambda: abs(named(w, "Goal 1").th + 90) <= 2, 5, "the goal turned")
    assert named(w, "Goal 1").x == moved.x  # turning did not move it
    # a click selects it in the list
    pointer.drag(pointer.at(moved.x, moved.y), (0, 0))
    pump(lambda: (s := w.selected()) is not None and s.name == "Goal 1", 5, "the goal selected")

    # a forbidden line and an area, drawn
    click(gui, w.tool_buttons[Tool.LINE])
    line_start = pointer.at(CORRIDOR[0], CORRIDOR[1] - 60 * pointer.mm)
    pointer.drag(line_start, (120, 0))
    pump(lambda: len(kinds(w, "ForbiddenLine")) == lines_before + 1, 5, "the drawn line")
    click(gui, w.tool_buttons[Tool.AREA])
    pointer.drag(pointer.at(CORRIDOR[0] - 120 * pointer.mm, CORRIDOR[1]), (-60, 60))
    pump(lambda: len(kinds(w, "ForbiddenArea")) == areas_before + 1, 5, "the drawn area")
    gui.shot("line-and-area-drawn")

    # the line selected on the map and deleted in the window
    click(gui, w.tool_buttons[Tool.SELECT])
    pointer.drag((line_start[0] + 60, line_start[1]), (0, 0))
    pump(lambda: (s := w.selected()) is not None and s.type == "ForbiddenLine", 5, "the line selected")
    click(gui, w.delete_button)
    pump(lambda: len(kinds(w, "ForbiddenLine")) == lines_before, 5, "the line deleted")

    # a press on nothing pans the map, and edits nothing
    edits, centre = len(w.draft.edits), (gui.stage.viewport.cx, gui.stage.viewport.cy)  # type: ignore[union-attr]
    pointer.drag(pointer.at(CORRIDOR[0] - 50 * pointer.mm, CORRIDOR[1] - 150 * pointer.mm), (40, -40))
    pump(lambda: (gui.stage.viewport.cx, gui.stage.viewport.cy) != centre, 5, "the map to pan")
    assert len(w.draft.edits) == edits  # type: ignore[union-attr]
    assert sim.snapshot().mode_name != "Goto"  # no tool ever moved the robot

    click(gui, w.apply_button)
    pump(lambda: w.applied == 1, 20, "the server's verdict")
    pump(lambda: "Goal 1" in gui.model.navigation.value.goals, 10, "the robot's map to hold the goal")
    data = gui.model.map.value.data
    assert data is not None
    assert len([o for o in data.objects if o.type == "ForbiddenArea"]) == areas_before + 1
    assert len([o for o in data.objects if o.type == "ForbiddenLine"]) == lines_before
    gui.shot("applied")

    # Space stops the robot with a drawing tool on (the cycle ends back on the map: the window closes)
    click(gui, w.tool_buttons[Tool.LINE])
    StopCycle(gui, sim).prove("the Line tool on the map", dpad_here=False)


def test_closing_the_window_gives_the_map_back_to_panning(gui: Gui, sim: SimThread) -> None:
    w = open_window(gui)
    canvas = gui.window.commissioning.canvas_edit
    assert canvas is not None
    w.set_tool(Tool.AREA)
    assert canvas.tool is Tool.AREA and canvas.editor is w
    assert w.tool_buttons[Tool.AREA].get_active() and not w.tool_buttons[Tool.PAN].get_active()
    gui.render(w, gui.shots / f"{gui.name}-area-tool.png")
    w.close()
    pump(lambda: w.closed, 5, "the window to close")
    assert canvas.tool is Tool.PAN and canvas.editor is None
