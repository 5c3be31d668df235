"""ARNL's ``Files/Map`` parameter in the simulator: the map file it serves, changed through ``setConfig``.

ARIA's map handler keeps the map file it loads in the configuration (section ``Files``, parameter ``Map``,
a path relative to its base folder) and loads a new one when a client sets it; ``mapUpdated`` follows.
The simulator does the same with its files folder (``--files``) as the base folder: a value names a
``.map`` file there (found as ARIA finds files: without regard to case, never through a dot entry or
outside the folder); one that is missing or does not read as a map is refused with the reason, and the
map served stays as it was. The served map's own file (``--map``, usually outside the folder) is
shown by its name until another is chosen.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rtmu.mapfile import MapFormatError, read_map
from rtmu.protocol.payloads.config import ConfigParam, ParamType, Priority

from .files_folder import files_folder, wire

if TYPE_CHECKING:
    from .context import SimHost

SECTION, NAME = "Files", "Map"
COMMENT = "The files where important data is stored"
TEMPLATE = ConfigParam(NAME, ParamType.STRING, "", "map file to load", Priority.BASIC)
"""ARIA registers it as IMPORTANT, which ArConfig's clients show with the basic parameters."""


def current(host: SimHost) -> str:
    """The served map as the parameter names it: its path in the files folder, else its file name."""
    path = host.config.map_path
    if path is None:
        return ""
    root = files_folder(host).root.resolve()
    try:
        return wire(path.resolve().relative_to(root).as_posix())
    except (OSError, ValueError):  # outside the folder (--map elsewhere): its name
        return wire(path.name)


def problem(host: SimHost, value: str) -> str:
    """Why ``value`` cannot become the served map ("" when it can)."""
    if not value or value == current(host):
        return ""
    path = files_folder(host).match(value)
    if path is None or not path.is_file():
        return f"there is no file {value!r} in the robot's files folder"
    try:
        read_map(path)
    except (MapFormatError, OSError, ValueError) as exc:
        return f"{value!r} cannot be read as a map: {exc}"
    return ""


def switch(host: SimHost, value: str) -> None:
    """Serve the map file ``value`` names (checked by :func:`problem` first): ``mapUpdated`` follows."""
    if not value or value == current(host):
        return
    path = files_folder(host).match(value)
    assert path is not None
    host.config.map_path = Path(path)
    host.file_md5 = b""  # a switch always loads (and says so), even a file with the same bytes
    host.check_map()
