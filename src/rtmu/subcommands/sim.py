"""``rtmu sim``: run the bundled ARIA robot simulator (a Pioneer 3-DX behind an ArNetworking server).

It behaves on the wire like ARIA's serverDemo driving MobileSim, so the RTMU
window, ARIA's own example clients and MobileEyes-style tools can connect to
it. It listens on 127.0.0.1 unless told otherwise; Ctrl-C stops it cleanly
(every client is told SHUTDOWN). ``--make-map FILE`` writes a generated
building map instead of serving.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..base.exit_codes import ENDED, EXIT_CONNECTION, EXIT_OK, EXIT_SIGINT, EXIT_USAGE
from ..base.i18n import N_, Said, _
from ..package_data import project_map
from ._common import until_stop_signal
from ._options import number_in
from ._sim_lines import joined, plain, start_line

EXIT_BAD_INPUT = EXIT_USAGE
EXIT_CANNOT_LISTEN = EXIT_CONNECTION
EXITS = (EXIT_OK, EXIT_USAGE, EXIT_CONNECTION, *ENDED)
SIM_DESCRIPTION = N_(
    "Run the bundled ARIA robot simulator: an ArNetworking server that behaves on the wire like ARIA's "
    "serverDemo driving MobileSim (--kind aram: an Omron LD robot), so the RTMU window, ARIA's own example "
    "clients and MobileEyes-style tools can connect to it. It listens on 127.0.0.1 unless told otherwise; "
    "Ctrl-C stops it cleanly (every client is told SHUTDOWN). --make-map FILE writes a generated "
    "building map instead of serving."
)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "sim",
        help=_("run the bundled ARIA robot simulator (ArNetworking server, simulated Pioneer 3-DX)"),
        description=_(SIM_DESCRIPTION),
    )
    p.add_argument(
        "--host", default="127.0.0.1", metavar="ADDR", help=_("address to listen on (default 127.0.0.1)")
    )
    p.add_argument(
        "--port",
        type=number_in(0, 65535, integer=True),
        default=7272,
        metavar="PORT",
        help=_("the robot server's TCP port (default 7272, ARIA's; 0 = any free port)"),
    )
    maps = p.add_mutually_exclusive_group()
    maps.add_argument(
        "--map", type=Path, metavar="FILE", help=_("ARIA .map file to serve (default: the project's arena)")
    )
    maps.add_argument("--no-map", action="store_true", help=_("serve no map (an empty world)"))
    p.add_argument(
        "--users",
        type=Path,
        metavar="FILE",
        help=_("ARIA user-info file (UserInfoVersion1); default: open to anyone"),
    )
    p.add_argument(
        "--no-camera", action="store_true", help=_("no camera: video and camera data are not offered")
    )
    p.add_argument(
        "--camera-size",
        type=_size,
        default=(320, 240),
        metavar="WxH",
        help=_("picture size at start (default 320x240; e.g. 640x480)"),
    )
    p.add_argument(
        "--camera-hz",
        type=number_in(0.1, 60),
        default=10.0,
        metavar="HZ",
        help=_(
            "the simulated camera's own frame rate, 0.1…60 new frames/s (default 10, like ARIA's video "
            "forwarder)"
        ),
    )
    p.add_argument(
        "--seed", type=int, default=1, metavar="N", help=_("seed for everything random (default 1)")
    )
    p.add_argument(
        "--drive-timeout",
        type=number_in(0, 3600),
        default=2.0,
        metavar="S",
        help=_("seconds without ratioDrive before a moving robot is stopped (default 2, ARIA's; 0 disables)"),
    )
    p.add_argument(
        "--battery",
        type=float,
        default=None,
        metavar="VOLTS",
        help=_("starting battery voltage (default 12.8)"),
    )
    p.add_argument(
        "--server-key",
        default="",
        metavar="KEY",
        help=_("ARIA server key mixed into password digests (default: none)"),
    )
    p.add_argument(
        "--max-clients",
        type=number_in(0, 100_000, integer=True),
        default=100,
        metavar="N",
        help=_("refuse more clients than this, ARIA's reason 5 (default 100; 0 = no limit)"),
    )
    p.add_argument(
        "--kind",
        choices=("default", "aram"),
        default="default",
        help=_(
            "which server to be: default (serverDemo, Pioneer 3-DX) or aram (an Omron LD robot: "
            "protocol 6MTX, state of charge, Ex4 map, only data 6MTX robots list); default: default"
        ),
    )
    p.add_argument(
        "--test-hooks",
        action="store_true",
        default=None,
        help=_(
            "list the simulator's own Simulator… commands (put it in a state: a fault, a locked mode, "
            "a stall …) also on a kind that leaves them out to stay true to a real robot's list (aram)"
        ),
    )
    p.add_argument("--profile", dest="kind", choices=("default", "aram"), help=argparse.SUPPRESS)  # old name
    p.add_argument(
        "--protocol",
        metavar="STRING",
        default=None,
        help=_(
            "enforce and advertise this protocol string, refusing others with reason 4 "
            "(default: the profile's — none, or 6MTX for aram)"
        ),
    )
    p.add_argument(
        "--config-filler",
        type=int,
        default=0,
        metavar="N",
        help=_("add N configuration parameters, markup in every text (try clients on a hostile ArConfig)"),
    )
    p.add_argument(
        "--save-map-changes",
        action="store_true",
        help=_(
            "write live map changes (processMapChanges) into the --map file, as ARIA does "
            "(default: they live in the simulator only)"
        ),
    )
    p.add_argument(
        "--robots",
        type=int,
        default=None,
        metavar="N",
        help=_(
            "run N robots on the map, one server each on consecutive ports from --port, "
            "named robot1…N (default 1); with --central: N simulated robots switched to it (default 0)"
        ),
    )
    p.add_argument(
        "--files",
        type=Path,
        metavar="DIR",
        help=_(
            "the folder served to getDirListing/getFile/putFile/deleteFile, where scans are written "
            "(default: a temporary folder, removed when the simulator stops)"
        ),
    )
    p.add_argument(
        "--files-default-dir",
        metavar="NAME",
        default=None,
        help=_("offer getDefaultUploadDownloadDir naming this folder (ARIA offers it only when given one)"),
    )
    p.add_argument("-v", "--verbose", action="store_true", help=_("log connections and refusals"))
    central = p.add_argument_group("ARIA central server (switchServer)")
    central.add_argument(
        "--central",
        action="store_true",
        help=_(
            "be a central server instead of a robot: operators on --port (7272) get the robot list, "
            "robots switch to --robot-port (5000) and are each forwarded on a port of their own"
        ),
    )
    central.add_argument(
        "--robot-port",
        type=number_in(0, 65535, integer=True),
        default=5000,
        metavar="PORT",
        help=_("with --central: where robots switch to (default 5000)"),
    )
    central.add_argument(
        "--switch-to",
        metavar="HOST[:PORT]",
        help=_(
            "as a robot: connect out to this central server's robot port (default port 5000) and be "
            "forwarded by it (ARIA's -centralServer); direct logins are then refused with reason 2"
        ),
    )
    central.add_argument(
        "--name",
        default="",
        metavar="NAME",
        help=_("with --switch-to: the robot's name (ARIA's -identifier; default: its address)"),
    )
    gen = p.add_argument_group("map generator (writes a map and exits)")
    gen.add_argument(
        "--make-map", type=Path, metavar="FILE", help=_("write a generated building map to FILE")
    )
    gen.add_argument(
        "--points",
        type=int,
        default=100_000,
        metavar="N",
        help=_("points in the generated map (default 100000)"),
    )
    gen.add_argument(
        "--lines",
        type=int,
        default=5_000,
        metavar="N",
        help=_("line segments in the generated map (default 5000)"),
    )
    p.set_defaults(handler=run)


def _size(text: str) -> tuple[int, int]:
    """``WxH`` → (W, H), each 16…1920 (ArNetworking's packet limit caps a JPEG well before that)."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(
            _("{text} is not WxH (e.g. 640x480)").format(text=repr(text))
        ) from None
    if not (16 <= w <= 1920 and 16 <= h <= 1920):
        raise argparse.ArgumentTypeError(
            _("{text}: each side must be 16…1920 pixels").format(text=repr(text))
        )
    return w, h


def run(args: argparse.Namespace) -> int:
    import asyncio

    if args.make_map is not None:
        return make_map(args)
    if args.central:
        args.robots = 0 if args.robots is None else args.robots
        if not 0 <= args.robots <= 100:
            print(_("rtmu sim: with --central, --robots takes 0…100"), file=sys.stderr)
            return EXIT_BAD_INPUT
    else:
        from ..sim.multi import MAX_ROBOTS

        args.robots = 1 if args.robots is None else args.robots
        if not 1 <= args.robots <= MAX_ROBOTS:
            print(
                _("rtmu sim: --robots must be 1…{MAX_ROBOTS}").format(MAX_ROBOTS=MAX_ROBOTS), file=sys.stderr
            )
            return EXIT_BAD_INPUT
    from ..sim import SimConfig

    map_path = (
        None
        if args.no_map
        else (args.map or project_map("office.map" if args.kind == "aram" else "arena.map"))
    )
    if map_path is not None and not map_path.is_file():
        print(_("rtmu sim: no such map file: {map_path}").format(map_path=map_path), file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.files is not None and not args.files.is_dir():
        print(_("rtmu sim: no such folder: {files}").format(files=args.files), file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.users is not None and not args.users.is_file():
        print(_("rtmu sim: no such user file: {users}").format(users=args.users), file=sys.stderr)
        return EXIT_BAD_INPUT
    cfg = SimConfig(
        host=args.host,
        port=args.port,
        map_path=map_path,
        users_path=args.users,
        camera=not args.no_camera,
        camera_size=args.camera_size,
        camera_hz=args.camera_hz,
        seed=args.seed,
        drive_timeout=args.drive_timeout,
        server_key=args.server_key,
        max_clients=args.max_clients if args.max_clients > 0 else None,
        protocol_version=args.protocol,
        profile=args.kind,
        test_hooks=args.test_hooks,
        config_filler=max(0, min(args.config_filler, 200_000)),
        files_dir=args.files,
        files_default_dir=args.files_default_dir,
        save_map_changes=args.save_map_changes,
        verbose=args.verbose,
    )
    if args.battery is not None:
        cfg.battery_v = args.battery
    if args.switch_to:
        from ..sim.switch import parse_address

        try:
            parse_address(args.switch_to)
        except ValueError as exc:
            print(_("rtmu sim: {exc}").format(exc=exc), file=sys.stderr)
            return EXIT_BAD_INPUT
        cfg.switch_to, cfg.switch_name = args.switch_to, args.name
    if args.verbose:
        import logging

        from ..base import logs

        logs.configure(logging.INFO)
    try:
        if args.central:
            from ._sim_central import serve_central

            return asyncio.run(serve_central(cfg, args.robot_port, args.robots))
        return asyncio.run(serve(cfg) if args.robots == 1 else serve_fleet(cfg, args.robots))
    except KeyboardInterrupt:  # before the handlers were in place
        return EXIT_SIGINT


async def serve(cfg) -> int:
    from ..mapfile import MapFormatError
    from ..sim import SimServer
    from ..sim.profiles import get_profile

    try:
        server = SimServer(cfg)
    except (OSError, MapFormatError, ValueError) as exc:
        print(_("rtmu sim: cannot load: {exc}").format(exc=exc), file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        await server.start()
    except OSError as exc:
        print(
            _("rtmu sim: cannot listen on {host}:{port}: {value}").format(
                host=cfg.host, port=cfg.port, value=exc.strerror or exc
            ),
            file=sys.stderr,
        )
        return EXIT_CANNOT_LISTEN
    from ..base.heap import settle
    from ..sim.files_folder import files_folder

    settle()  # the world and map are built: later full collections do not walk them (base.heap)

    files = files_folder(server)
    served = Said(N_("map {path}"), path=str(cfg.map_path)) if cfg.map_path else Said(N_("no map"))
    extras = [] if cfg.camera else [Said(N_("no camera"))]
    if cfg.users_path:
        extras.append(Said(N_("users from {path}"), path=str(cfg.users_path)))
    if cfg.profile != "default":
        extras.append(Said(N_("profile {name}"), name=cfg.profile))
    if cfg.protocol_version:
        extras.append(Said(N_("protocol {version} enforced"), version=repr(cfg.protocol_version)))
    temporary = files.temporary is not None
    extras.append(
        Said(N_("files in {path} (temporary)") if temporary else N_("files in {path}"), path=str(files.root))
    )
    x, y, th = server.home
    line = Said(
        N_(
            "rtmu sim: ARIA robot server listening on {where}, serving {served}; "
            "{robot} at ({x}, {y}) mm, {th} deg{extras}"
        ),
        where=f"{cfg.host}:{server.port}",
        served=served,
        robot=get_profile(cfg.profile).robot,
        x=plain(x),
        y=plain(y),
        th=plain(th),
        extras=joined(extras),
    )
    print(start_line(line), flush=True)
    code = await until_stop_signal()
    print(_("rtmu sim: stopping (telling clients SHUTDOWN)"), flush=True)
    await server.stop()
    if files.temporary is not None:
        files.temporary.cleanup()
    return code


async def serve_fleet(cfg, count: int) -> int:
    """``--robots N``: N servers on one loop (``sim.multi``), one line per robot, Ctrl-C stops all."""
    from ..mapfile import MapFormatError
    from ..sim.multi import SimFleet, fleet_configs

    try:
        fleet = SimFleet(fleet_configs(cfg, count))
    except (OSError, MapFormatError, ValueError) as exc:
        print(_("rtmu sim: cannot load: {exc}").format(exc=exc), file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        await fleet.start()
    except OSError as exc:
        print(_("rtmu sim: cannot listen: {value}").format(value=exc.strerror or exc), file=sys.stderr)
        return EXIT_CANNOT_LISTEN
    from ..base.heap import settle

    settle()  # every robot's world and map are built (base.heap)
    for robot, server in zip(fleet.robots, fleet.servers, strict=True):
        x, y, th = server.home
        line = Said(
            N_("rtmu sim: {name} listening on {where}, at ({x}, {y}) mm, {th} deg"),
            name=robot.name,
            where=f"{cfg.host}:{server.port}",
            x=plain(x),
            y=plain(y),
            th=plain(th),
        )
        print(start_line(line), flush=True)
    code = await until_stop_signal()
    print(_("rtmu sim: stopping every robot (telling clients SHUTDOWN)"), flush=True)
    await fleet.stop()
    return code


def make_map(args: argparse.Namespace) -> int:
    from ..mapfile import write_map
    from ..sim.mapgen import generate_map

    if args.points < 0 or args.lines < 0:
        print(_("rtmu sim: --points and --lines cannot be negative"), file=sys.stderr)
        return EXIT_BAD_INPUT
    data = generate_map(args.points, args.lines, seed=args.seed)
    write_map(data, args.make_map)
    print(
        _("rtmu sim: wrote {make_map} ({num_points} points, {num_lines} lines)").format(
            make_map=args.make_map, num_points=data.num_points, num_lines=data.num_lines
        )
    )
    return EXIT_OK
