"""Commissioning a robot from the window: its files page, and (``scan_mode``) scanning for a map.

The window builds one :class:`Commissioning` and its actions open what it holds (Server ▸ Files on
the robot…, Server ▸ Scan a map…, Server ▸ Edit the map…); the scanning banner sits under the
toolbar. Each part asks the *selected* robot through intents (``SelectedRobot``) and follows the
selection; this class only keeps one of each open.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import _, ngettext  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..model.observables import RobotModel  # noqa: E402
from .banners import BannerStack  # noqa: E402
from .map_canvas_edit import MapCanvasEdit  # noqa: E402
from .map_point_pick import MapPointPick  # noqa: E402
from .mapview import MapStage  # noqa: E402
from .scan_mode import ScanBar  # noqa: E402

if TYPE_CHECKING:  # the files page and the map editor are imported when first opened (issue 28)
    from ..mapedit import MapObject
    from .files_page import FilesPage
    from .map_edit_window import MapEditWindow

DRAFT_TOPIC = "map-draft"


def default_downloads() -> Path:
    """Where downloads go until the operator picks a folder: ~/Downloads where it exists, else ~."""
    home = Path.home()
    downloads = home / _("Downloads")
    return downloads if downloads.is_dir() else home


class Commissioning:
    """See the module notes."""

    def __init__(
        self,
        window: Gtk.Window,
        robot: SelectedRobot,
        model: RobotModel,
        *,
        column: Gtk.Box,
        after: Gtk.Widget,
        clock: Callable[[], float],
        stage: MapStage | None = None,
        banners: BannerStack | None = None,
    ) -> None:
        self.window, self.robot, self.model = window, robot, model
        self.stage, self.banners = stage, banners
        self.point_pick = MapPointPick(stage) if stage is not None else None
        """The map editor's one-point pick on the map (None without a map stage)."""
        self.canvas_edit = MapCanvasEdit(stage) if stage is not None else None
        """The map editor's tools on the map itself (None without a map stage)."""
        self.files_page: FilesPage | None = None
        """The files page last opened."""
        self.map_edit: MapEditWindow | None = None
        """The map editing window last opened."""
        self.scan_bar = ScanBar(window, robot, model, clock)
        """The scanning banner, in the window's ``column`` right under ``after`` (the toolbar)."""
        column.insert_child_after(self.scan_bar, after)

    def edit_map(self) -> None:
        """Server ▸ Edit the map…: one draft window at a time."""
        if self.map_edit is None or self.map_edit.closed:
            pick = self.point_pick.start if self.point_pick is not None else None
            from .map_edit_window import MapEditWindow

            self.map_edit = MapEditWindow(
                self.window, self.robot, self.model, self._show_draft, pick, self.canvas_edit
            )
        self.map_edit.present()

    def _show_draft(self, objects: tuple[MapObject, ...] | None, edits: int) -> None:
        """The map draws a draft (or the robot's map again), and a banner says a draft is shown."""
        if self.stage is not None:
            self.stage.draft_objects = list(objects) if objects is not None else None
            self.stage.queue_draw()
        if self.banners is None:
            return
        if objects is None:
            self.banners.dismiss(DRAFT_TOPIC)
        else:
            text = ngettext(
                "The map shows a draft ({edits} edit), not applied: Apply or Discard in Edit the map",
                "The map shows a draft ({edits} edits), not applied: Apply or Discard in Edit the map",
                edits,
            ).format(edits=edits)
            self.banners.tell(DRAFT_TOPIC, "info", text, timeout=None)

    def scan(self) -> None:
        """Server ▸ Scan a map…"""
        self.scan_bar.open_dialog()

    def show_files(self) -> None:
        """The robot's files (a window of its own): one at a time."""
        page = self.files_page
        if page is None or page.closed:
            downloads = default_downloads()
            from .files_page import FilesPage

            page = self.files_page = FilesPage(self.window, self.robot, self.model, downloads=downloads)
        page.present()

    def close(self) -> None:
        self.scan_bar.close()
        if self.point_pick is not None:
            self.point_pick.cancel()
        if self.canvas_edit is not None:
            self.canvas_edit.attach(None)
        for page in (self.files_page, self.map_edit):
            if page is not None and not page.closed:
                page.close()
