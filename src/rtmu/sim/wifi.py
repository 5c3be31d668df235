"""A Wi-Fi access point on the map and the link the robot would have to it.

Log-distance path loss plus a fixed loss for every wall on the line of sight,
turned into the numbers Linux reports and ARIA's ``ArSystemStatus`` publishes:
signal level in dBm, noise in dBm and the link quality (0–70 scale of the
kernel's wireless extensions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .geometry import Obstacles

TX_AT_1M_DBM = -38.0
PATH_LOSS_EXPONENT = 2.4
WALL_LOSS_DB = 5.0
MAX_WALLS_COUNTED = 8
NOISE_DBM = -95
FLOOR_DBM = -100.0


@dataclass(frozen=True, slots=True)
class Link:
    signal_dbm: int
    noise_dbm: int
    quality: int
    """0..70, like ``/proc/net/wireless``'s link quality."""
    walls: int


class AccessPoint:
    def __init__(self, obstacles: Obstacles, x: float, y: float) -> None:
        self.obstacles = obstacles
        self.x = x
        self.y = y
        self.tx_at_1m_dbm = TX_AT_1M_DBM
        self.path_loss_exponent = PATH_LOSS_EXPONENT
        self.wall_loss_db = WALL_LOSS_DB
        """The model's parameters, per access point: the server's configuration changes them live."""

    def link(self, rx: float, ry: float) -> Link:
        d_m = max(math.hypot(rx - self.x, ry - self.y) / 1000.0, 1.0)
        walls = min(self.obstacles.segment_crossings(self.x, self.y, rx, ry), MAX_WALLS_COUNTED)
        loss = 10.0 * self.path_loss_exponent * math.log10(d_m) + self.wall_loss_db * walls
        signal = self.tx_at_1m_dbm - loss
        signal = max(signal, FLOOR_DBM)
        quality = int(max(0, min(70, round(signal + 110))))
        return Link(round(signal), NOISE_DBM, quality, walls)
