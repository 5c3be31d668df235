"""``rtmu replay FILE.mcap``: the window shows a recording instead of a robot (wiring only).

The session is the window's ordinary one, built with a :class:`~rtmu.recorder.replay.Replayer`
as its opener, no recorder and no guardian; so the map, robot, trail, sonar, navigation,
banners and camera come out of the same code as live. The controller is put in replay
mode (nothing is sent; drive keys, D-pad and STOP say "replay"), the header and a
badge in the controls say REPLAY, and :class:`~rtmu.ui.replay_bar.ReplayBar` moves the clock.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from gi.repository import GLib

from ..base.i18n import _
from ..fleet.sessions import RobotSession
from ..recorder.replay import REPLAY_HOST, Replayer
from ..recorder.replay_file import load
from ..settings.store import Profile
from ..values.state import StateChange
from ..values.target import Target
from .replay_bar import ReplayBar

if TYPE_CHECKING:
    from .window import MainWindow


def open_replay(path: Path, conn: int = 1) -> Replayer:
    """Connection ``conn`` of the recording, ready to play (``ReplayFileError`` says why it cannot)."""
    return Replayer(load(path, conn))


def replay_profile(path: Path) -> Profile:
    return Profile(
        name=_("Replay of {name}").format(name=path.name), host=REPLAY_HOST, port=0, auto_reconnect=False
    )


def show_replay(window: MainWindow, session: RobotSession, replayer: Replayer) -> ReplayBar:
    """Put the window in replay mode, add the controls and start playing from the beginning."""
    name = replayer.recorded.path.name
    model = session.state

    def publish(change: StateChange) -> None:  # camera pictures from the file (network thread)
        GLib.idle_add(model.apply, change)

    replayer.publish = publish
    session.controller.replay = name
    session.controller.refresh_commands()
    runner = session.runner

    def seek(at_ns: int) -> None:
        rebuild = replayer.seek_needs_rebuild(at_ns)
        replayer.clock.seek(at_ns)
        if rebuild:  # back in time: the state is rebuilt from the first byte
            runner.connect(Target(REPLAY_HOST, 0, auto_reconnect=False))

    window.stage.status_age = window.toolbar.status_age = replayer.status_age  # ages in recording time
    bar = ReplayBar(replayer.clock, seek, name)
    window.column.append(bar)
    window.title_label.set_text(_("RTMU — REPLAY"))
    for button in (window.connect_button, window.fullscreen_bar.connect_button):
        button.set_visible(False)  # there is no robot to disconnect from; closing the window ends it
    more = replayer.recorded.connections
    extra = (
        _(" (connection {conn} of {more}; --conn N picks another)").format(
            conn=replayer.recorded.conn, more=more
        )
        if more > 1
        else ""
    )
    window.banners.tell(
        "replay",
        "info",
        _("Replay of {name}{extra}: nothing is sent to any robot").format(name=name, extra=extra),
        timeout=6.0,
    )
    replayer.clock.play()
    runner.connect(Target(REPLAY_HOST, 0, auto_reconnect=False))
    return bar
