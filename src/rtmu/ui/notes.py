"""What the window says about its connection: the note at the bottom of the map and the header's status.

One function each decides them, from the model alone, and the window calls them on
every connection change and every map change — so the note can never say "not
connected" next to a Disconnect button, or vanish after a disconnect. GTK-free.

The grid's step is not repeated here: it changes with the zoom, and the legend
drawn on the map (``grid 2 m``) is its one source of truth.
"""

from __future__ import annotations

from ..model.observables import ConnectionState, MapModel, Phase
from ..settings.store import Profile

CONNECT_HINT = "press Connect (Ctrl+O)"


def heading_text(degrees: float) -> str:
    """A heading in whole degrees, never "-0°" (a robot facing -0.3° faces 0°)."""
    return f"{round(degrees) + 0}°"


def map_note(conn: ConnectionState, m: MapModel) -> str:
    """What the map area should say now; "" when the map speaks for itself."""
    where = f" to {conn.host}:{conn.port}" if conn.host else ""
    phase = conn.phase
    if phase is Phase.DISCONNECTED:
        return f"Not connected: {CONNECT_HINT}"
    if phase is Phase.FAILED:
        return f"Not connected (the last attempt failed): {CONNECT_HINT} to try again"
    if phase is Phase.CONNECTING:
        return f"Connecting{where}…"
    if phase is Phase.RECONNECTING:
        return "Link lost: the robot is shown where it was last seen"
    # Connected: the map's own state.
    if m.state == "loading":
        return f"Loading the map… ({m.received} packets)" if m.received else "Loading the map…"
    if m.state in ("none", "unsupported"):
        return "This server has no map: the robot on a metric grid (scale at the top left)"
    if m.state == "failed":
        return f"The map could not be loaded: {m.error or 'no reason given'}"
    if m.state == "unknown":
        return "Connected; asking for the map…"
    return ""


def status_line(conn: ConnectionState, profile: Profile, map_name: str) -> str:
    """The header's status line (and the full-screen bar's): profile · where · phase · map file."""
    phase = conn.phase
    where = f"{conn.host}:{conn.port}" if conn.host else f"{profile.host}:{profile.port}"
    state = {
        Phase.DISCONNECTED: "not connected",
        Phase.CONNECTING: "connecting…",
        Phase.CONNECTED: "connected",
        Phase.RECONNECTING: f"reconnecting ({conn.error})" if conn.error else "reconnecting",
        Phase.FAILED: f"failed: {conn.error}" if conn.error else "failed",
    }[phase]
    name = map_name.replace("\\", "/").rsplit("/", 1)[-1]
    parts = [profile.name, state] if where in profile.name else [profile.name, where, state]
    parts += [name] if name and phase is Phase.CONNECTED else []
    return " · ".join(parts)
