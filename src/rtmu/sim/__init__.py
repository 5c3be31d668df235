"""The bundled ARIA robot simulator: an ArNetworking server driving a simulated Pioneer 3-DX.

``SimServer`` runs on an asyncio loop you own; ``SimThread`` runs one on its
own thread. ``SimConfig(realtime=False)`` gives a clock that only moves when a
test calls ``advance``.
"""

from .config import SimConfig
from .server import SimServer
from .thread import SimThread
from .world import RobotSnapshot

__all__ = ["RobotSnapshot", "SimConfig", "SimServer", "SimThread"]
