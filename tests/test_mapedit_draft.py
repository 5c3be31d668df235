"""The map-edit draft (no display, no network): edits, undo and redo, the change, another client's change."""

from __future__ import annotations

import pytest

from rtmu.mapedit import DraftError, MapDraft, describe
from rtmu.mapfile import MapObject

HOME = MapObject("RobotHome", 0, 0, 0, name="Home")
KITCHEN = MapObject("Goal", 1000, 2000, 0, name="Kitchen")
DOCK = MapObject("Dock", 800, 6000, 180, name="Charger")
WALL = MapObject("ForbiddenLine", 0, -1000, 0, from_xy=(0, -1000), to_xy=(3000, -1000))
BASE = (HOME, KITCHEN, DOCK, WALL)


def test_a_fresh_draft_changes_nothing() -> None:
    draft = MapDraft(BASE)
    assert draft.objects == BASE and draft.change().empty and not draft.dirty
    assert not draft.can_undo and not draft.can_redo


def test_adding_goals_docks_and_forbidden_shapes() -> None:
    draft = MapDraft(BASE)
    draft.add_goal("Lab", 5000.4, -200, None)
    draft.add_goal("Door", 100, 200, 450)
    draft.add_dock("Second dock", 10, 20, -90)
    draft.add_forbidden_line(0, 0, 1000, 0)
    draft.add_forbidden_area(500, 900, -500, 100)
    added = draft.change().added
    assert added == (
        MapObject("Goal", 5000, -200, 0, name="Lab"),
        MapObject("GoalWithHeading", 100, 200, 90, name="Door"),
        MapObject("Dock", 10, 20, -90, name="Second dock"),
        MapObject("ForbiddenLine", 0, 0, 0, from_xy=(0, 0), to_xy=(1000, 0)),
        MapObject("ForbiddenArea", 0, 0, 0, from_xy=(-500, 100), to_xy=(500, 900)),  # lower-left, upper-right
    )
    assert draft.change().removed == ()
    assert [e.label for e in draft.edits][:2] == ['add goal "Lab"', 'add goal "Door"']


def test_move_turn_rename_and_delete_are_a_deletion_and_an_addition() -> None:
    draft = MapDraft(BASE)
    draft.move("kitchen", 1500, 2500)  # names match ignoring case, as ARIA matches them
    draft.turn("Kitchen", -30)
    draft.rename("Kitchen", "Galley")
    draft.delete("Charger")
    change = draft.change()
    assert change.removed == (KITCHEN, DOCK)
    assert change.added == (MapObject("GoalWithHeading", 1500, 2500, -30, name="Galley"),)
    assert draft.find("galley") is not None and draft.find("Kitchen") is None


def test_undo_and_redo_walk_the_steps_and_a_new_step_forgets_the_redo() -> None:
    draft = MapDraft(BASE)
    draft.add_goal("Lab", 1, 2)
    draft.move("Lab", 3, 4)
    assert draft.find("Lab") == MapObject("Goal", 3, 4, 0, name="Lab")
    undone = draft.undo()
    assert undone is not None and undone.label == 'move goal "Lab"'
    assert draft.find("Lab") == MapObject("Goal", 1, 2, 0, name="Lab") and draft.can_redo
    draft.undo()
    assert draft.change().empty and draft.undo() is None
    draft.redo()
    draft.redo()
    assert draft.find("Lab") == MapObject("Goal", 3, 4, 0, name="Lab") and draft.redo() is None
    draft.undo()
    draft.delete("Home")
    assert not draft.can_redo
    assert draft.change().removed == (HOME,) and [o.name for o in draft.change().added] == ["Lab"]


def test_adding_then_deleting_cancels_out() -> None:
    draft = MapDraft(BASE)
    draft.add_goal("Lab", 1, 2)
    draft.delete("Lab")
    draft.delete_object(WALL)
    assert draft.change().added == () and draft.change().removed == (WALL,)


@pytest.mark.parametrize(
    ("edit", "why"),
    [
        (lambda d: d.add_goal("Kitchen", 0, 0), 'already has goal "Kitchen"'),
        (lambda d: d.add_goal("KITCHEN", 0, 0), "already has"),
        (lambda d: d.add_goal("  ", 0, 0), "needs a name"),
        (lambda d: d.add_goal('Say "hi"', 0, 0), "quotes"),
        (lambda d: d.add_goal("Bell\x07", 0, 0), "control characters"),
        (lambda d: d.add_goal("Café ☕", 0, 0), "latin-1"),
        (lambda d: d.add_goal("Far", 1e12, 0), "not a map coordinate"),
        (lambda d: d.add_goal("Nan", float("nan"), 0), "not a map coordinate"),
        (lambda d: d.add_dock("D", 0, 0, float("inf")), "not a heading"),
        (lambda d: d.move("Nowhere", 0, 0), 'no goal or dock named "Nowhere"'),
        (lambda d: d.rename("Kitchen", "Home"), "already has"),
        (lambda d: d.add_forbidden_line(5, 5, 5, 5), "two different ends"),
        (lambda d: d.add_forbidden_area(0, 0, 0, 10), "differ in x and in y"),
        (lambda d: d.delete_object(MapObject("Goal", 9, 9, 0, name="Ghost")), "not on the map"),
    ],
)
def test_edits_that_do_not_fit_are_refused_and_leave_the_draft_alone(edit, why: str) -> None:
    draft = MapDraft(BASE)
    draft.add_goal("Lab", 1, 2)
    before = (draft.objects, draft.edits)
    with pytest.raises(DraftError, match=why):
        edit(draft)
    assert (draft.objects, draft.edits) == before


def test_a_rename_may_change_only_the_case() -> None:
    draft = MapDraft(BASE)
    draft.rename("Kitchen", "KITCHEN")
    assert draft.change().added == (MapObject("Goal", 1000, 2000, 0, name="KITCHEN"),)


def test_another_clients_change_keeps_the_draft_and_says_what_changed_underneath() -> None:
    draft = MapDraft(BASE)
    draft.add_goal("Lab", 1, 2)
    draft.move("Kitchen", 1500, 2500)
    theirs = (
        HOME,
        MapObject("Goal", 1000, 2100, 0, name="Kitchen"),
        MapObject("Goal", 7, 7, 0, name="Porch"),
    )
    under = draft.rebase(theirs)
    assert under.added == (MapObject("Goal", 7, 7, 0, name="Porch"),)
    assert set(under.removed) == {DOCK, WALL}
    assert under.changed == ((KITCHEN, theirs[1]),)
    assert [str(c) for c in under.conflicts] == [
        'move goal "Kitchen": goal "Kitchen" was changed by someone else'
    ]
    text = under.summary()
    assert text.startswith('The map was changed on the robot: added goal "Porch"')
    assert "Your draft is kept" in text and "Conflicts: move goal" in text
    # the draft still holds both edits, now over the new map: the move wins over their change
    assert draft.base == theirs
    assert draft.change().removed == (theirs[1],)
    assert {o.name for o in draft.change().added} == {"Lab", "Kitchen"}


def test_conflicts_name_deleted_objects_and_names_taken_by_someone_else() -> None:
    draft = MapDraft(BASE)
    draft.add_goal("Lab", 1, 2)
    draft.delete("Charger")
    under = draft.rebase((HOME, KITCHEN, WALL, MapObject("Goal", 9, 9, 0, name="lab")))
    reasons = sorted(str(c) for c in under.conflicts)
    assert reasons == [
        'add goal "Lab": goal "Lab" is already on the map (added by someone else)',
        'delete dock "Charger": dock "Charger" was deleted by someone else',
    ]
    assert draft.change().empty  # neither step can be made any more: nothing is sent for them
    quiet = MapDraft(BASE).rebase(BASE)
    assert quiet.nothing and quiet.summary() == ""


def test_a_big_base_is_handled_without_quadratic_work() -> None:
    base = [MapObject("Goal", i, 0, 0, name=f"g{i}") for i in range(100_000)]
    draft = MapDraft(base)
    draft.add_goal("new", 1, 1)
    draft.delete("g5")
    change = draft.change()
    assert change.removed == (base[5],) and [o.name for o in change.added] == ["new"]


def test_objects_are_described_in_plain_words() -> None:
    assert describe(KITCHEN) == 'goal "Kitchen"'
    assert describe(WALL) == "forbidden line (0, -1000)–(3000, -1000)"
    assert describe(MapObject("ForbiddenArea", 0, 0, 0, from_xy=(1, 2), to_xy=(3, 4))) == (
        "forbidden area (1, 2)–(3, 4)"
    )
