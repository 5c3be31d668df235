"""The standard feeds of every session, in the order their subscriptions are made and their
``connected`` hooks run: the drive loop first (the guardian arms before anything else), status
before drawings (a shown sonar drawing takes over the status feed's sonar request), the map last
(its download is the longest answer); the commissioning feeds — files, scans, configuration care,
map changes — just before it."""

from __future__ import annotations

from .config_care_feed import ConfigCareFeed
from .config_feed import ConfigFeed
from .console_feed import ConsoleFeed
from .custom_commands import CommandsFeed
from .drawings_feed import DrawingsFeed
from .drive_loop import DriveFeed
from .feed import Feed
from .files_feed import FilesFeed
from .ld_session import LdFeed
from .map_feed import MapFeed
from .mapedit_feed import MapEditFeed
from .nav_session import NavFeed
from .popups import PopupFeed
from .ptz import PtzFeed
from .scan_feed import ScanFeed
from .server_strings import StringsFeed
from .status_feed import StatusFeed
from .video_session import CameraFeed
from .why_feed import WhyFeed

FEEDS: tuple[type[Feed], ...] = (
    DriveFeed,
    StatusFeed,
    NavFeed,
    LdFeed,
    PopupFeed,
    StringsFeed,
    PtzFeed,
    ConfigFeed,
    CameraFeed,
    DrawingsFeed,
    CommandsFeed,
    FilesFeed,
    ScanFeed,
    ConfigCareFeed,
    MapEditFeed,
    WhyFeed,
    ConsoleFeed,
    MapFeed,
)
