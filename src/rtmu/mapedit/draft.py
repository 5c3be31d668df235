"""A draft of map edits: goals and docks added, moved, turned, renamed, deleted; forbidden lines and areas.

The draft is a list of :class:`Edit` steps over the map's objects as last read from the server (its
*base*). It never changes the map itself: :meth:`MapDraft.change` turns the steps into one
:class:`ObjectChanges` (objects to delete, objects to add) for one ``processMapChanges``; undo and
redo walk the steps. When another client changes the map while a draft is open, :meth:`MapDraft.rebase`
takes the new objects as the base and keeps every step, and says what changed underneath and which
steps now conflict (the object they touch was changed or deleted, or a name they add was taken).

Objects are matched as ARIA's ``ArMapChanger`` matches a deletion: by name (case-insensitive) when
the object has one, otherwise by type, pose, end points, description and icon. No GTK, no network.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace

from ..base.i18n import N_, _
from ..mapfile import MapObject, object_text

MAX_COORD_MM = 1_000_000_000
"""Whole-mm coordinates beyond this (1000 km) are refused: ARIA keeps them in 32-bit integers."""
GOAL = "Goal"
GOAL_WITH_HEADING = "GoalWithHeading"
DOCK = "Dock"
FORBIDDEN_LINE = "ForbiddenLine"
FORBIDDEN_AREA = "ForbiddenArea"
NAMED_KINDS = {"goal": (GOAL, GOAL_WITH_HEADING), "dock": (DOCK,)}


class DraftError(ValueError):
    """An edit that cannot be made, and why (the draft is left as it was)."""


def object_key(obj: MapObject) -> tuple[object, ...]:
    """What identifies an object to ARIA: its name, or for an unnamed one its whole shape."""
    if obj.name:
        return ("name", obj.name.lower())
    return (
        "shape",
        obj.type.lower(),
        obj.x,
        obj.y,
        obj.th,
        obj.from_xy,
        obj.to_xy,
        obj.description,
        obj.icon,
    )


def describe(obj: MapObject, *, translated: bool = False) -> str:
    """An object in a few plain words: ``goal "Kitchen"``, ``forbidden line (0, 0)–(1000, 0)``.

    ``translated``: in the operator's language (the window); machine output (``--json``) keeps English."""
    say = _ if translated else str
    kind = {
        "goal": N_("goal"),
        "goalwithheading": N_("goal"),
        "dock": N_("dock"),
        "home": N_("home"),
        "forbiddenline": N_("forbidden line"),
        "forbiddenarea": N_("forbidden area"),
    }.get(obj.type.lower(), obj.type.lower())
    kind = say(kind) if obj.type.lower() in _KNOWN_KINDS else kind
    if obj.name:
        return say(N_('{kind} "{name}"')).format(kind=kind, name=obj.name)
    if obj.from_xy is not None and obj.to_xy is not None:
        (x1, y1), (x2, y2) = obj.from_xy, obj.to_xy
        return say(N_("{kind} ({x1:g}, {y1:g})–({x2:g}, {y2:g})")).format(
            kind=kind, x1=x1, y1=y1, x2=x2, y2=y2
        )
    return say(N_("{kind} at ({x:g}, {y:g})")).format(kind=kind, x=obj.x, y=obj.y)


_KNOWN_KINDS = frozenset({"goal", "goalwithheading", "dock", "home", "forbiddenline", "forbiddenarea"})


@dataclass(frozen=True, slots=True)
class Edit:
    """One step: ``before`` becomes ``after`` (``before`` None: added; ``after`` None: deleted)."""

    before: MapObject | None
    after: MapObject | None
    label: str


@dataclass(frozen=True, slots=True)
class ObjectChanges:
    """What a draft asks of the server: these objects deleted, these added (a move is both)."""

    removed: tuple[MapObject, ...] = ()
    added: tuple[MapObject, ...] = ()

    @property
    def empty(self) -> bool:
        return not self.removed and not self.added


@dataclass(frozen=True, slots=True)
class Conflict:
    """A step that no longer fits the map underneath it, in words."""

    edit: Edit
    reason: str

    def __str__(self) -> str:
        return f"{self.edit.label}: {self.reason}"


@dataclass(frozen=True, slots=True)
class Underneath:
    """What another client changed under an open draft (:meth:`MapDraft.rebase`)."""

    added: tuple[MapObject, ...] = ()
    removed: tuple[MapObject, ...] = ()
    changed: tuple[tuple[MapObject, MapObject], ...] = ()
    """(before, after) of objects that kept their name but moved or changed."""
    conflicts: tuple[Conflict, ...] = ()

    @property
    def nothing(self) -> bool:
        return not (self.added or self.removed or self.changed)

    def summary(self) -> str:
        """One plain sentence for the operator (empty when nothing changed)."""
        parts: list[str] = []
        if self.added:
            parts.append(
                _("added {objects}").format(
                    objects=", ".join(describe(o, translated=True) for o in self.added)
                )
            )
        if self.removed:
            parts.append(
                _("deleted {objects}").format(
                    objects=", ".join(describe(o, translated=True) for o in self.removed)
                )
            )
        if self.changed:
            parts.append(
                _("changed {objects}").format(
                    objects=", ".join(describe(after, translated=True) for _before, after in self.changed)
                )
            )
        if not parts:
            return ""
        text = _("The map was changed on the robot: ") + "; ".join(parts) + _(". Your draft is kept.")
        if self.conflicts:
            text += _(" Conflicts: {conflicts}.").format(conflicts="; ".join(str(c) for c in self.conflicts))
        return text


class MapDraft:
    """Edits over a base list of map objects, with undo and redo."""

    def __init__(self, base: Iterable[MapObject]) -> None:
        self._base = tuple(base)
        self._edits: list[Edit] = []
        self._undone: list[Edit] = []
        self._objects, self._conflicts = _replay(self._base, self._edits)

    # -- what the draft holds --------------------------------------------------------------------
    @property
    def base(self) -> tuple[MapObject, ...]:
        return self._base

    @property
    def objects(self) -> tuple[MapObject, ...]:
        """The map's objects as they will be once the draft is applied."""
        return self._objects

    @property
    def edits(self) -> tuple[Edit, ...]:
        return tuple(self._edits)

    @property
    def conflicts(self) -> tuple[Conflict, ...]:
        return self._conflicts

    @property
    def dirty(self) -> bool:
        return not self.change().empty

    @property
    def can_undo(self) -> bool:
        return bool(self._edits)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    def find(self, name: str) -> MapObject | None:
        """The object named ``name`` (case-insensitive, as ARIA matches names), in the draft."""
        low = name.lower()
        return next((o for o in self._objects if o.name and o.name.lower() == low), None)

    def free_name(self, stem: str) -> str:
        """``stem 1``, ``stem 2`` …: the first name no object of the draft has (a goal placed by a click)."""
        n = 1
        while self.find(f"{stem} {n}") is not None:
            n += 1
        return f"{stem} {n}"

    def change(self) -> ObjectChanges:
        """Net objects to delete and to add: what differs between the base and the draft."""
        return _difference(self._base, self._objects)

    # -- steps -----------------------------------------------------------------------------------
    def add_goal(self, name: str, x: float, y: float, th: float | None = None) -> Edit:
        """A goal; with a heading it is a ``GoalWithHeading`` (the robot turns to it on arrival)."""
        kind = GOAL if th is None else GOAL_WITH_HEADING
        obj = MapObject(kind, *_xy(x, y), _heading(th or 0.0), name=self._new_name(name))
        return self._push(Edit(None, obj, _('add goal "{name}"').format(name=obj.name)))

    def add_dock(self, name: str, x: float, y: float, th: float) -> Edit:
        """A charging dock, facing ``th`` (the robot drives in along it)."""
        obj = MapObject(DOCK, *_xy(x, y), _heading(th), name=self._new_name(name))
        return self._push(Edit(None, obj, _('add dock "{name}"').format(name=obj.name)))

    def add_forbidden_line(self, x1: float, y1: float, x2: float, y2: float) -> Edit:
        a, b = _xy(x1, y1), _xy(x2, y2)
        if a == b:
            raise DraftError(_("a forbidden line needs two different ends"))
        obj = MapObject(FORBIDDEN_LINE, *a, 0.0, from_xy=a, to_xy=b)
        return self._push(
            Edit(None, obj, _("add {describe}").format(describe=describe(obj, translated=True)))
        )

    def add_forbidden_area(self, x1: float, y1: float, x2: float, y2: float) -> Edit:
        """An axis-aligned area between two opposite corners (stored lower-left, upper-right, as ARIA)."""
        (ax, ay), (bx, by) = _xy(x1, y1), _xy(x2, y2)
        if ax == bx or ay == by:
            raise DraftError(_("a forbidden area needs two corners that differ in x and in y"))
        lo, hi = (min(ax, bx), min(ay, by)), (max(ax, bx), max(ay, by))
        obj = MapObject(FORBIDDEN_AREA, 0.0, 0.0, 0.0, from_xy=lo, to_xy=hi)
        return self._push(
            Edit(None, obj, _("add {describe}").format(describe=describe(obj, translated=True)))
        )

    def move(self, name: str, x: float, y: float) -> Edit:
        obj = self._named(name)
        return self._push(
            Edit(
                obj,
                replace(obj, x=_xy(x, y)[0], y=_xy(x, y)[1]),
                _("move {describe}").format(describe=describe(obj, translated=True)),
            )
        )

    def turn(self, name: str, th: float) -> Edit:
        """Set a goal's or dock's heading (a plain goal becomes a goal with heading)."""
        obj = self._named(name)
        kind = GOAL_WITH_HEADING if obj.type.lower() == "goal" else obj.type
        return self._push(
            Edit(
                obj,
                replace(obj, type=kind, th=_heading(th)),
                _("turn {describe}").format(describe=describe(obj, translated=True)),
            )
        )

    def rename(self, name: str, new_name: str) -> Edit:
        obj = self._named(name)
        if new_name.lower() == obj.name.lower():
            new = replace(obj, name=_checked_name(new_name))
        else:
            new = replace(obj, name=self._new_name(new_name))
        return self._push(
            Edit(
                obj,
                new,
                _('rename {describe} to "{name}"').format(
                    describe=describe(obj, translated=True), name=new.name
                ),
            )
        )

    def delete(self, name: str) -> Edit:
        obj = self._named(name)
        return self._push(
            Edit(obj, None, _("delete {describe}").format(describe=describe(obj, translated=True)))
        )

    def delete_object(self, obj: MapObject) -> Edit:
        """Delete an object as it is in the draft (an unnamed forbidden line or area)."""
        if obj not in self._objects:
            raise DraftError(
                _("{describe} is not on the map").format(describe=describe(obj, translated=True))
            )
        return self._push(
            Edit(obj, None, _("delete {describe}").format(describe=describe(obj, translated=True)))
        )

    def undo(self) -> Edit | None:
        if not self._edits:
            return None
        edit = self._edits.pop()
        self._undone.append(edit)
        self._refresh()
        return edit

    def redo(self) -> Edit | None:
        if not self._undone:
            return None
        edit = self._undone.pop()
        self._edits.append(edit)
        self._refresh()
        return edit

    def clear(self) -> None:
        """Drop every step (after Apply, or to discard the draft)."""
        self._edits.clear()
        self._undone.clear()
        self._refresh()

    def rebase(self, objects: Iterable[MapObject]) -> Underneath:
        """Another client changed the map: ``objects`` become the base, the steps stay; what changed, said."""
        old = self._base
        self._base = tuple(objects)
        self._refresh()
        before = {object_key(o): o for o in old}
        after = {object_key(o): o for o in self._base}
        return Underneath(
            added=tuple(o for k, o in after.items() if k not in before),
            removed=tuple(o for k, o in before.items() if k not in after),
            changed=tuple((before[k], o) for k, o in after.items() if k in before and before[k] != o),
            conflicts=self._conflicts,
        )

    # -- inside ----------------------------------------------------------------------------------
    def _push(self, edit: Edit) -> Edit:
        if edit.after is not None:
            try:
                object_text(edit.after)
            except ValueError as exc:
                said = _("this cannot be written into an ARIA map: {error}").format(error=exc)
                raise DraftError(said) from None
        self._edits.append(edit)
        self._undone.clear()
        self._refresh()
        return edit

    def _refresh(self) -> None:
        self._objects, self._conflicts = _replay(self._base, self._edits)

    def _named(self, name: str) -> MapObject:
        obj = self.find(name)
        if obj is None:
            names = ", ".join(o.name for o in self._objects if o.name) or "none"
            raise DraftError(
                _('no goal or dock named "{name}" on the map (named objects: {names})').format(
                    name=name, names=names
                )
            )
        return obj

    def _new_name(self, name: str) -> str:
        name = _checked_name(name)
        taken = self.find(name)
        if taken is not None:
            raise DraftError(
                _("the map already has {describe}: names must differ (ARIA matches them by name)").format(
                    describe=describe(taken, translated=True)
                )
            )
        return name


def _checked_name(name: str) -> str:
    name = name.strip()
    if not name:
        raise DraftError(_("a goal or dock needs a name"))
    if '"' in name or any(ord(c) < 32 for c in name):
        raise DraftError(_("a name cannot hold quotes or control characters: {name!r}").format(name=name))
    try:
        name.encode("latin-1")
    except UnicodeEncodeError:
        raise DraftError(_("ARIA map names are latin-1 text: {name!r}").format(name=name)) from None
    return name


def _xy(x: float, y: float) -> tuple[float, float]:
    out = []
    for v in (x, y):
        if not math.isfinite(v) or abs(v) > MAX_COORD_MM:
            raise DraftError(
                _("{v!r} is not a map coordinate (whole mm within ±{MAX_COORD_MM})").format(
                    v=v, MAX_COORD_MM=MAX_COORD_MM
                )
            )
        out.append(float(round(v)))
    return out[0], out[1]


def _heading(th: float) -> float:
    if not math.isfinite(th):
        raise DraftError(_("{th!r} is not a heading in degrees").format(th=th))
    th = math.fmod(th, 360.0)
    if th > 180.0:
        th -= 360.0
    elif th <= -180.0:
        th += 360.0
    return round(th, 6) + 0.0


def _replay(
    base: Sequence[MapObject], edits: Sequence[Edit]
) -> tuple[tuple[MapObject, ...], tuple[Conflict, ...]]:
    """The objects after ``edits``, and the steps that did not fit (skipped or applied over a change)."""
    objects = list(base)
    conflicts: list[Conflict] = []
    for edit in edits:
        if edit.before is None:
            assert edit.after is not None
            key = object_key(edit.after)
            if any(object_key(o) == key for o in objects):
                conflicts.append(
                    Conflict(
                        edit,
                        _("{describe} is already on the map (added by someone else)").format(
                            describe=describe(edit.after, translated=True)
                        ),
                    )
                )
                continue
            objects.append(edit.after)
            continue
        if edit.before in objects:
            at = objects.index(edit.before)
        else:
            key = object_key(edit.before)
            at = next((i for i, o in enumerate(objects) if object_key(o) == key), -1)
            if at < 0:
                conflicts.append(
                    Conflict(
                        edit,
                        _("{describe} was deleted by someone else").format(
                            describe=describe(edit.before, translated=True)
                        ),
                    )
                )
                continue
            conflicts.append(
                Conflict(
                    edit,
                    _("{describe} was changed by someone else").format(
                        describe=describe(edit.before, translated=True)
                    ),
                )
            )
        if edit.after is None:
            del objects[at]
        else:
            clash = object_key(edit.after)
            if edit.after.name and any(object_key(o) == clash for i, o in enumerate(objects) if i != at):
                conflicts.append(
                    Conflict(
                        edit,
                        _("{describe} is already on the map (added by someone else)").format(
                            describe=describe(edit.after, translated=True)
                        ),
                    )
                )
                continue
            objects[at] = edit.after
    return tuple(objects), tuple(conflicts)


def _difference(base: Sequence[MapObject], now: Sequence[MapObject]) -> ObjectChanges:
    """Objects only in ``base`` (to delete) and only in ``now`` (to add), counting duplicates."""
    left = Counter(now)
    removed: list[MapObject] = []
    for obj in base:
        if left[obj] > 0:
            left[obj] -= 1
        else:
            removed.append(obj)
    added: list[MapObject] = []
    for obj in now:
        if left[obj] > 0:
            left[obj] -= 1
            added.append(obj)
    return ObjectChanges(tuple(removed), tuple(added))
