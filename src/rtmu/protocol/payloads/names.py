"""Which module of this package defines the payload types of each data name.

The registry (:mod:`.base`) imports a payload module the first time a lookup needs one of its
names, so a command that decodes the status alone never builds the ~150 dataclasses of the
others (each costs a fraction of a millisecond to create: most of ``rtmu``'s start-up once).
Family names (``NameMatch.PREFIX``/``SUFFIX``: ``getPicture`` → ``getPictureCam1``,
``Current`` → ``sonarCurrent``) are listed as their ``DATA_NAME``.
``tests/protocol/test_payloads_registry.py`` checks this table against the registered types,
so a new payload type that is missing here fails the suite, naming the line to add.
"""

from __future__ import annotations

from typing import Final

MODULE_NAMES: Final[dict[str, tuple[str, ...]]] = {
    "camera": (
        "cameraInfo",
        "cameraListUpdated",
        "cameraModeUpdated",
        "cameraUpdate",
        "getCameraData",
        "getCameraInfo",
        "getCameraList",
        "getCameraModeList",
        "getPicture",
        "sendVideo",
        "setCameraAbs",
        "setCameraMode",
        "setCameraPct",
        "setCameraRel",
        "videoSize",
    ),
    "central": (
        "centralHeartbeat",
        "centralServerHeartbeat",
        "clientAdded",
        "clientList",
        "clientRemoved",
        "switch",
    ),
    "commands": ("listCommands", "listStringCommands"),
    "config": (
        "configCausingRestart",
        "configUpdated",
        "getConfigBySections",
        "getConfigBySectionsV2",
        "getConfigBySectionsV3",
        "getConfigBySectionsV4",
        "getConfigSectionFlags",
        "getLastEditablePriority",
        "setConfig",
    ),
    "configcare": (
        "checkMap",
        "configDefaultsUpdated",
        "getConfigDefaults",
        "reloadConfig",
        "setConfigParam",
    ),
    "drawings": ("getDrawingList", "listDrawings"),
    "drive": ("getSafeDrive", "moveDist", "ratioDrive", "setSafeDrive", "turnByAngle", "turnToHeading"),
    "files": (
        "deleteFile",
        "getDefaultUploadDownloadDir",
        "getDirListing",
        "getDirListingMultiplePackets",
        "getFile",
        "getFileWithTimestamp",
        "putFile",
        "putFileInterleaved",
        "putFileWithTimestamp",
        "putFileWithTimestampInterleaved",
    ),
    "ld": ("DataStore_", "dockInfo", "dockInfoChanged", "getRoutes", "gotoRouteGoal", "patrol", "say"),
    "map": (
        "getGoals",
        "getMap",
        "getMapBinary",
        "getMapId",
        "getMapMultiScans",
        "getMapName",
        "getMapWithMaxCategory",
        "goalsUpdated",
        "mapUpdated",
    ),
    "mapchange": ("mapChangesInProgress", "processMapChanges"),
    "mapping": (
        "mappingEnd",
        "mappingLoopEnd",
        "mappingLoopStart",
        "mappingStart",
        "mappingStatus",
        "mappingStatusBroadcast",
    ),
    "navigation": (
        "dock",
        "getLocState",
        "getPath",
        "goalName",
        "gotoGoal",
        "gotoPose",
        "home",
        "localizeToPose",
        "pathPlannerStatus",
        "tourGoals",
    ),
    "popup": ("popupClicked", "popupClose", "popupCreate", "popupList"),
    "robot": (
        "activityTimeInfo",
        "batteryInfo",
        "getModeDataList",
        "getModeInfo",
        "modeBusyChanged",
        "physicalInfo",
        "update",
        "updateNumbers",
        "updateStrings",
    ),
    "sensors": ("Cumulative", "Current", "getSensorCumulative", "getSensorCurrent", "getSensorList"),
    "server": (
        "getHeartbeatInterval",
        "heartbeatTcp",
        "heartbeatUdp",
        "identSetSelfIdentifier",
        "idleProcessingPending",
        "requestClientRestart",
    ),
    "strings": ("getStrings", "getStringsInfo"),
}
"""Payload module (of this package) → the data names its types are registered under."""

PAYLOAD_MODULES: Final = (*MODULE_NAMES, "control", "mapstream")
"""Every module of this package with payload types; ``control`` and ``mapstream`` hold none that
a data name finds (control packets go by command; a map stream is read by its reply's reader)."""
