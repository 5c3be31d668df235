"""The standard feeds of every session, in the order their subscriptions are made and their
``connected`` hooks run: the drive loop first (the guardian arms before anything else), status
before drawings (a shown sonar drawing takes over the status feed's sonar request), the map last
(its download is the longest answer); the commissioning feeds — files, scans, configuration care,
map changes — just before it. The feeds that only answer the operator (files, the console, the
server's commands) are named, not imported (:class:`~rtmu.client.lazy_feed.LazyFeed`): their
modules load with their first intent."""

from __future__ import annotations

from ..values.intents import (
    ConsoleCall,
    ConsoleFollow,
    ConsoleList,
    ConsoleNext,
    DeleteFile,
    DownloadFile,
    ListFiles,
    ListServerCommands,
    RunServerCommand,
    UploadFile,
)
from .config_care_feed import ConfigCareFeed
from .config_feed import ConfigFeed
from .drawings_feed import DrawingsFeed
from .drive_loop import DriveFeed
from .feed import Feed
from .lazy_feed import LazyFeed
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

FILES = LazyFeed("rtmu.client.files_feed", "FilesFeed", (ListFiles, DownloadFile, UploadFile, DeleteFile))
CONSOLE = LazyFeed(
    "rtmu.client.console_feed", "ConsoleFeed", (ConsoleList, ConsoleCall, ConsoleFollow, ConsoleNext)
)
COMMANDS = LazyFeed("rtmu.client.custom_commands", "CommandsFeed", (ListServerCommands, RunServerCommand))
LAZY: tuple[LazyFeed, ...] = (FILES, CONSOLE, COMMANDS)
"""The feeds imported on their first intent (each entry's ``handles`` checked against its class by
``tests/client/test_lazy_feed.py``)."""

FEEDS: tuple[type[Feed] | LazyFeed, ...] = (
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
    COMMANDS,
    FILES,
    ScanFeed,
    ConfigCareFeed,
    MapEditFeed,
    WhyFeed,
    CONSOLE,
    MapFeed,
)
