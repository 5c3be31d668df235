"""The ``rtmu`` window's entry points: options (``--demo``, ``--host``, ``--fullscreen``…) and ``run_gui``.

GTK is imported only when the window really opens (``application`` module), so
``rtmu --help`` and the headless subcommands never initialise a display. With
``--demo`` the bundled simulator runs beside the window for as long as it lives (``ui.demo``).
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from ..base.exit_codes import EXIT_CONNECTION, EXIT_INTERNAL, EXIT_NO_DISPLAY, EXIT_USAGE
from ..base.heap import hold, resume
from ..base.i18n import _
from ..client.defaults import DEFAULT_PORT

if TYPE_CHECKING:
    from .options import GuiOptions

if TYPE_CHECKING:
    from .demo import RunningDemo


def add_gui_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of the window (``rtmu`` without a subcommand)."""
    g = parser.add_argument_group(_("operator window (no subcommand)"))
    g.add_argument(
        "--demo",
        action="store_true",
        help=_("run the bundled robot simulator (office map) on a free loopback port and connect to it"),
    )
    g.add_argument(
        "--robots",
        type=int,
        default=1,
        metavar="N",
        help=_(
            "with --demo: N simulated robots on one map (as rtmu sim --robots N), all in the window "
            "(default 1)"
        ),
    )
    g.add_argument(
        "--central",
        metavar=_("HOST[:PORT]"),
        help=_("ARIA's central server: every robot it lists in the window (as a profile's central = …)"),
    )
    g.add_argument("--host", metavar="HOST", help=_("robot server to connect to (default: the last profile)"))
    g.add_argument(
        "--port",
        type=int,
        metavar="PORT",
        help=_("its port (default {DEFAULT_PORT})").format(DEFAULT_PORT=DEFAULT_PORT),
    )
    g.add_argument("--user", metavar="USER", help=_("user name for the server (asks for the password)"))
    g.add_argument("--profile", metavar="NAME", help=_("use this saved connection profile"))
    g.add_argument(
        "--protocol",
        metavar="STRING",
        help=_("protocol string to log in with (default: the one the server advertises, e.g. 6MTX)"),
    )
    g.add_argument("--fullscreen", action="store_true", help=_("start full screen (F11 toggles)"))
    g.add_argument("--no-connect", action="store_true", help=_("open the window without connecting"))
    g.add_argument("--report-first-frame", action="store_true", help=argparse.SUPPRESS)
    g.add_argument("--no-guardian", action="store_true", help=argparse.SUPPRESS)  # bench baselines only


def options_from_args(args: argparse.Namespace) -> GuiOptions:
    from .options import GuiOptions

    return GuiOptions(
        host=getattr(args, "host", None),
        port=getattr(args, "port", None),
        user=getattr(args, "user", None),
        profile=getattr(args, "profile", None),
        central=getattr(args, "central", None),
        fullscreen=bool(getattr(args, "fullscreen", False)),
        connect=False if getattr(args, "no_connect", False) else None,
        demo=bool(getattr(args, "demo", False)),
        report_first_frame=bool(getattr(args, "report_first_frame", False)),
        protocol=getattr(args, "protocol", None),
        guardian=not getattr(args, "no_guardian", False),
        replay=getattr(args, "replay", None),
        replay_conn=getattr(args, "replay_conn", 1),
    )


def run_gui(args: argparse.Namespace) -> int:
    """Open the window; with ``--demo`` run the simulator beside it for as long as the window lives."""
    from ..settings.store import parse_central

    options = options_from_args(args)
    if options.port is not None and not 1 <= options.port <= 65535:
        print(_("rtmu: --port {port} is not 1…65535").format(port=options.port), file=sys.stderr)
        return EXIT_USAGE
    if options.central is not None:
        try:
            parse_central(options.central)
        except ValueError as exc:
            print(_("rtmu: --central: {error}").format(error=exc), file=sys.stderr)
            return EXIT_USAGE
        if options.host or options.demo:
            print(_("rtmu: --central goes without --host and --demo"), file=sys.stderr)
            return EXIT_USAGE
    robots = getattr(args, "robots", 1)
    if robots != 1 and not options.demo:
        print(_("rtmu: --robots N goes with --demo (a fleet profile names real robots)"), file=sys.stderr)
        return EXIT_USAGE
    if not 1 <= robots <= 50:
        print(_("rtmu: --robots {robots} is not 1…50").format(robots=robots), file=sys.stderr)
        return EXIT_USAGE
    hold()  # no collector passes while the window's modules and widgets are built (base.heap)
    try:
        return _open_window(options, robots)
    finally:
        resume()  # the window settles (and collects again) 3 s after it shows; it may have closed sooner


def _open_window(options: GuiOptions, robots: int) -> int:
    """The display, the demo's simulator if asked for, the window until it closes: the exit status."""
    if not display_available():
        print(
            _(
                "rtmu: cannot open a display (is DISPLAY or WAYLAND_DISPLAY set?); "
                "without one, use the headless subcommands (rtmu status, rtmu drive, rtmu sim …)"
            ),
            file=sys.stderr,
        )
        return EXIT_NO_DISPLAY
    sim: RunningDemo | None = None
    if options.demo:
        from .demo import start_demo

        try:
            options, sim = start_demo(options, robots)
        except Exception as exc:  # the window is useless without it: say why and stop
            print(_("rtmu: the demo simulator did not start: {error}").format(error=exc), file=sys.stderr)
            return EXIT_CONNECTION
    try:
        from .application import RtmuApplication

        app = RtmuApplication(options)
        status = int(app.run([sys.argv[0]]))
        return EXIT_INTERNAL if app.failed and status == 0 else status
    finally:
        if sim is not None:
            sim.stop()


def display_available() -> bool:
    """GTK can open a display (imports GTK: call only when the window is really wanted)."""
    import gi

    gi.require_version("Gtk", "4.0")
    gi.require_version("Gdk", "4.0")
    from gi.repository import Gdk, Gtk

    return bool(Gtk.init_check()) and Gdk.Display.get_default() is not None
