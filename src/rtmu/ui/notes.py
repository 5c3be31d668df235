"""What the window says about its connection: the note at the bottom of the map and the header's status.

One function each decides them, from the model alone, and the window calls them on
every connection change and every map change — so the note can never say "not
connected" next to a Disconnect button, or vanish after a disconnect. GTK-free.

The grid's step is not repeated here: it changes with the zoom, and the legend
drawn on the map (``grid 2 m``) is its one source of truth.
"""

from __future__ import annotations

from ..base.i18n import N_, _
from ..model.observables import ConnectionState, MapModel, Phase
from ..settings.store import Profile
from .state_words import sentence_words

CONNECT_HINT = N_("press Connect (Ctrl+O)")


def heading_text(degrees: float) -> str:
    """A heading in whole degrees, never "-0°" (a robot facing -0.3° faces 0°)."""
    return f"{round(degrees) + 0}°"


def map_note(conn: ConnectionState, m: MapModel) -> str:
    """What the map area should say now; "" when the map speaks for itself."""
    where = _(" to {host}:{port}").format(host=conn.host, port=conn.port) if conn.host else ""
    phase = conn.phase
    if phase is Phase.DISCONNECTED:
        return _("Not connected: {CONNECT_HINT}").format(CONNECT_HINT=_(CONNECT_HINT))
    if phase is Phase.FAILED:
        return _("Not connected (the last attempt failed): {CONNECT_HINT} to try again").format(
            CONNECT_HINT=_(CONNECT_HINT)
        )
    if phase is Phase.CONNECTING:
        return _("Connecting{where}…").format(where=where)
    if phase is Phase.RECONNECTING:
        return _("Link lost: the robot is shown where it was last seen")
    # Connected: the map's own state.
    if m.state == "loading":
        return (
            _("Loading the map… ({received} packets)").format(received=m.received)
            if m.received
            else _("Loading the map…")
        )
    if m.state in ("none", "unsupported"):
        return _("This server has no map: the robot on a metric grid (scale at the top left)")
    if m.state == "failed":
        return _("The map could not be loaded: {value}").format(value=m.error or _("no reason given"))
    if m.state == "unknown":
        return _("Connected; asking for the map…")
    return ""


def status_line(conn: ConnectionState, profile: Profile, map_name: str) -> str:
    """The header's status line (and the full-screen bar's): profile · where · phase · map file."""
    phase = conn.phase
    where = f"{conn.host}:{conn.port}" if conn.host else f"{profile.host}:{profile.port}"
    state = {
        Phase.DISCONNECTED: _("not connected"),
        Phase.CONNECTING: _("connecting…"),
        Phase.CONNECTED: _("connected"),
        Phase.RECONNECTING: _("reconnecting ({error})").format(error=sentence_words(conn.error))
        if conn.error
        else _("reconnecting"),
        Phase.FAILED: _("failed: {error}").format(error=sentence_words(conn.error))
        if conn.error
        else _("failed"),
    }[phase]
    name = map_name.replace("\\", "/").rsplit("/", 1)[-1]
    parts = [profile.name, state] if where in profile.name else [profile.name, where, state]
    parts += [name] if name and phase is Phase.CONNECTED else []
    return " · ".join(parts)
