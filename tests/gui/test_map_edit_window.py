"""Editing the map as a draft in the real window: add, undo / redo, Apply as one change, seen elsewhere.

Real window, real simulator, real keys and clicks, and a second client (a plain runner, as another
operator's RTMU would be). Checked: edits stay a draft until Apply; Ctrl+Z / Ctrl+Y walk them; Apply
sends one change set that the second client then sees in its goals; another client's change while a
draft is open is said plainly and the draft kept; Space stops the robot while this window has the
keys.
"""

from __future__ import annotations

import re

import gi

from client.uiqueue import UiQueue
from rtmu.client.runner import ClientRunner
from rtmu.mapedit import MapDraft
from rtmu.model.observables import MapPhase, RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.ui.map_edit_window import MapEditWindow
from rtmu.values.intents import ApplyMapChanges
from rtmu.values.target import Target
from simulators import simulator

from .harness import Gui, idle, pump
from .stop_paths import StopCycle
from .test_config_page import click, type_into

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

sim = simulator(map_path=project_map("office.map"), seed=1)


class Other:
    """Another operator's client on the same robot."""

    def __init__(self, port: int) -> None:
        self.model, self.ui = RobotModel(), UiQueue()
        self.runner = ClientRunner(self.model, post=self.ui.post)
        self.runner.start()
        self.runner.connect(Target("127.0.0.1", port, "", "", profile="other")).result(10)
        self.until(lambda: self.model.map.value.state is MapPhase.READY, "the other client's map")

    def until(self, condition, what: str, timeout: float = 15.0) -> None:  # type: ignore[no-untyped-def]
        pump(lambda: self.ui.drain() >= 0 and condition(), timeout, what)

    @property
    def goals(self) -> tuple[str, ...]:
        return tuple(self.model.navigation.value.goals)


def press(gui: Gui, button: Gtk.Button) -> None:
    """Activate ``button`` from the keyboard (focus, then a real Return), wherever it is scrolled to."""
    button.grab_focus()
    pump(button.has_focus, 3, "the button to have the focus")
    gui.key("Return")


def labels_under(widget: Gtk.Widget) -> list[Gtk.Label]:
    found, child = [], widget.get_first_child()
    while child is not None:
        found += [child] if isinstance(child, Gtk.Label) else labels_under(child)
        child = child.get_next_sibling()
    return found


def open_window(gui: Gui) -> MapEditWindow:
    gui.window.activate_action("win.map-edit", None)
    pump(lambda: gui.window.commissioning.map_edit is not None, 5, "the map edit window")
    w = gui.window.commissioning.map_edit
    assert w is not None
    pump(lambda: w.get_mapped() and w.draft is not None, 10, "the draft on the robot's map")
    return w


def test_a_draft_applied_as_one_change_is_seen_by_a_second_client(gui: Gui, sim: SimThread) -> None:
    from gi.repository import GdkX11

    other = Other(sim.port)
    try:
        w = open_window(gui)
        assert w.state_label.get_text().startswith("No changes")
        assert not w.apply_button.get_sensitive()
        gui.render(w, gui.shots / f"{gui.name}-opened.png")
        type_into(gui, w.name_entry, "Charger-side")
        type_into(gui, w.fields["x"], "2500")
        type_into(gui, w.fields["y"], "3000")
        type_into(gui, w.fields["th"], "90")
        click(gui, w.add_button)
        pump(lambda: w.draft is not None and len(w.draft.edits) == 1, 5, "the goal in the draft")
        assert w.state_label.get_text() == "Draft: 1 edit, not applied"
        assert "Charger-side" not in gui.model.navigation.value.goals  # a draft changes nothing
        w.kind.set_selected(2)  # Forbidden line (the drop-down's own popover is GTK's)
        for name, value in (("x", "1000"), ("y", "1000"), ("x2", "1000"), ("y2", "2500")):
            type_into(gui, w.fields[name], value)
        click(gui, w.add_button)
        pump(lambda: len(w.draft.edits) == 2, 5, "the line in the draft")  # type: ignore[union-attr]
        assert "forbidden line (1000, 1000)–(1000, 2500)  — draft" in [
            r.get_child().get_text() for r in _rows(w)
        ]
        gui.render(w, gui.shots / f"{gui.name}-draft.png")
        # the map draws the draft, and a banner says it is one
        drawn = gui.stage.draft_objects
        assert drawn is not None and any(getattr(o, "name", "") == "Charger-side" for o in drawn)
        assert any(getattr(o, "type", "") == "RobotHome" for o in drawn)  # the rest of the map stays drawn
        assert "draft (2 edits), not applied" in (gui.window.banners.text("map-draft") or "")
        gui.shot("draft-on-the-map")
        # undo and redo with their keys
        gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(w.get_surface())))
        w.rows.grab_focus()
        gui.key("ctrl+z")
        pump(lambda: len(w.draft.edits) == 1, 3, "Ctrl+Z")  # type: ignore[union-attr]
        gui.key("ctrl+y")
        pump(lambda: len(w.draft.edits) == 2, 3, "Ctrl+Y")  # type: ignore[union-attr]

        click(gui, w.apply_button)
        pump(lambda: w.applied == 1, 20, "the server's verdict")
        assert w.news.get_text().startswith("Applied") and not w.news.has_css_class("error")
        other.until(lambda: "Charger-side" in other.goals, "the second client to see the goal")
        lines = [o for o in other.model.map.value.data.objects if o.type == "ForbiddenLine"]  # type: ignore[union-attr]
        assert any(o.from_xy == (1000, 1000) and o.to_xy == (1000, 2500) for o in lines)
        pump(lambda: "Charger-side" in gui.model.navigation.value.goals, 10, "the window's goals")
        pump(lambda: w.state_label.get_text().startswith("No changes"), 10, "a fresh draft")
        assert gui.stage.draft_objects is None and gui.window.banners.text("map-draft") is None
        gui.render(w, gui.shots / f"{gui.name}-applied.png")

        # another client's change under an open draft: said, the draft kept
        type_into(gui, w.name_entry, "Mine")
        w.kind.set_selected(0)
        click(gui, w.add_button)
        pump(lambda: len(w.draft.edits) == 1, 5, "a new draft edit")  # type: ignore[union-attr]
        theirs = MapDraft(other.model.map.value.data.objects)  # type: ignore[union-attr]
        theirs.add_goal("Visitor", 4000, 3000)
        change = theirs.change()
        verdict = other.runner.send(
            ApplyMapChanges(change.removed, change.added, other.model.map.value.generation)
        ).result(20)
        assert verdict.applied
        pump(lambda: 'added goal "Visitor"' in w.news.get_text(), 15, "the other client's change said")
        assert "Your draft is kept" in w.news.get_text() and len(w.draft.edits) == 1  # type: ignore[union-attr]
        gui.render(w, gui.shots / f"{gui.name}-changed-underneath.png")

        # Space stops the robot while this window has the keys
        cycle = StopCycle(gui, sim)
        gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(w.get_surface())))
        pump(w.is_active, 5, "the window to have the keys")
        cycle.prove("the map edit window with the keyboard", dpad_here=False)
    finally:
        other.runner.close()


def _rows(w: MapEditWindow) -> list:  # type: ignore[type-arg]
    out, i = [], 0
    while (row := w.rows.get_row_at_index(i)) is not None:
        out.append(row)
        i += 1
    return out


def test_a_goal_placed_by_a_click_and_a_drag_on_the_map(gui: Gui, sim: SimThread) -> None:
    from gi.repository import GdkX11, Graphene

    w = open_window(gui)
    stage = gui.stage
    sx, sy = stage.viewport.to_screen(6500, 6000)  # the corridor, in the stage's own pixels
    ok, point = stage.compute_point(stage.get_native(), Graphene.Point().init(sx, sy))
    assert ok
    dx, dy = stage.get_native().get_surface_transform()
    x, y = round(point.x + dx), round(point.y + dy)
    edit_xid = str(GdkX11.X11Surface.get_xid(w.get_surface()))
    gui.xdotool("windowmove", "--sync", edit_xid, "640", "0")  # off the map's left half (no window manager)
    idle(0.3)
    click(gui, w.pick_button)
    pump(lambda: gui.window.commissioning.point_pick.active, 3, "the pick mode")  # type: ignore[union-attr]
    xid = str(GdkX11.X11Surface.get_xid(gui.window.get_surface()))
    gui.xdotool("mousemove", "--window", xid, str(x), str(y))
    idle(0.2)  # the pointer enters the window first (under a bare X server the first press is the enter)
    gui.xdotool("mousedown", "1")
    gui.xdotool("mousemove", "--window", xid, str(x), str(y - 20))
    gui.xdotool("mousemove", "--window", xid, str(x), str(y - 60), "mouseup", "1")  # dragged up: 90°
    pump(lambda: w.fields["x"].get_text() != "", 5, "the picked point in the fields")
    px, py, th = (float(w.fields[n].get_text()) for n in ("x", "y", "th"))
    scale_mm = 1.0 / stage.viewport.scale  # one pixel, in mm
    assert abs(px - 6500) <= 2 * scale_mm and abs(py - 6000) <= 2 * scale_mm, (px, py)
    assert abs(th - 90) <= 2, th
    assert not gui.window.commissioning.point_pick.active  # type: ignore[union-attr]  # one pick per start
    type_into(gui, w.name_entry, "Picked")
    click(gui, w.add_button)
    pump(
        lambda: w.draft is not None and w.draft.find("Picked") is not None, 5, "the picked goal in the draft"
    )
    gui.shot("picked-goal-drawn")
    assert "Picked" not in gui.model.navigation.value.goals


def test_in_german_a_picked_point_and_typed_numbers_read_as_german_writes_them(
    german: None, gui: Gui, sim: SimThread
) -> None:
    """The map editor in the operator's language: the picked point said with German's decimal comma
    (base.units), a number typed with one read as meant, the row saying where in German too."""
    from gi.repository import GdkX11, Graphene

    w = open_window(gui)
    stage = gui.stage
    sx, sy = stage.viewport.to_screen(6500, 6000)
    ok, point = stage.compute_point(stage.get_native(), Graphene.Point().init(sx, sy))
    assert ok
    dx, dy = stage.get_native().get_surface_transform()
    x, y = round(point.x + dx), round(point.y + dy)
    edit_xid = str(GdkX11.X11Surface.get_xid(w.get_surface()))
    gui.xdotool("windowmove", "--sync", edit_xid, "640", "0")  # off the map's left half
    idle(0.3)
    click(gui, w.pick_button)
    pump(lambda: gui.window.commissioning.point_pick.active, 3, "the pick mode")  # type: ignore[union-attr]
    xid = str(GdkX11.X11Surface.get_xid(gui.window.get_surface()))
    gui.xdotool("mousemove", "--window", xid, str(x), str(y))
    idle(0.2)
    gui.xdotool("click", "1")
    pump(lambda: w.fields["x"].get_text() != "", 5, "the picked point in the fields")
    pump(lambda: "Gewählt: 6," in w.news.get_text(), 5, "the pick said in German")
    assert re.search(r"Gewählt: 6,\d\d; 6,\d\d m", w.news.get_text()), w.news.get_text()
    for name, typed in (("x", "2500,5"), ("y", "3.000"), ("th", "45,4")):  # German: 3.000 is three thousand
        type_into(gui, w.fields[name], typed)
    type_into(gui, w.name_entry, "Deutsch")
    press(
        gui, w.add_button
    )  # German's longer words scroll it below the window's fold: the keyboard reaches it
    pump(lambda: w.draft is not None and w.draft.find("Deutsch") is not None, 5, "the typed goal")
    goal = w.draft.find("Deutsch")  # type: ignore[union-attr]
    assert goal is not None and abs(goal.x - 2500.5) <= 0.5 and goal.y == 3000 and abs(goal.th - 45.4) <= 0.4
    gui.screen_shot("map-editor-in-german")  # the editor is a window of its own: the screen shows it
    rows = [label.get_text() for label in labels_under(w.rows)]
    assert any(re.search(r"Deutsch.* bei 2,50; 3,00 m 45°", text) for text in rows), rows
    type_into(gui, w.fields["x"], "zwei")
    press(gui, w.add_button)
    pump(lambda: "keine Zahl" in w.news.get_text(), 5, "a word that is no number, said in German")
