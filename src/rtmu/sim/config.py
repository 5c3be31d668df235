"""Everything a simulator can be told, in one place (the ``rtmu sim`` options map onto it)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from . import p3dx


@dataclass
class SimConfig:
    host: str = "127.0.0.1"
    port: int = 7272
    """0 picks a free port (read it back from ``SimServer.port``)."""
    map_path: Path | None = None
    """None: serve no map (the robot is in an empty world)."""
    users_path: Path | None = None
    """An ARIA user-info file; None: anyone may log in and see everything."""
    camera: bool = True
    seed: int = 1
    drive_timeout: float = 2.0
    """ARIA's ratio-drive watchdog (seconds without a ratioDrive while moving); 0 disables it."""
    realtime: bool = True
    """False: the clock stands still until ``SimServer.advance`` moves it (for tests)."""
    battery_v: float = p3dx.BATTERY_FULL_V
    server_key: str = ""
    max_clients: int | None = 100
    """ARIA's maxClientsAllowed: one more is refused with reason 5 (None: no limit, as ARIA's default —
    but every client may queue up to ``max_queued_bytes``, so a simulator keeps a limit)."""
    protocol_version: str | None = None
    """Enforce a protocol version (reason 4 for a client that differs); None: the profile's."""
    profile: str = "default"
    """Which kind of server to be (:mod:`rtmu.sim.profiles`): ``default`` or ``aram``."""
    test_hooks: bool | None = None
    """List the simulator's own ``Simulator…`` commands (None: as the profile does — the default profile
    lists them, ``aram`` only when asked, being true to a 6MTX robot's list)."""
    client_type: int | None = None
    """Enforce a client type (reason 6), as ``ArServerBase::enforceType`` does."""
    central_server: str | None = None
    """Pretend to be managed by a central server at this address: every login gets reason 2."""
    switch_to: str | None = None
    """``HOST[:PORT]`` of a central server's robot port (ARIA's ``-centralServer``): connect out and
    switch (:mod:`rtmu.sim.switch`); direct logins are then refused with reason 2, as ARIA's are."""
    switch_name: str = ""
    """The name to switch with (ARIA's ``-identifier``); empty: the central server uses our address."""
    switch_retry: float = 10.0
    """Seconds before switching again after the central server's connection ended (ARIA: 10)."""
    switch_silence: float = 120.0
    """Seconds without the central server's heartbeat before that link counts as dead and is dropped
    (ARIA's ``RobotFromCentralServerTimeoutInMins``, 2)."""
    video_trailer: bool = True
    """Append the 2 bytes ARIA's video forwarder leaves after each JPEG (serverDemo does this)."""
    camera_size: tuple[int, int] = (320, 240)
    """The picture size at start (``SimulatorVideo…`` commands still switch between 320x240 and 640x480)."""
    camera_hz: float = 10.0
    """New frames per second at most, shared by all clients (ARIA's forwarder polls its camera ~10 times a
    second; raise it to serve live video faster)."""
    render_in_thread: bool | None = None
    """Render camera frames on a worker thread; None: in real-time mode only (inline on the manual clock)."""
    save_map_changes: bool = False
    """Write a map changed by ``processMapChanges`` into the served file, as ARIA does (False: the change
    lives in the simulator only and the file is left as it was)."""
    intro_timeout: float = 60.0
    backup_timeout: float = 5.0
    """Drop a client whose queued output has not moved for this long (ARIA's backup timeout)."""
    max_queued_bytes: int = 4 * 1024 * 1024
    """Drop a client at once when this much output is waiting for it. Map downloads are sent as the
    client reads (a 1 M-point map is 8 MB binary, 21 MB as text), so they never count whole."""
    skip_periodic_above: int = 1024 * 1024
    """Skip periodic sends to a client with this much output still queued (it is not keeping up)."""
    config_filler: int = 0
    """Extra configuration parameters, markup in every text (:mod:`rtmu.sim.arconfig`): hostile tests."""
    start_pose: tuple[float, float, float] | None = None
    """Where the robot starts (x, y mm, th deg; moved to the nearest free spot); None: the map's home.
    ``rtmu sim --robots N`` gives each robot its own (``sim.multi``)."""
    files_dir: Path | None = None
    """The folder ``getDirListing``/``getFile``/``putFile``/``deleteFile`` share and scans are written to;
    None: a temporary folder of the simulator's own, removed when it goes (:mod:`rtmu.sim.files_folder`)."""
    files_default_dir: str | None = None
    """Offer ``getDefaultUploadDownloadDir`` naming this folder (ARIA lists it only when given one)."""
    verbose: bool = False
