"""The exit codes every ``rtmu`` subcommand shares, apart from the CLI so that any layer may name them.

A typed client error carries its code (``rtmu.client.errors``) without importing the
command line; subcommands add their own codes above these in their modules.

Codes taken elsewhere (never reuse one with another meaning): 1 ``rtmu decode`` unreadable input,
6–8 navigation outcomes (``subcommands._navigate``; 6 is also ``rtmu config``'s refusal and the
window's missing display), 10–17 ``rtmu doctor``'s steps (``client.diagnosis.Step``), 128 + N a
signal, 141 a reader that went away.

20–39: "why won't it move?" (``rtmu why``, ``rtmu drive``, ``rtmu doctor``'s motion step): one code
per cause (:class:`rtmu.client.why.Cause`), the most fundamental cause found decides.
"""

from __future__ import annotations

EXIT_OK = 0
EXIT_USAGE = 2
EXIT_CONNECTION = 3
EXIT_UNSUPPORTED = 4
EXIT_TIMEOUT = 5
EXIT_REFUSED = 6
"""The server answered and said no (a file it will not give or delete, a scan it cannot start): its words
are printed. ``rtmu config --set`` uses the same number for a refused value."""

# -- why the robot does not move (rtmu why / drive / doctor) ---------------------------------------
EXIT_WHY_NO_STOP = 20
"""This login may not send ``stop`` (no ``stop`` in its data list): a safety fact, told loudly."""
EXIT_WHY_NO_DRIVE = 21
"""This login may not drive (no ``ratioDrive`` in its data list)."""
EXIT_WHY_LINK = 22
"""Our own link to the server is stale, lost or down."""
EXIT_WHY_ESTOP = 23
"""The robot's e-stop is pressed (the server's own words say so)."""
EXIT_WHY_FAULTS = 24
"""The robot reports faults of its own (an LD robot's ``getFaults``)."""
EXIT_WHY_MOTORS = 25
"""The motors are disabled (the server's own words say so)."""
EXIT_WHY_STALLED = 26
"""The motors are stalled (status ``Stalled`` / ``Bumped``)."""
EXIT_WHY_LOCKED = 27
"""The active server mode is locked (``getModeInfo``)."""
EXIT_WHY_NAVIGATING = 28
"""The server is driving the robot itself (a goal, home, the dock)."""
EXIT_WHY_DOCKED = 29
"""The robot is docked / charging."""
EXIT_WHY_BATTERY = 30
"""The battery is at or below the robot's shutdown level."""
EXIT_WHY_SAFE_DRIVE = 31
"""Safe drive holds the robot back: an obstacle inside the safe-drive distance."""
EXIT_WHY_WATCHDOG = 32
"""The server's drive watchdog is shorter than twice RTMU's resend period: it stops the robot
between commands (jerky motion, none on a slow link)."""
EXIT_WHY_LOST = 33
"""Localization is lost (only when asking about navigation)."""
EXIT_WHY_LEASE = 34
"""Our drive lease is not live (no key held, or a held key blocked until released; a replay)."""
EXIT_WHY_UNEXPLAINED = 39
"""``rtmu drive``: asked to move, the robot did not, and nothing RTMU can read says why."""

EXIT_FOREIGN_CONFIG = 9
"""The robot has a configuration RTMU cannot show or edit yet (an Omron LD robot's ``getConfigValues``
/ ``setConfigValues``, whose layouts are not public): ``rtmu config`` says which, and stops."""
