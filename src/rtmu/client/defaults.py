"""The client's defaults that a command line shows before anything connects.

Apart from :mod:`.connection` (which re-exports them) so that ``rtmu SUB --help`` can say them
without loading asyncio and the codec.
"""

from __future__ import annotations

DEFAULT_PORT = 7272
"""ARIA's server port (``ArServerBase``'s default), and Omron LD robots'."""
CONNECT_TIMEOUT = 10.0
"""ARIA's own client gives up connecting after 10 s."""
MAX_FPS = 30.0
"""Live video: camera pictures asked for per second at most (a request per frame, one in flight)."""
MIN_FPS = 0.5
