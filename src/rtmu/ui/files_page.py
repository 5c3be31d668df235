"""The robot's files (ARIA's ``ArServerFileUtils``): folders, sizes, dates; download, upload, delete.

A window of its own (menu: Server ▸ Files on the robot…), so typing in it never drives, and
``stop_keys`` gives it Space like every other surface. It asks through intents to the *selected*
robot (``ListFiles``, ``DownloadFile``, ``UploadFile``, ``DeleteFile``) and follows the selection.
Every name shown comes from the robot and is set as plain text; the client already refused a
listing holding a name that is not one plain file name, and the page says so.

A ``.map`` file can be made the robot's map (``SwitchMap``: ARNL's ``Files/Map``, then ``checkMap``),
after a question; the window's map reloads on the server's ``mapUpdated``.

Nothing is lost by a click: a delete asks first, naming the file; a download into a folder that
already holds the name asks before replacing it (the client writes to a hidden file beside it and
renames it only when complete); an upload over a file the robot lists asks too. Transfers show a
progress bar each (``TransfersChanged``, published at most ten times a second). A feature the
server does not offer to this user is greyed with the reason, never an error. At most
:data:`MAX_ROWS` entries are shown (a listing of 10⁵ entries costs the page that many rows, not more).
"""

from __future__ import annotations

import concurrent.futures
from pathlib import Path
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..client.config_care import map_param_problem  # noqa: E402
from ..client.remote_files import Listing, local_name, wire_name  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import ConnectionState, Phase, RobotModel  # noqa: E402
from ..protocol.payloads.files import DirEntry  # noqa: E402
from ..values.commission import TransfersState  # noqa: E402
from ..values.intents import DeleteFile, DownloadFile, FetchConfig, Intent, ListFiles, SwitchMap, UploadFile  # noqa: E402
from . import accessible  # noqa: E402
from .confirm import Confirm  # noqa: E402
from .files_text import greyed, human_size, parent_of, remote_join, transfer_text, when  # noqa: E402
from .layout import fit_default_size, wrapping_row  # noqa: E402
from .state_words import failure_words  # noqa: E402

MAX_ROWS = 1000
"""Entries shown at once; the rest are counted in the status line."""


class FilesPage(Gtk.Window):
    """See the module notes. ``downloads``: where downloads go until the operator picks a folder."""

    def __init__(
        self, parent: Gtk.Window, robot: SelectedRobot, model: RobotModel, *, downloads: Path
    ) -> None:
        super().__init__(
            title=_("Files on the robot"), transient_for=parent, modal=False, destroy_with_parent=True
        )
        fit_default_size(self, 640, 460)
        self.robot, self.model = robot, model
        self.folder = ""
        """The folder shown, relative to the one the robot shares ("" is that one)."""
        self.listing: Listing | None = None
        self.shown: list[DirEntry] = []
        """The entries on screen, in row order."""
        self.listings = self.downloads = 0
        """Listings and downloads finished (tests wait for the next one)."""
        self.closed = False
        self.confirm: Confirm | None = None
        """The confirmation open now (delete, replace), if any."""
        self.map_param: str | None = None
        """Why this robot's configuration cannot switch maps ("" when it can; None until read)."""
        self._build(downloads)
        self._unobserve = [
            model.transfers.observe(lambda _o, new: self._show_transfers(new)),
            model.connection.observe(self._connection_changed),
        ]
        self._unswitch = robot.on_switch(self._robot_switched)
        self.connect("close-request", self._closing)
        self._update_greyed()
        self._check_map_param()
        self.refresh()

    # -- layout -----------------------------------------------------------------------------------
    def _build(self, downloads: Path) -> None:
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(8)
        bar = Gtk.Box(spacing=8)
        self.up_button = Gtk.Button(icon_name="go-up-symbolic", tooltip_text=_("The folder above"))
        accessible.name(self.up_button, _("The folder above"))
        self.up_button.connect("clicked", lambda _b: self.open_folder(parent_of(self.folder)))
        bar.append(self.up_button)
        self.path_label = Gtk.Label(xalign=0.0, hexpand=True, ellipsize=Pango.EllipsizeMode.START)
        bar.append(self.path_label)
        self.refresh_button = Gtk.Button(label=_("Refresh"))
        self.refresh_button.connect("clicked", lambda _b: self.refresh())
        bar.append(self.refresh_button)
        box.append(bar)
        self.reason = Gtk.Label(xalign=0.0, wrap=True)
        self.reason.add_css_class("dim-label")
        box.append(self.reason)
        self.rows = Gtk.ListBox(activate_on_single_click=False)
        self.rows.connect("row-activated", self._row_activated)
        self.rows.connect("row-selected", lambda *_a: self._update_greyed())
        scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_child(self.rows)
        box.append(scroller)
        local = Gtk.Box(spacing=8)
        local.append(Gtk.Label(label=_("Downloads go to"), wrap=True, max_width_chars=10))
        self.local_entry = Gtk.Entry(text=str(downloads), hexpand=True, width_chars=8)
        local.append(self.local_entry)
        self.choose_button = Gtk.Button(label=_("Choose…"))
        self.choose_button.connect("clicked", lambda _b: self._choose_folder())
        local.append(self.choose_button)
        box.append(local)
        actions = wrapping_row(at_least=2)
        self.download_button = Gtk.Button(label=_("Download"))
        self.download_button.connect("clicked", lambda _b: self.download_selected())
        self.upload_button = Gtk.Button(label=_("Upload…"))
        self.upload_button.connect("clicked", lambda _b: self._choose_upload())
        self.delete_button = Gtk.Button(label=_("Delete…"))
        self.delete_button.connect("clicked", lambda _b: self.delete_selected())
        self.use_map_button = Gtk.Button(label=_("Use as the robot's map…"))
        self.use_map_button.connect("clicked", lambda _b: self.use_selected_map())
        for button in (self.download_button, self.upload_button, self.delete_button, self.use_map_button):
            actions.append(button)
        box.append(actions)
        self.progress = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=4)
        box.append(self.progress)
        self.status = Gtk.Label(xalign=0.0, wrap=True, selectable=True)
        box.append(self.status)
        self.set_child(box)

    def _row(self, entry: DirEntry) -> Gtk.ListBoxRow:
        line = Gtk.Box(spacing=12)
        icon = "folder-symbolic" if entry.is_folder else "text-x-generic-symbolic"
        line.append(Gtk.Image(icon_name=icon))
        end = Pango.EllipsizeMode.END
        line.append(Gtk.Label(label=visible(entry.name), xalign=0.0, hexpand=True, ellipsize=end))
        size = Gtk.Label(label="" if entry.is_folder else human_size(entry.size), xalign=1.0, width_chars=9)
        line.append(size)
        line.append(Gtk.Label(label=when(entry.mtime), xalign=1.0, width_chars=16))
        return Gtk.ListBoxRow(child=line)

    # -- what the operator can do now ----------------------------------------------------------------
    def _greyed(self) -> dict[str, str]:
        conn = self.model.connection.value
        return greyed(conn.offers, conn.phase is Phase.CONNECTED)

    def _update_greyed(self) -> None:
        missing = self._greyed()
        entry = self.selected()
        is_file = entry is not None and entry.is_file
        self.download_button.set_sensitive("download" not in missing and is_file)
        self.upload_button.set_sensitive("upload" not in missing)
        self.delete_button.set_sensitive("delete" not in missing and entry is not None)
        switching = self._switch_problem(entry)
        self.use_map_button.set_sensitive(not switching)
        self.use_map_button.set_tooltip_text(switching or _("Make this map the robot's (ARNL's Files/Map)"))
        self.refresh_button.set_sensitive("list" not in missing)
        self.up_button.set_sensitive("list" not in missing and bool(self.folder))
        for button, feature in (
            (self.download_button, "download"),
            (self.upload_button, "upload"),
            (self.delete_button, "delete"),
        ):
            reason = missing.get(feature)
            if reason:
                button.set_tooltip_text(reason)
            else:
                button.set_has_tooltip(False)
        said = list(dict.fromkeys(missing.values()))  # once each, in the page's order
        self.reason.set_text("\n".join(said))
        self.reason.set_visible(bool(said))

    def _switch_problem(self, entry: DirEntry | None) -> str:
        """Why the selection cannot become the robot's map ("" when it can)."""
        conn = self.model.connection.value
        if conn.phase is not Phase.CONNECTED:
            return _("not connected to a robot")
        if not SwitchMap.offered(conn.offers):
            return _("this robot's configuration cannot be set (it offers no setConfig)")
        if self.map_param:
            return self.map_param
        if entry is None or not entry.is_file or not entry.name.lower().endswith(".map"):
            return _("select a .map file")
        return ""

    def _check_map_param(self) -> None:
        """Read the configuration once per connection: can it name the robot's map (``Files/Map``)?"""
        if self.map_param is not None or not SwitchMap.offered(self.model.connection.value.offers):
            return
        self.map_param = ""

        def read(future: concurrent.futures.Future[Any]) -> bool:
            error = None if future.cancelled() else future.exception()
            if future.cancelled() or error is not None:
                self.map_param = _("this robot's configuration could not be read ({value})").format(
                    value=failure_words(error)
                )
            else:
                self.map_param = map_param_problem(future.result())
            if not self.closed:
                self._update_greyed()
            return False

        self.robot.request(FetchConfig()).add_done_callback(lambda f: GLib.idle_add(read, f))

    def selected(self) -> DirEntry | None:
        row = self.rows.get_selected_row()
        if row is None or row.get_index() >= len(self.shown):
            return None
        return self.shown[row.get_index()]

    # -- listing ----------------------------------------------------------------------------------
    def refresh(self) -> None:
        """List the folder shown again (the selection is kept by name where it still is)."""
        self.path_label.set_text(_("Robot files") + (f" / {visible(self.folder)}" if self.folder else ""))
        if "list" in self._greyed():
            self._fill(None)
            return
        folder = self.folder
        self._ask(ListFiles(folder), lambda answer: self._listed(folder, answer), _("List"))

    def open_folder(self, folder: str) -> None:
        self.folder = folder
        self.refresh()

    def _listed(self, folder: str, listing: Listing) -> None:
        if folder != self.folder:
            return  # the operator went elsewhere meanwhile
        self._fill(listing)
        self.listings += 1

    def _fill(self, listing: Listing | None) -> None:
        kept = self.selected()
        self.listing = listing
        while (row := self.rows.get_first_child()) is not None:  # GTK 4.8 has no remove_all
            self.rows.remove(row)
        entries = listing.sorted() if listing is not None else ()
        self.shown = list(entries[:MAX_ROWS])
        for entry in self.shown:
            self.rows.append(self._row(entry))
        if kept is not None:
            for i, entry in enumerate(self.shown):
                if entry.name == kept.name:
                    self.rows.select_row(self.rows.get_row_at_index(i))
        if listing is not None and len(entries) > MAX_ROWS:
            self._say(
                _("Showing the first {MAX_ROWS} of {len} entries").format(
                    MAX_ROWS=MAX_ROWS, len=len(entries)
                ),
                error=False,
            )
        self._update_greyed()

    def _row_activated(self, _box: Gtk.ListBox, row: Gtk.ListBoxRow) -> None:
        entry = self.shown[row.get_index()] if row.get_index() < len(self.shown) else None
        if entry is not None and entry.is_folder:
            self.open_folder(remote_join(self.folder, entry.name))
        elif entry is not None:
            self.download_selected()

    # -- download ---------------------------------------------------------------------------------
    def download_selected(self) -> None:
        """Download the selected file into the chosen folder (asking before replacing a file there)."""
        entry = self.selected()
        if entry is None or not entry.is_file or "download" in self._greyed():
            return
        folder = Path(self.local_entry.get_text()).expanduser()
        if not folder.is_dir():
            self._say(
                _("There is no folder {folder} on this computer to download into").format(folder=folder),
                error=True,
            )
            return
        target = folder / local_name(entry.name)
        remote = remote_join(self.folder, entry.name)
        if target.exists() or target.is_symlink():
            self._confirm(
                _("“{name}” already exists in {folder}. Replace it?").format(name=target.name, folder=folder),
                _("Replace"),
                lambda: self._download(remote, target, entry.size, overwrite=True),
                detail=_("The download from the robot ({human_size}) replaces it once complete.").format(
                    human_size=human_size(entry.size)
                ),
            )
            return
        self._download(remote, target, entry.size, overwrite=False)

    def _download(self, remote: str, target: Path, size: int, *, overwrite: bool) -> None:
        self._say(_("Downloading {visible}…").format(visible=visible(remote)), error=False)
        intent = DownloadFile(remote, str(target), size=size, overwrite=overwrite)

        def done(finished: Any) -> None:
            self.downloads += 1
            self._say(
                _("Downloaded {visible} to {target} ({human_size})").format(
                    visible=visible(remote), target=target, human_size=human_size(finished.size)
                ),
                error=False,
            )

        self._ask(intent, done, _("Download"))

    def _choose_folder(self) -> None:
        chooser = Gtk.FileChooserDialog(
            title=_("Download into"),
            transient_for=self,
            modal=True,
            action=Gtk.FileChooserAction.SELECT_FOLDER,
        )
        chooser.add_button(_("Cancel"), Gtk.ResponseType.CANCEL)
        chooser.add_button(_("Select"), Gtk.ResponseType.ACCEPT)
        chooser.connect("response", self._folder_chosen)
        chooser.present()

    def _folder_chosen(self, chooser: Gtk.FileChooserDialog, response: int) -> None:
        chosen = chooser.get_file() if response == Gtk.ResponseType.ACCEPT else None
        chooser.destroy()
        if chosen is not None and chosen.get_path():
            self.local_entry.set_text(str(chosen.get_path()))

    # -- upload -----------------------------------------------------------------------------------
    def _choose_upload(self) -> None:
        chooser = Gtk.FileChooserDialog(
            title=_("Upload to the robot"), transient_for=self, modal=True, action=Gtk.FileChooserAction.OPEN
        )
        chooser.add_button(_("Cancel"), Gtk.ResponseType.CANCEL)
        chooser.add_button(_("Upload"), Gtk.ResponseType.ACCEPT)
        chooser.connect("response", self._upload_chosen)
        self.chooser = chooser
        chooser.present()

    def _upload_chosen(self, chooser: Gtk.FileChooserDialog, response: int) -> None:
        chosen = chooser.get_file() if response == Gtk.ResponseType.ACCEPT else None
        chooser.destroy()
        path = chosen.get_path() if chosen is not None else None
        if path:
            self.upload(Path(path))

    def upload(self, local: Path) -> None:
        """Send ``local`` into the folder shown, under its own name (asking before replacing one)."""
        if "upload" in self._greyed():
            return
        name = wire_name(local.name)
        remote = remote_join(self.folder, name)
        if self.listing is not None and self.listing.find(name) is not None:
            self._confirm(
                _("The robot already has “{visible}”. Replace it with {local}?").format(
                    visible=visible(remote), local=local
                ),
                _("Replace"),
                lambda: self._upload(local, remote),
            )
            return
        self._upload(local, remote)

    def _upload(self, local: Path, remote: str) -> None:
        self._say(_("Uploading {name}…").format(name=local.name), error=False)

        def done(_answer: Any) -> None:
            self._say(
                _("Uploaded {local} to {visible}").format(local=local, visible=visible(remote)), error=False
            )
            self.refresh()

        self._ask(UploadFile(str(local), remote), done, _("Upload"))

    # -- delete -----------------------------------------------------------------------------------
    def delete_selected(self) -> None:
        entry = self.selected()
        if entry is None or "delete" in self._greyed():
            return
        remote = remote_join(self.folder, entry.name)
        question = (
            _("Delete the folder “{visible}” from the robot?")
            if entry.is_folder
            else _("Delete the file “{visible}” from the robot?")
        )
        self._confirm(
            question.format(visible=visible(remote)),
            _("Delete"),
            lambda: self._delete(remote),
            detail=_("It cannot be undone."),
        )

    def _delete(self, remote: str) -> None:
        def done(_answer: Any) -> None:
            self._say(_("Deleted {visible}").format(visible=visible(remote)), error=False)
            self.refresh()

        self._ask(DeleteFile(remote), done, _("Delete"))

    # -- switch map -------------------------------------------------------------------------------
    def use_selected_map(self) -> None:
        """Make the selected ``.map`` the robot's map (asked first: the robot loads it at once)."""
        entry = self.selected()
        if entry is None or self._switch_problem(entry):
            return
        remote = remote_join(self.folder, entry.name)
        self._confirm(
            _("Make “{visible}” the robot's map?").format(visible=visible(remote)),
            _("Use this map"),
            lambda: self._switch(remote),
            detail=_("The robot loads it at once (ARNL's Files/Map parameter)."),
        )

    def _switch(self, remote: str) -> None:
        self._say(_("Switching the robot to {visible}…").format(visible=visible(remote)), error=False)

        def done(updated: Any) -> None:
            if updated:
                self._say(_("The robot now uses {visible}").format(visible=visible(remote)), error=False)
            else:
                self._say(
                    _("The robot took {visible} but has not said its map changed yet").format(
                        visible=visible(remote)
                    ),
                    error=False,
                )

        self._ask(SwitchMap(remote), done, _("Switch map"))

    # -- plumbing ---------------------------------------------------------------------------------
    def _confirm(self, question: str, action: str, on_yes: Any, *, detail: str = "") -> None:
        self.confirm = Confirm(self, question, action, on_yes, detail=detail)
        self.confirm.present()

    def _ask(self, intent: Intent, on_answer: Any, what: str) -> None:
        """Send ``intent`` to the selected robot; its answer (or failure, in words) on the UI thread."""

        def done(future: concurrent.futures.Future[Any]) -> None:
            GLib.idle_add(self._answered, future, on_answer, what)

        self.robot.request(intent).add_done_callback(done)

    def _answered(self, future: concurrent.futures.Future[Any], on_answer: Any, what: str) -> bool:
        if self.closed:
            return False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self._say(_("{what} failed: {value}").format(what=what, value=failure_words(error)), error=True)
            if isinstance(future.exception(), Exception) and what == "List":
                self._fill(None)
            return False
        on_answer(future.result())
        return False

    def _say(self, text: str, *, error: bool) -> None:
        self.status.set_text(text)
        if error:
            self.status.add_css_class("error")
        else:
            self.status.remove_css_class("error")

    def _show_transfers(self, state: TransfersState) -> None:
        while (child := self.progress.get_first_child()) is not None:
            self.progress.remove(child)
        for t in state.active:
            bar = Gtk.ProgressBar(show_text=True, text=transfer_text(t))
            fraction = t.fraction
            if fraction is None:
                bar.pulse()
            else:
                bar.set_fraction(fraction)
            self.progress.append(bar)

    def _connection_changed(self, old: ConnectionState, new: ConnectionState) -> None:
        if new.phase is not Phase.CONNECTED:
            self.map_param = None
        self._update_greyed()
        if new.phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED:
            self._check_map_param()
            self.refresh()

    def _robot_switched(self, _old: RobotSession, _new: RobotSession) -> None:
        self.folder = ""
        self.map_param = None
        self._check_map_param()
        self._update_greyed()
        self.refresh()

    def _closing(self, _w: Gtk.Window) -> bool:
        self.closed = True
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        self._unswitch()
        return False
