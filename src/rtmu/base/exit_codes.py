"""The exit codes of the whole ``rtmu`` command line: one table, one meaning per code.

Every subcommand exits with one of these (``rtmu --help``, each subcommand's ``--help`` and
the README print :func:`table_text`); ``tests/test_exit_codes.py`` runs each subcommand's
failure paths and checks the code against :data:`EXIT_CODES`. A typed client error carries
its code (``rtmu.client.errors``) without importing the command line.
"""

from __future__ import annotations

import signal

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_USAGE = 2
EXIT_CONNECTION = 3
EXIT_UNSUPPORTED = 4
EXIT_TIMEOUT = 5
EXIT_REFUSED = 6
EXIT_CANCELLED = 7
EXIT_LOST = 8
EXIT_NO_DISPLAY = 9
EXIT_DOCTOR_RESOLVE = 10
EXIT_DOCTOR_TCP = 11
EXIT_DOCTOR_INTRODUCTION = 12
EXIT_DOCTOR_LOGIN = 13
EXIT_DOCTOR_DATALIST = 14
EXIT_DOCTOR_STATUS = 15
EXIT_BAD_FILE = 16
EXIT_SIZE_LIMIT = 17
EXIT_FOREIGN_CONFIG = 18
"""The robot has a configuration RTMU cannot show or edit yet (an Omron LD robot's ``getConfigValues``
/ ``setConfigValues``, whose layouts are not public): ``rtmu config`` says which, and stops."""
EXIT_NOT_HELD = 19
"""``rtmu mapedit``: the server said it applied the change, but the map read again does not hold it."""

# -- why the robot does not move (rtmu why / drive / doctor's motion step) -----------------------
EXIT_WHY_NO_STOP = 20
EXIT_WHY_NO_DRIVE = 21
EXIT_WHY_LINK = 22
EXIT_WHY_ESTOP = 23
EXIT_WHY_FAULTS = 24
EXIT_WHY_MOTORS = 25
EXIT_WHY_STALLED = 26
EXIT_WHY_LOCKED = 27
EXIT_WHY_NAVIGATING = 28
EXIT_WHY_DOCKED = 29
EXIT_WHY_BATTERY = 30
EXIT_WHY_SAFE_DRIVE = 31
EXIT_WHY_WATCHDOG = 32
EXIT_WHY_LOST = 33
EXIT_WHY_LEASE = 34
EXIT_WHY_DEAD_ZONE = 35
EXIT_WHY_UNEXPLAINED = 39
EXIT_SIGHUP = 128 + signal.SIGHUP
EXIT_SIGINT = 128 + signal.SIGINT
EXIT_SIGQUIT = 128 + signal.SIGQUIT
EXIT_SIGPIPE = 128 + signal.SIGPIPE
EXIT_SIGTERM = 128 + signal.SIGTERM
EXIT_SIGTSTP = 128 + signal.SIGTSTP

EXIT_CODES: dict[int, str] = {
    EXIT_OK: "done",
    EXIT_INTERNAL: "internal error in RTMU (a bug: please report it with the message)",
    EXIT_USAGE: "usage: a bad or out-of-range argument, an unknown name (goal, route, robot, command), "
    "a missing or unreadable password source, an input file that does not exist, or an output file "
    "that exists (without --force) or cannot be written",
    EXIT_CONNECTION: "connection, login or protocol failure: refused, unreachable, rejected, closed, "
    "the server sent something malformed, or a port that cannot be listened on (sim, bridge)",
    EXIT_UNSUPPORTED: "the server (or this user) does not offer what is needed",
    EXIT_TIMEOUT: "timeout: no answer, or no outcome within --limit (a navigation is stopped)",
    EXIT_REFUSED: "the server refused or could not do it, in its own words: a setting refused, a goal it "
    "could not reach, a failed dock, a file it will not give or take, a scan it cannot start, a map change "
    "it refused",
    EXIT_CANCELLED: "stopped before arriving (STOP, a drive, another goal)",
    EXIT_LOST: "the robot is lost (localize it first)",
    EXIT_NO_DISPLAY: "no display: the window needs DISPLAY or WAYLAND_DISPLAY",
    EXIT_DOCTOR_RESOLVE: "doctor: the name does not resolve",
    EXIT_DOCTOR_TCP: "doctor: no TCP connection",
    EXIT_DOCTOR_INTRODUCTION: "doctor: no ArNetworking introduction",
    EXIT_DOCTOR_LOGIN: "doctor: login refused",
    EXIT_DOCTOR_DATALIST: "doctor: no data list",
    EXIT_DOCTOR_STATUS: "doctor: no first status",
    EXIT_BAD_FILE: "a file's contents cannot be used: not a capture, recording or map RTMU reads, "
    "cut short or malformed",
    EXIT_SIZE_LIMIT: "record: the recording could not go on (its --max-mb limit, a full or failing disk); "
    "what it holds is kept",
    EXIT_FOREIGN_CONFIG: "config: the robot's configuration is of a kind RTMU cannot show or edit yet "
    "(an Omron LD robot's getConfigValues; rtmu call reads it raw)",
    EXIT_NOT_HELD: "mapedit: the server said it applied the change, but its map does not hold it",
    EXIT_WHY_NO_STOP: "why: this user may not even stop the robot (no stop in its data list)",
    EXIT_WHY_NO_DRIVE: "why: this user may not drive (no ratioDrive in its data list)",
    EXIT_WHY_LINK: "why: our own link to the robot is stale, lost or down",
    EXIT_WHY_ESTOP: "why: the robot's e-stop is pressed",
    EXIT_WHY_FAULTS: "why: the robot reports faults of its own",
    EXIT_WHY_MOTORS: "why: the motors are disabled",
    EXIT_WHY_STALLED: "why: the motors are stalled (status Stalled / Bumped)",
    EXIT_WHY_LOCKED: "why: the active server mode is locked",
    EXIT_WHY_NAVIGATING: "why: the server drives the robot itself (a goal, home, the dock)",
    EXIT_WHY_DOCKED: "why: the robot is docked / charging",
    EXIT_WHY_BATTERY: "why: the battery is at or below the robot's shutdown level",
    EXIT_WHY_SAFE_DRIVE: "why: safe drive holds the robot back (an obstacle inside its distance)",
    EXIT_WHY_WATCHDOG: "why: the server's drive watchdog is shorter than RTMU's resend period allows",
    EXIT_WHY_LOST: "why: localization is lost (asked about navigation)",
    EXIT_WHY_LEASE: "why: our drive lease is not live (no key held, a blocked key, a replay)",
    EXIT_WHY_DEAD_ZONE: "drive: the ratios asked for are inside ARIA's dead zone (translation up to ±10 %, "
    "rotation under ±5 %): the robot ignores them",
    EXIT_WHY_UNEXPLAINED: "drive: asked to move, the robot did not, and nothing RTMU can read says why",
    EXIT_SIGHUP: "ended by SIGHUP (the terminal went away)",
    EXIT_SIGINT: "ended by Ctrl-C (SIGINT)",
    EXIT_SIGQUIT: "ended by SIGQUIT",
    EXIT_SIGPIPE: "the reader of the output went away (e.g. piped into head)",
    EXIT_SIGTERM: "ended by SIGTERM",
    EXIT_SIGTSTP: "rtmu drive ended by Ctrl-Z (the robot was stopped first)",
}
"""Code → meaning. Other 128 + N: ended by signal N (any ending signal stops what the command drove)."""


ENDED = (EXIT_SIGHUP, EXIT_SIGINT, EXIT_SIGTERM)
"""Every command that runs a while ends by these three through its own clean-up."""
NETWORK = (
    EXIT_OK, EXIT_USAGE, EXIT_CONNECTION, EXIT_UNSUPPORTED, EXIT_TIMEOUT, EXIT_INTERNAL, *ENDED, EXIT_SIGPIPE
)  # fmt: skip
"""The codes of a subcommand that talks to a robot server (its module's ``EXITS`` when it has more)."""
WHY_ASKED = (
    EXIT_WHY_NO_STOP, EXIT_WHY_NO_DRIVE, EXIT_WHY_ESTOP, EXIT_WHY_FAULTS, EXIT_WHY_MOTORS, EXIT_WHY_STALLED,
    EXIT_WHY_LOCKED, EXIT_WHY_NAVIGATING, EXIT_WHY_DOCKED, EXIT_WHY_BATTERY, EXIT_WHY_SAFE_DRIVE,
    EXIT_WHY_WATCHDOG,
)  # fmt: skip
"""The causes a login of the command line can find by asking (``rtmu why``, doctor's last step); the
link and the lease (22, 34) are the window's own side, a lost robot (33) counts only for navigation."""
WHY_DRIVE = (*(c for c in WHY_ASKED if c != EXIT_WHY_NO_STOP), EXIT_WHY_DEAD_ZONE, EXIT_WHY_UNEXPLAINED)
"""What ``rtmu drive`` exits with when the robot did not move (a login that may not stop is warned)."""


def signal_code(signum: int) -> int:
    """The code of a command ended by signal ``signum``: 128 + N, as shells report it."""
    return 128 + signum


def table_text(codes: tuple[int, ...] | None = None, *, indent: str = "  ", width: int = 79) -> str:
    """The table as plain text for a ``--help`` epilog (``codes``: only those), in order of code."""
    import textwrap

    chosen = sorted(set(EXIT_CODES if codes is None else codes))
    lines = []
    for code in chosen:
        head = f"{indent}{code:>3}  "
        lines.append(
            textwrap.fill(EXIT_CODES[code], width, initial_indent=head, subsequent_indent=" " * len(head))
        )
    return "\n".join(lines)
