"""ARIA ``.map`` files for the rest of RTMU: ``from rtmu.maps import read_map, MapData, ...``.

The implementation lives in the ``rtmu.mapfile`` package (one module per job:
tokens, header, numeric sections, reader, writer); this module is the stable
name the client, the simulator and the view import.
"""

from .mapfile import *  # noqa: F403
from .mapfile import __all__  # noqa: F401
