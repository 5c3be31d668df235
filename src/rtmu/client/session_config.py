"""What a session is told when it is made (periods, timeouts, guardian, feeds); where it connects is a
:class:`~rtmu.values.target.Target`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from .mapcache import SharedMaps
from .reconnect import Backoff
from .roles import Role

if TYPE_CHECKING:
    from ..guardian.shared import GuardianSeat


@dataclass
class SessionConfig:
    status_interval_ms: int = 100
    """``updateNumbers`` period: the status stream is also the link's heartbeat."""
    sonar_interval_ms: int = 200
    wifi_interval_ms: int = 1000
    """``getStrings`` period (Wi-Fi gauges, and the details table while it is open)."""
    loc_state_interval_ms: int = 1000
    """``getLocState`` period, where the server offers it."""
    path_interval_ms: int = 500
    """``getPath`` period, only while the server navigates."""
    ping_interval: float = 1.0
    connect_timeout: float = 10.0
    reply_timeout: float = 5.0
    lost_after: float = 2.0
    ping_timeout: float | None = None
    """The longest a ping may go unanswered (None: ``health.PING_CEILING``; learned below it)."""
    fetch_map: bool = True
    backoff: Callable[[], Backoff] = field(default=Backoff)
    guardian: bool = False
    """Start a guardian process (:mod:`rtmu.guardian`) of this session's own for each connection that
    may drive: it stops the robot if this process is killed or frozen while driving (``rtmu bridge
    --allow-drive``). A window's sessions share one instead (:attr:`guardian_seat`)."""
    guardian_seat: GuardianSeat | None = field(default=None, compare=False)
    """This session's seat at the window's ONE guardian (``rtmu.guardian.shared``): armed for the
    robot the window lets drive, and no drive starts before it is (or could not be)."""
    shared_maps: SharedMaps | None = field(default=None, compare=False)
    """Maps shared with the process's other sessions (a fleet's window: one download per map file)."""
    extra_feeds: tuple[type[Any], ...] = ()
    """:class:`~rtmu.client.feed.Feed` classes besides the standard set (:data:`rtmu.client.feeds.FEEDS`):
    a new capability plugs in here."""
    role: Role = Role.OPERATOR
    """OBSERVER (a recorder, a read-only bridge, a replay): no motion request ever leaves (client.roles)."""
