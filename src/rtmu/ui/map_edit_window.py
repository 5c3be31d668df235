"""Editing the robot's map as a draft (ARIA's ``ArMapChanger``): goals, docks, forbidden lines and areas.

Server ▸ Edit the map… opens a window of its own over the map. Edits are kept in a
:class:`~rtmu.mapedit.MapDraft` — shown as a draft, with undo and redo — and change nothing until
Apply sends them as ONE ``processMapChanges`` series (``ApplyMapChanges`` to the selected robot,
guarded by the map's id). The server's ``mapUpdated`` then reloads the window's map; a draft Applied
starts afresh on it. When the map changes under an open draft (another client's change), the draft is
kept, rebased on the new map, and what changed — and which edits now conflict — is said plainly. A
change the server refuses leaves its map as it was and the draft as it is.

What is typed is in mm and degrees; "Robot's pose" fills the fields from where the robot is, "Pick on
the map" from the next click on the map (a drag from the point sets the heading: ``map_point_pick``). While
the draft holds edits, the map draws the draft's goals, docks and forbidden lines and areas instead
of the robot's, and a banner says a draft is shown, not applied (``show_draft``); closing the window
shows the robot's map again.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _, ngettext, parse_number  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..base.units import coordinates, quantity  # noqa: E402
from ..client.map_changes import ChangeVerdict  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..mapedit import MapDraft, MapObject  # noqa: E402
from ..mapedit.draft import (  # noqa: E402
    DOCK,
    FORBIDDEN_AREA,
    FORBIDDEN_LINE,
    GOAL,
    GOAL_WITH_HEADING,
    DraftError,
    describe,
    object_key,
)
from ..model.observables import MapModel, MapPhase, Phase, RobotModel  # noqa: E402
from ..values.intents import ApplyMapChanges  # noqa: E402
from .layout import fit_default_size, wrapping_row  # noqa: E402
from .map_canvas_edit import TOOL_TIPS, MapCanvasEdit, Tool  # noqa: E402
from .map_point_pick import Picked  # noqa: E402
from .state_words import failure_words  # noqa: E402

EDITABLE = {t.lower() for t in (GOAL, GOAL_WITH_HEADING, DOCK, FORBIDDEN_LINE, FORBIDDEN_AREA)}
KINDS = (N_("Goal"), N_("Dock"), N_("Forbidden line"), N_("Forbidden area"))


def field_text(value: float) -> str:
    """A whole mm or degree for a field: no grouping mark and no decimal one, so it reads back in every
    language (what is typed is read by ``parse_number``: German ``2,5`` too)."""
    return str(round(value))


def editable(objects: tuple[MapObject, ...] | list[MapObject]) -> list[MapObject]:
    """The objects this window edits, in map order."""
    return [o for o in objects if o.type.lower() in EDITABLE]


class MapEditWindow(Gtk.Window):
    """See the module notes."""

    def __init__(
        self,
        parent: Gtk.Window,
        robot: SelectedRobot,
        model: RobotModel,
        show_draft: Callable[[tuple[MapObject, ...] | None, int], None] = lambda _o, _n: None,
        pick: Callable[[Picked], None] | None = None,
        canvas: MapCanvasEdit | None = None,
    ) -> None:
        super().__init__(title=_("Edit the map (draft)"), transient_for=parent, destroy_with_parent=True)
        fit_default_size(self, 620, 520, beside_map=True)
        self.robot, self.model = robot, model
        self._show_draft, self._pick, self.canvas = show_draft, pick, canvas
        """Told the draft's objects to draw on the map (None: the map's own again) and its edit count."""
        self.draft: MapDraft | None = None
        self.generation = -1
        """The map the draft is made on (``MapModel.generation``)."""
        self.applying = False
        self.applied = 0
        """Change sets the server took (tests wait for the next one)."""
        self.closed = False
        self.shown: list[MapObject] = []
        self._build()
        self._unobserve = [
            model.map.observe(self._map_changed),
            model.connection.observe(lambda *_a: self._show()),
        ]
        self._unswitch = robot.on_switch(self._switched)
        self.connect("close-request", self._closing)
        self._map_changed(MapModel(), model.map.value)
        if canvas is not None:
            canvas.attach(self)

    # -- layout -----------------------------------------------------------------------------------
    def _build(self) -> None:
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(8)
        # The state on a line of its own above the buttons, which wrap: a longer language or a phone's
        # 360 px never widens the window past its screen (tests/gui/test_pseudo_locale.py,
        # tests/gui/test_commissioning_phone.py).
        bar = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        self.state_label = Gtk.Label(xalign=0.0, hexpand=True, wrap=True)
        bar.append(self.state_label)
        buttons = wrapping_row(at_least=2)
        bar.append(buttons)
        self.undo_button = Gtk.Button(label=_("Undo"))
        self.undo_button.connect("clicked", lambda _b: self._step(undo=True))
        self.redo_button = Gtk.Button(label=_("Redo"))
        self.redo_button.connect("clicked", lambda _b: self._step(undo=False))
        self.discard_button = Gtk.Button(label=_("Discard"))
        self.discard_button.connect("clicked", lambda _b: self._discard())
        self.apply_button = Gtk.Button(label=_("Apply"))
        self.apply_button.add_css_class("suggested-action")
        self.apply_button.connect("clicked", lambda _b: self.apply())
        for b in (self.undo_button, self.redo_button, self.discard_button, self.apply_button):
            buttons.append(b)
        box.append(bar)
        box.append(self._tool_row())
        self.news = Gtk.Label(xalign=0.0, wrap=True, selectable=True)
        box.append(self.news)
        self.rows = Gtk.ListBox()
        self.rows.connect("row-selected", self._row_selected)
        scroller = Gtk.ScrolledWindow(
            vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER, min_content_height=120
        )
        scroller.set_child(self.rows)
        box.append(scroller)
        self.edits_label = Gtk.Label(xalign=0.0, wrap=True)
        self.edits_label.add_css_class("dim-label")
        box.append(self.edits_label)
        form = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        what = wrapping_row(at_least=2, at_most=5)
        self.kind = Gtk.DropDown.new_from_strings([_(k) for k in KINDS])
        self.name_entry = Gtk.Entry(placeholder_text=_("name (goals, docks)"), width_chars=12)
        self.fields: dict[str, Gtk.Entry] = {}
        what.append(self.kind)
        what.append(self.name_entry)
        here = Gtk.Button(label=_("Robot's pose"))
        here.connect("clicked", lambda _b: self._fill_from_robot())
        what.append(here)
        self.pick_button = Gtk.Button(
            label=_("Pick on the map"), tooltip_text=_("Click a point; drag for a heading")
        )
        self.pick_button.connect("clicked", lambda _b: self.pick_point(end=False))
        self.pick_end_button = Gtk.Button(
            label=_("Pick the end"), tooltip_text=_("The other end of a line or area")
        )
        self.pick_end_button.connect("clicked", lambda _b: self.pick_point(end=True))
        self.pick_button.set_sensitive(self._pick is not None)
        self.pick_end_button.set_sensitive(self._pick is not None)
        what.append(self.pick_button)
        what.append(self.pick_end_button)
        form.append(what)
        fields = Gtk.Grid(column_spacing=6, column_homogeneous=True)
        titles = {
            "x": _("x (mm)"),
            "y": _("y (mm)"),
            "th": _("heading (°)"),
            "x2": _("x2 (mm, line / area)"),
            "y2": _("y2 (mm)"),
        }
        for i, (name, title) in enumerate(titles.items()):
            fields.attach(Gtk.Label(label=title, xalign=0.0, ellipsize=Pango.EllipsizeMode.END), i, 0, 1, 1)
            entry = Gtk.Entry(width_chars=5)
            self.fields[name] = entry
            fields.attach(entry, i, 1, 1, 1)
        form.append(fields)
        actions = wrapping_row(at_least=2)
        self.add_button = Gtk.Button(label=_("Add"))
        self.add_button.connect("clicked", lambda _b: self.add())
        self.move_button = Gtk.Button(label=_("Move selected here"))
        self.move_button.connect("clicked", lambda _b: self.move_selected())
        self.rename_button = Gtk.Button(label=_("Rename selected"))
        self.rename_button.connect("clicked", lambda _b: self.rename_selected())
        self.delete_button = Gtk.Button(label=_("Delete selected"))
        self.delete_button.connect("clicked", lambda _b: self.delete_selected())
        for b in (self.add_button, self.move_button, self.rename_button, self.delete_button):
            actions.append(b)
        form.append(actions)
        box.append(form)
        # Scrolls as a whole where the screen is lower than the form (800x480, a phone held sideways):
        # every control stays reachable and the window never grows past the screen.
        page = Gtk.ScrolledWindow(hscrollbar_policy=Gtk.PolicyType.NEVER, propagate_natural_height=True)
        page.set_child(box)
        self.set_child(page)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)

    def _tool_row(self) -> Gtk.Widget:
        """What a press on the map does (``map_canvas_edit``): one of a group of toggles."""
        row = wrapping_row(at_least=2)
        row.set_max_children_per_line(len(Tool))
        self.tool_buttons: dict[Tool, Gtk.ToggleButton] = {}
        first: Gtk.ToggleButton | None = None
        for tool in Tool:
            button = Gtk.ToggleButton(label=_(tool.value), tooltip_text=_(TOOL_TIPS[tool]))
            button.set_group(first)
            first = first or button
            button.set_active(tool is Tool.PAN)
            button.set_sensitive(self.canvas is not None)
            button.connect("toggled", self._tool_toggled, tool)
            self.tool_buttons[tool] = button
            row.append(button)
        return row

    def _tool_toggled(self, button: Gtk.ToggleButton, tool: Tool) -> None:
        if button.get_active():
            self.set_tool(tool)

    def set_tool(self, tool: Tool) -> None:
        """What a press on the map does from now on (the toggles show it)."""
        if self.canvas is not None:
            self.canvas.set_tool(tool)
        if not self.tool_buttons[tool].get_active():
            self.tool_buttons[tool].set_active(True)

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, state: Gdk.ModifierType) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        if state & Gdk.ModifierType.CONTROL_MASK and keyval in (Gdk.KEY_z, Gdk.KEY_y):
            self._step(undo=keyval == Gdk.KEY_z)
            return True
        return False

    # -- the map underneath -------------------------------------------------------------------------
    def _map_changed(self, _old: MapModel, new: MapModel) -> None:
        if new.state != MapPhase.READY or new.data is None or new.generation == self.generation:
            self._show()
            return
        objects = editable(new.data.objects)
        draft, self.generation = self.draft, new.generation
        if draft is None or not draft.dirty:
            self.draft = MapDraft(objects)  # nothing of the operator's to keep: the list follows the map
        else:
            underneath = draft.rebase(objects)
            if not underneath.nothing:
                self._say(underneath.summary(), error=bool(underneath.conflicts))
        self._show()

    def _switched(self, _old: RobotSession, _new: RobotSession) -> None:
        """Another robot selected: a draft belongs to one map, so it is dropped, and said."""
        dropped = self.draft is not None and self.draft.dirty
        self.draft, self.generation = None, -1
        self._map_changed(MapModel(), self.model.map.value)
        if dropped:
            self._say(
                _("Another robot was selected: the draft made on the other map was dropped."), error=True
            )

    # -- editing ----------------------------------------------------------------------------------
    def _number(self, name: str, *, required: bool = True) -> float | None:
        text = self.fields[name].get_text().strip()
        if not text and not required:
            return None
        try:
            return parse_number(text)  # as the operator's language writes it (German: 2,5)
        except ValueError:
            raise DraftError(_("{name}: {text!r} is not a number").format(name=name, text=text)) from None

    def _edit(self, what: Any) -> bool:
        """Run one draft edit; a DraftError is said, and the draft stays as it was (False)."""
        if self.draft is None:
            self._say(_("There is no map to edit yet."), error=True)
            return False
        try:
            what(self.draft)
        except DraftError as exc:
            self._say(str(exc), error=True)
            return False
        self._say("", error=False)
        self._show()
        return True

    # -- what the map's tools ask (``map_canvas_edit.CanvasEditor``) ------------------------------
    def run_edit(self, what: Callable[[MapDraft], object]) -> bool:
        return self._edit(what)

    def drawn_objects(self) -> tuple[MapObject, ...]:
        data = self.model.map.value.data
        kept = [o for o in (data.objects if data is not None else ()) if o.type.lower() not in EDITABLE]
        return (*kept, *(self.draft.objects if self.draft is not None else ()))

    def select_object(self, obj: MapObject) -> None:
        low = obj.name.lower()
        for i, shown in enumerate(self.shown):
            if (shown.name.lower() == low) if obj.name else object_key(shown) == object_key(obj):
                self.rows.select_row(self.rows.get_row_at_index(i))
                return

    def name_for(self, stem: str) -> str:
        typed = self.name_entry.get_text().strip()
        if typed and (self.draft is None or self.draft.find(typed) is None):
            return typed
        return self.draft.free_name(_(stem)) if self.draft is not None else _(stem)

    def refresh(self) -> None:
        self._show()

    def add(self) -> None:
        kind = KINDS[self.kind.get_selected()]
        name = self.name_entry.get_text().strip()

        def run(d: MapDraft) -> None:
            x, y = self._number("x"), self._number("y")
            assert x is not None and y is not None
            if kind == "Goal":
                d.add_goal(name, x, y, self._number("th", required=False))
            elif kind == "Dock":
                d.add_dock(name, x, y, self._number("th") or 0.0)
            else:
                x2, y2 = self._number("x2"), self._number("y2")
                assert x2 is not None and y2 is not None
                (d.add_forbidden_line if kind == "Forbidden line" else d.add_forbidden_area)(x, y, x2, y2)

        self._edit(run)

    def selected(self) -> MapObject | None:
        row = self.rows.get_selected_row()
        return self.shown[row.get_index()] if row is not None and row.get_index() < len(self.shown) else None

    def move_selected(self) -> None:
        obj = self.selected()
        if obj is None or not obj.name:
            self._say(
                _("Select a goal or dock to move (a line or area is deleted and drawn again)."), error=True
            )
            return

        def run(d: MapDraft) -> None:
            x, y = self._number("x"), self._number("y")
            assert x is not None and y is not None
            d.move(obj.name, x, y)
            th = self._number("th", required=False)
            if th is not None:
                d.turn(obj.name, th)

        self._edit(run)

    def rename_selected(self) -> None:
        obj = self.selected()
        if obj is None or not obj.name:
            self._say(_("Select a goal or dock to rename."), error=True)
            return
        self._edit(lambda d: d.rename(obj.name, self.name_entry.get_text().strip()))

    def delete_selected(self) -> None:
        obj = self.selected()
        if obj is not None:
            self._edit(lambda d: d.delete_object(obj))

    def _step(self, *, undo: bool) -> None:
        if self.draft is not None:
            (self.draft.undo if undo else self.draft.redo)()
            self._show()

    def _discard(self) -> None:
        if self.draft is not None:
            self.draft.clear()
            self._say(_("The draft was discarded; the robot's map is unchanged."), error=False)
            self._show()

    def _fill_from_robot(self) -> None:
        pose = self.model.robot.value
        for name, value in (("x", pose.x), ("y", pose.y), ("th", pose.th)):
            self.fields[name].set_text(field_text(value))

    def pick_point(self, *, end: bool) -> None:
        """The next click on the map fills x, y (and a dragged heading) — or x2, y2 with ``end``."""
        if self._pick is None:
            return
        self.set_tool(Tool.PAN)  # the next press is the pick's, not a tool's
        self._say(
            _("Click the map") + ("" if end else _(" (drag from the point for a heading)")), error=False
        )

        def picked(x: float, y: float, th: float | None) -> None:
            self.fields["x2" if end else "x"].set_text(field_text(x))
            self.fields["y2" if end else "y"].set_text(field_text(y))
            if th is not None and not end:
                self.fields["th"].set_text(field_text(th))
            self._say(
                _("Picked {where}").format(where=coordinates(x, y))
                + (_(", heading {heading}").format(heading=quantity(th, "deg")) if th is not None else ""),
                error=False,
            )

        self._pick(picked)

    def _row_selected(self, _box: Gtk.ListBox, _row: Gtk.ListBoxRow | None) -> None:
        obj = self.selected()
        if obj is None:
            return
        self.name_entry.set_text(obj.name)
        self.fields["x"].set_text(field_text(obj.x))
        self.fields["y"].set_text(field_text(obj.y))
        self.fields["th"].set_text(field_text(obj.th))

    # -- applying ---------------------------------------------------------------------------------
    def apply(self) -> None:
        """Send the draft as one change set; the server's verdict is said here."""
        draft = self.draft
        if draft is None or not draft.dirty or self.applying:
            return
        change = draft.change()
        self.applying = True
        self._say(_("Applying {len} edits…").format(len=len(draft.edits)), error=False)
        self._show()
        intent = ApplyMapChanges(change.removed, change.added, self.generation)
        self.robot.request(intent).add_done_callback(lambda f: GLib.idle_add(self._verdict, f))

    def _verdict(self, future: concurrent.futures.Future[Any]) -> bool:
        self.applying = False
        if self.closed:
            return False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self._say(
                _("Not applied: {value}. The draft is kept.").format(value=failure_words(error)), error=True
            )
        else:
            verdict: ChangeVerdict = future.result()
            if verdict.applied:
                self.applied += 1
                if self.draft is not None:
                    self.draft = MapDraft(self.draft.objects)  # the map now holds it: a fresh draft
                self._say(_("Applied: {words}").format(words=verdict.words), error=False)
            else:
                self._say(
                    _("The robot refused the change; its map is as it was. {words}").format(
                        words=verdict.words
                    ),
                    error=True,
                )
        self._show()
        return False

    # -- showing ----------------------------------------------------------------------------------
    def _say(self, text: str, *, error: bool) -> None:
        self.news.set_text(text)
        (self.news.add_css_class if error else self.news.remove_css_class)("error")

    def _show(self) -> None:
        draft = self.draft
        connected = self.model.connection.value.phase is Phase.CONNECTED
        while (row := self.rows.get_first_child()) is not None:
            self.rows.remove(row)
        self.shown = list(draft.objects) if draft is not None else []
        added = {object_key(o) for o in (draft.change().added if draft is not None else ())}
        for obj in self.shown:
            text = describe(obj, translated=True) + (
                ""
                if obj.from_xy
                else _(" at {where} {heading}").format(
                    where=coordinates(obj.x, obj.y), heading=quantity(obj.th, "deg")
                )
            )
            if object_key(obj) in added:
                text += _("  — draft")
            label = Gtk.Label(label=visible(text), xalign=0.0, ellipsize=Pango.EllipsizeMode.END)
            self.rows.append(label)
        edits = draft.edits if draft is not None else ()
        dirty = draft is not None and draft.dirty
        if draft is None:
            self.state_label.set_text(_("No map to edit") if connected else _("Not connected"))
        elif dirty:
            self.state_label.set_text(
                ngettext(
                    "Draft: {count} edit, not applied", "Draft: {count} edits, not applied", len(edits)
                ).format(count=len(edits))
            )
        else:
            self.state_label.set_text(_("No changes: the list is the robot's map"))
        self.edits_label.set_text("; ".join(e.label for e in edits))
        self.undo_button.set_sensitive(draft is not None and draft.can_undo)
        self.redo_button.set_sensitive(draft is not None and draft.can_redo)
        self.discard_button.set_sensitive(dirty)
        self.apply_button.set_sensitive(dirty and connected and not self.applying)
        if dirty and draft is not None:
            data = self.model.map.value.data
            kept = [o for o in (data.objects if data is not None else ()) if o.type.lower() not in EDITABLE]
            self._show_draft((*kept, *draft.objects), len(edits))  # home and the like stay as they are
        else:
            self._show_draft(None, 0)

    def _closing(self, _w: Gtk.Window) -> bool:
        self.closed = True
        self._show_draft(None, 0)  # the map shows the robot's map again
        if self.canvas is not None:
            self.canvas.attach(None)
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        self._unswitch()
        return False
