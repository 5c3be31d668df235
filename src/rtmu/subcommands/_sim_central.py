"""``rtmu sim --central [--robots N]``: a central server, and optionally N robots switched to it."""

from __future__ import annotations

import dataclasses
import sys
from typing import TYPE_CHECKING

from ..base.exit_codes import EXIT_CONNECTION, EXIT_USAGE
from ..base.i18n import N_, Said, _, ngettext
from ._common import until_stop_signal
from ._sim_lines import start_line

if TYPE_CHECKING:
    from ..sim import SimConfig

EXIT_BAD_INPUT = EXIT_USAGE
EXIT_CANNOT_LISTEN = EXIT_CONNECTION


async def serve_central(cfg: SimConfig, robot_port: int, robots: int) -> int:
    """Serve until SIGINT/SIGTERM; ``cfg`` is the robots' template (map, camera, seed…)."""
    from ..mapfile import MapFormatError
    from ..sim import SimServer
    from ..sim.central import CentralConfig, CentralServer
    from ..sim.multi import start_poses

    # The user file guards the central port and the forwarders, as ARIA's switchServer's does; the
    # robots behind it let the forwarder in (it logs in without a user).
    central = CentralServer(
        CentralConfig(host=cfg.host, port=cfg.port, robot_port=robot_port, users_path=cfg.users_path)
    )
    try:
        await central.start()
    except OSError as exc:
        where = f"{cfg.host}:{cfg.port}/{robot_port}"
        print(
            _("rtmu sim: cannot listen on {where}: {value}").format(where=where, value=exc.strerror or exc),
            file=sys.stderr,
        )
        return EXIT_CANNOT_LISTEN
    line = Said(
        N_("rtmu sim: ARIA central server: operators on {operators}, robots switch to {robots}"),
        operators=f"{cfg.host}:{central.port}",
        robots=f"{cfg.host}:{central.robot_port}",
    )
    print(start_line(line), flush=True)  # read by programs (the ports): English unless at a terminal
    sims: list[SimServer] = []
    try:
        # Start poses apart, as `rtmu sim --robots N` gives them (not all on the map's home).
        for i, pose in enumerate(start_poses(cfg, robots), start=1):
            robot_cfg = dataclasses.replace(
                cfg,
                start_pose=pose,
                port=0,
                seed=cfg.seed + i - 1,
                switch_to=f"{cfg.host}:{central.robot_port}",
                switch_name=f"robot{i}",
                central_server=None,
                users_path=None,
            )
            sim = SimServer(robot_cfg)
            await sim.start()
            sims.append(sim)
        if robots:
            print(
                ngettext(
                    "rtmu sim: {robots} simulated robot switching to it: robot1…robot{robots}",
                    "rtmu sim: {robots} simulated robots switching to it: robot1…robot{robots}",
                    robots,
                ).format(robots=robots),
                flush=True,
            )
        code = await until_stop_signal()
        print(_("rtmu sim: stopping (telling operators and robots SHUTDOWN)"), flush=True)
        return code
    except (OSError, MapFormatError, ValueError) as exc:
        print(_("rtmu sim: cannot start the robots: {exc}").format(exc=exc), file=sys.stderr)
        return EXIT_BAD_INPUT
    finally:
        await central.stop()
        for sim in sims:
            await sim.stop()
