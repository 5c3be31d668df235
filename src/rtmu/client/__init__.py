"""The headless ArNetworking client: asyncio connection, link health, drive lease, reconnect.

One job per module:

* ``errors``     — typed errors an operator understands (and the CLI's exit codes).
* ``connection`` — :class:`AriaClient`, one logged-in connection on asyncio streams.
* ``health``     — RTT, status age, dropped packets → OK / STALE / LOST.
* ``lease``      — the drive lease the UI renews and the governor that turns it into packets.
* ``reconnect``  — backoff policy.
* ``session``    — everything that runs on the network loop for one operator session.
* ``runner``     — :class:`ClientRunner`: the network thread and its thread-safe facade for a UI.

Nothing here imports GTK.

Wiring a window (what the GTK view does)::

    model = Model()
    runner = ClientRunner(model, post=GLib.idle_add).start()     # network thread
    controller = Controller(model, runner, view)                   # UI thread
    GLib.timeout_add(100, lambda: controller.tick() or True)       # renews the drive lease at 10 Hz
    GLib.timeout_add(500, warn_if_slow)   # (runner.loop_lag() or 0) > 0.5: "drive commands are not going out"
    controller.select_profile(settings.current()); controller.connect()
    ...
    runner.close()                                                 # stops the robot, disconnects

The safety design (lease, governor, loop heartbeat, server watchdog) is written up in ``runner``.

Scripts without a UI use :class:`AriaClient` directly under ``asyncio.run`` (see ``rtmu.subcommands``).
"""

from .connection import AriaClient, Packet, Reply
from .errors import (
    ClientError,
    ClientTimeout,
    ConnectionFailed,
    ConnectionRefused,
    LoginRejected,
    MalformedReply,
    NotSupported,
    ProtocolFault,
    ReplyTooLarge,
    ServerClosed,
)
from .lease import DriveLease, DriveRatios, EndReason
from .runner import ClientRunner, call_directly
from .session import Session, SessionConfig

__all__ = [
    "AriaClient",
    "ClientError",
    "ClientRunner",
    "ClientTimeout",
    "ConnectionFailed",
    "ConnectionRefused",
    "DriveLease",
    "DriveRatios",
    "EndReason",
    "LoginRejected",
    "MalformedReply",
    "NotSupported",
    "Packet",
    "ProtocolFault",
    "Reply",
    "ReplyTooLarge",
    "ServerClosed",
    "Session",
    "SessionConfig",
    "call_directly",
]
