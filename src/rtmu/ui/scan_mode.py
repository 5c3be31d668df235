"""Scanning for a map from the window (ARIA's ``ArServerHandlerMapping``): name, start, drive, stop, download.

Server ▸ Scan a map… opens :class:`ScanDialog` (a name, Start). While the robot scans — started
here, by another client, or before this connection — :class:`ScanBar` sits under the toolbar:
"Scanning… 1:42, 14.2 m driven" with Loop start / Loop end (tags in the log where a loop closes) and
Stop. The operator drives as usual (keys, D-pad, gamepad); every intent that would move the robot
on its own is refused by the controller's guard with the reason (``control.scan_rule``). STOP is the
header's, always on screen, and Space stops from every surface as always.

Once the scan ends, the bar offers "Download the scan…" into a folder the operator picks (asking
before replacing a file there), through ``getFile`` like the files page. The time is counted from
when this window saw the scan start, the distance from the robot's poses since (a jump of metres —
a relocalisation — is not driving: ``client.scan.ScanProgress``).
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, GLib, Gtk  # noqa: E402

from ..base.i18n import _, error_words  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..client.scan import SCAN_FEATURES, ScanProgress, scan_name  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import Phase, RobotModel, RobotState  # noqa: E402
from ..values.commission import ScanState, TransfersState  # noqa: E402
from ..values.intents import DownloadFile, Intent, StartScan, StopScan, TagScanLoop  # noqa: E402
from . import accessible  # noqa: E402
from .confirm import Confirm  # noqa: E402
from .files_text import human_size, transfer_text  # noqa: E402
from .state_words import failure_words  # noqa: E402

REFRESH_MS = 500
"""How often the running time is redrawn while scanning."""


def scan_greyed(model: RobotModel) -> str:
    """Why a scan cannot be started now ("" when it can)."""
    conn = model.connection.value
    if conn.phase is not Phase.CONNECTED:
        return _("not connected to a robot")
    if not model.scan.value.offered:
        return SCAN_FEATURES["scan"][1] + _(" — or this user may not use it")
    if model.scan.value.scanning:
        return _("a scan is already running ({value})").format(
            value=model.scan.value.file_name or model.scan.value.name
        )
    return ""


class ScanDialog(Gtk.Window):
    """A name and Start; a refusal (a bad name, the robot's answer) is said here and the dialog stays."""

    def __init__(
        self, parent: Gtk.Window, model: RobotModel, start: Callable[[str], concurrent.futures.Future[Any]]
    ):
        super().__init__(title=_("Scan a map"), transient_for=parent, modal=False, destroy_with_parent=True)
        self.set_resizable(False)
        self._start = start
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=8)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(12)
        box.append(
            Gtk.Label(
                label=_("Name the scan, start it, then drive the robot round the place."),
                xalign=0.0,
                wrap=True,
                max_width_chars=40,
            )
        )
        self.name_entry = Gtk.Entry(placeholder_text=_("e.g. ground floor"), activates_default=True)
        box.append(self.name_entry)
        self.reason = Gtk.Label(xalign=0.0, wrap=True, max_width_chars=48)
        box.append(self.reason)
        buttons = Gtk.Box(spacing=8, halign=Gtk.Align.END)
        cancel = Gtk.Button(label=_("Cancel"))
        cancel.connect("clicked", lambda _b: self.close())
        self.start_button = Gtk.Button(label=_("Start"))
        self.start_button.add_css_class("suggested-action")
        self.start_button.connect("clicked", lambda _b: self.submit())
        buttons.append(cancel)
        buttons.append(self.start_button)
        box.append(buttons)
        self.set_child(box)
        self.set_default_widget(self.start_button)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        greyed = scan_greyed(model)
        if greyed:
            self.start_button.set_sensitive(False)
            self._say(_("Cannot scan: {greyed}").format(greyed=greyed), error=False)

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        return False

    def _say(self, text: str, *, error: bool) -> None:
        self.reason.set_text(text)
        (self.reason.add_css_class if error else self.reason.remove_css_class)("error")

    def submit(self) -> None:
        if not self.start_button.get_sensitive():
            return
        try:
            name = scan_name(self.name_entry.get_text().strip())
            if not name:
                raise ValueError(_("give the scan a name"))
        except ValueError as exc:
            self._say(error_words(exc), error=True)
            return
        self.start_button.set_sensitive(False)
        self._say(_("Starting…"), error=False)
        self._start(name).add_done_callback(lambda f: GLib.idle_add(self._started, f))

    def _started(self, future: concurrent.futures.Future[Any]) -> bool:
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self.start_button.set_sensitive(True)
            self._say(_("The scan did not start: {value}").format(value=failure_words(error)), error=True)
        else:
            self.close()
        return False


class ScanBar(Gtk.Revealer):
    """The scanning banner under the toolbar (see the module notes); hidden when there is nothing to say."""

    def __init__(
        self, parent: Gtk.Window, robot: SelectedRobot, model: RobotModel, clock: Callable[[], float]
    ):
        super().__init__(transition_type=Gtk.RevealerTransitionType.SLIDE_DOWN, reveal_child=False)
        self.parent, self.robot, self.model, self.clock = parent, robot, model, clock
        self.progress: ScanProgress | None = None
        self.offer_file = ""
        """The ended scan the bar offers to download ("" once dismissed)."""
        self.dialog: ScanDialog | None = None
        self.confirm: Confirm | None = None
        self.chooser: Gtk.FileChooserDialog | None = None
        self.loop_open = False
        self.downloads = 0
        # The words and the buttons side by side, the buttons under the words on a narrow (phone) window.
        box = Gtk.FlowBox(
            selection_mode=Gtk.SelectionMode.NONE, min_children_per_line=1, max_children_per_line=2,
            column_spacing=8, row_spacing=4, homogeneous=False,
        )  # fmt: skip
        box.add_css_class("scan-bar")
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(4)
        self.label = Gtk.Label(xalign=0.0, hexpand=True, wrap=True)
        buttons = Gtk.Box(spacing=8, halign=Gtk.Align.END, hexpand=True)
        self.loop_start = Gtk.Button(
            label=_("Loop start"), tooltip_text=_("Here a loop begins (the log is tagged)")
        )
        self.loop_start.connect("clicked", lambda _b: self._tag(True))
        self.loop_end = Gtk.Button(label=_("Loop end"), tooltip_text=_("Back where the loop began"))
        self.loop_end.connect("clicked", lambda _b: self._tag(False))
        # Not red: STOP is the only red button near the header (ui.bars); this one ends the log, not motion.
        self.stop_scan = Gtk.Button(
            label=_("Stop scan"), tooltip_text=_("End the scan (the robot is not stopped)")
        )
        self.stop_scan.connect("clicked", lambda _b: self._stop())
        self.download = Gtk.Button(label=_("Download the scan…"))
        self.download.add_css_class("suggested-action")
        self.download.connect("clicked", lambda _b: self._choose_folder())
        self.dismiss = Gtk.Button(icon_name="window-close-symbolic", tooltip_text=_("Hide"))
        accessible.name(self.dismiss, _("Hide the scan's panel"))
        self.dismiss.connect("clicked", lambda _b: self._dismiss())
        for button in (self.loop_start, self.loop_end, self.stop_scan, self.download, self.dismiss):
            buttons.append(button)
        # The scan's download as a bar on its own line: how far of how much (a pulse until its size is known).
        self.transfer_bar = Gtk.ProgressBar(show_text=True, hexpand=True)
        self.transfers_shown = 0
        """Updates of the download's progress shown (tests wait for one)."""
        for part in (self.label, buttons, self.transfer_bar):
            box.append(part)
            cell = part.get_parent()
            assert isinstance(cell, Gtk.FlowBoxChild)
            cell.set_focusable(False)  # Tab goes to the buttons, not to their cells
        cell = self.transfer_bar.get_parent()
        assert isinstance(cell, Gtk.FlowBoxChild)
        self._transfer_cell: Gtk.FlowBoxChild = cell
        cell.set_visible(False)
        self.set_child(box)
        self.note = ""
        self.message = ""
        """What the bar adds to its line: a tag taken, a download's progress or end, a failure."""
        self._unobserve = [
            model.scan.observe(lambda old, new: self._scan_changed(old, new)),
            model.robot.observe(self._robot_moved),
            model.transfers.observe(lambda _o, new: self._transfers(new)),
        ]
        self._unswitch = robot.on_switch(self._switched)
        self._timer = 0
        """The bar's clock while a scan runs; 0 otherwise (a window at rest does not wake for it)."""
        self._scan_changed(ScanState(), model.scan.value)

    # -- the dialog -------------------------------------------------------------------------------
    def open_dialog(self) -> None:
        """Server ▸ Scan a map…: one dialog at a time."""
        if self.dialog is None or not self.dialog.get_visible():
            self.dialog = ScanDialog(self.parent, self.model, lambda name: self._request(StartScan(name)))
        self.dialog.present()

    # -- what the robot says ------------------------------------------------------------------------
    def _scan_changed(self, old: ScanState, new: ScanState) -> None:
        if new.scanning and (not old.scanning or new.file_name != old.file_name):
            self.progress = ScanProgress(self.clock())
            self.progress.now = self.clock()
            self.loop_open = False
            self.note = "" if new.since is not None else _("running before this connection; ")
            self.offer_file = self.message = ""
        elif not new.scanning and old.scanning:
            self.offer_file = new.last_file
            self.note = self.message = ""
        if new.scanning and not self._timer and self._unobserve:
            self._timer = GLib.timeout_add(REFRESH_MS, self._tick)
        self._show()

    def _robot_moved(self, _old: RobotState, new: RobotState) -> None:
        if self.progress is not None and self.model.scan.value.scanning:
            self.progress.feed(new.x, new.y, self.clock())

    def _switched(self, _old: RobotSession, _new: RobotSession) -> None:
        self.progress = None
        self.offer_file = self.message = ""
        self._scan_changed(ScanState(), self.model.scan.value)

    def _tick(self) -> bool:
        if not self.model.scan.value.scanning:
            self._timer = 0
            return False
        if self.progress is not None:
            self.progress.now = max(self.progress.now, self.clock())
            self._show()
        return True

    def _show(self) -> None:
        scan = self.model.scan.value
        scanning = scan.scanning
        said = self.message
        if scanning:
            run = self.progress.text() if self.progress is not None else ""
            text = _("Scanning {visible}… {note}{run}").format(
                visible=visible(scan.file_name or scan.name), note=self.note, run=run
            )
            text += f" — {said}" if said else ""
        elif self.offer_file:
            text = said or _("The scan {visible} is on the robot.").format(visible=visible(self.offer_file))
        else:
            text = said
        if self.label.get_text() != text:
            self.label.set_text(text)
        loops = any(n in self.model.connection.value.offers for n in SCAN_FEATURES["scan_loops"][0])
        self.loop_start.set_visible(scanning and loops)
        self.loop_end.set_visible(scanning and loops)
        self.loop_end.set_sensitive(self.loop_open)
        self.stop_scan.set_visible(scanning)
        self.download.set_visible(not scanning and bool(self.offer_file))
        self.dismiss.set_visible(not scanning)
        self.set_reveal_child(bool(text))

    # -- the operator's buttons ---------------------------------------------------------------------
    def _tag(self, start: bool) -> None:
        def tagged(_answer: Any) -> None:
            self.loop_open = start
            self.message = _("loop start tagged") if start else _("loop end tagged")
            self._show()

        self._ask(TagScanLoop(start=start), tagged)

    def _stop(self) -> None:
        self._ask(StopScan(), lambda _name: self._show())

    def _dismiss(self) -> None:
        self.offer_file = self.message = ""
        self._show()

    def _choose_folder(self) -> None:
        chooser = Gtk.FileChooserDialog(
            title=_("Download the scan into"),
            transient_for=self.parent,
            modal=True,
            action=Gtk.FileChooserAction.SELECT_FOLDER,
        )
        chooser.add_button(_("Cancel"), Gtk.ResponseType.CANCEL)
        chooser.add_button(_("Select"), Gtk.ResponseType.ACCEPT)
        chooser.connect("response", self._folder_chosen)
        self.chooser = chooser
        chooser.present()

    def _folder_chosen(self, chooser: Gtk.FileChooserDialog, response: int) -> None:
        chosen = chooser.get_file() if response == Gtk.ResponseType.ACCEPT else None
        chooser.destroy()
        self.chooser = None
        path = chosen.get_path() if chosen is not None else None
        if path:
            self.download_into(Path(path))

    def download_into(self, folder: Path) -> None:
        """Fetch the ended scan into ``folder`` (asking before replacing a file of that name there)."""
        remote = self.offer_file
        if not remote:
            return
        from ..client.remote_files import local_name  # the files' rules load with the first download

        target = folder / local_name(remote)
        if target.exists() or target.is_symlink():
            self.confirm = Confirm(
                self.parent,
                _("“{name}” already exists in {folder}. Replace it?").format(name=target.name, folder=folder),
                _("Replace"),
                lambda: self._download(remote, target, overwrite=True),
            )
            self.confirm.present()
            return
        self._download(remote, target, overwrite=False)

    def _download(self, remote: str, target: Path, *, overwrite: bool) -> None:
        def done(finished: Any) -> None:
            self.downloads += 1
            self.message = _("Saved the scan to {target} ({human_size})").format(
                target=target, human_size=human_size(finished.size)
            )
            self._show()

        self._ask(DownloadFile(remote, str(target), overwrite=overwrite), done)

    def _transfers(self, state: TransfersState) -> None:
        mine = [t for t in state.active if self.offer_file and t.remote == self.offer_file]
        self._transfer_cell.set_visible(bool(mine))
        if mine:
            self.message = transfer_text(mine[0])
            self.transfer_bar.set_text(self.message)
            fraction = mine[0].fraction
            self.transfer_bar.pulse() if fraction is None else self.transfer_bar.set_fraction(fraction)
            self.transfers_shown += 1
            self._show()

    # -- plumbing ---------------------------------------------------------------------------------
    def _request(self, intent: Intent) -> concurrent.futures.Future[Any]:
        return self.robot.request(intent)

    def _ask(self, intent: Intent, on_answer: Callable[[Any], None]) -> None:
        """Send ``intent``; a failure is said in the bar (the runner's banner says it too)."""

        def answered(future: concurrent.futures.Future[Any]) -> bool:
            error = None if future.cancelled() else future.exception()
            if future.cancelled() or error is not None:
                self.message = _("{label} failed: {value}").format(
                    label=intent.label, value=failure_words(error)
                )
                self._show()
            else:
                on_answer(future.result())
            return False

        self._request(intent).add_done_callback(lambda f: GLib.idle_add(answered, f))

    def close(self) -> None:
        if self._timer:
            GLib.source_remove(self._timer)
            self._timer = 0
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        self._unswitch()
