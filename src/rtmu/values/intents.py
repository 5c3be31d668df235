"""Everything an operator can ask of one robot, as frozen values: the one vocabulary of the way in.

An intent leaves a widget (a key, a button, a menu row, a panel), goes to the *selected* robot's
controller — whose guard applies the safety rules to every intent alike: replay refusal, the
server's offer, "anything that moves the robot ends a held drive first", the recorder's tap —
and crosses to the network thread in ONE hop (``ClientRunner.send``), where the session hands
it to the feed that handles its type. Typed :class:`~rtmu.values.state.StateChange` values come
back the other way. Nothing here imports the client, GTK or asyncio.

Each class says, as class attributes, what the guard needs to know:

* ``moves`` — it starts or changes the robot's motion (a jog, a goal, a server command that may
  drive): a held drive ends before it is sent, a replay refuses it, an observer can never send it.
* ``needs`` — the data the server must list for it (any one of them); empty: always offered.
* ``label`` — how the operator calls it, for refusals ("Go to goal: not connected").
* ``kind`` — the notice kind its failure is told with (so the window shows it where it belongs).

The held drive itself is not an intent that crosses: keys grant and renew the drive lease, which
the network side turns into ``ratioDrive`` (see :mod:`rtmu.client.lease`). :class:`Stop` ends it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

from ..base.notices import Kind
from ..mapfile.model import MapObject


@dataclass(frozen=True)
class Intent:
    """The base of every intent; see the module notes for the class attributes."""

    moves: ClassVar[bool] = False
    needs: ClassVar[tuple[str, ...]] = ()
    label: ClassVar[str] = "Request"
    kind: ClassVar[Kind] = Kind.COMMAND
    """Where a failure is told to the operator (the navigation banner, the camera page…)."""

    @classmethod
    def offered(cls, offers: Collection[str]) -> bool:
        """Whether a server listing ``offers`` can carry this intent out (``needs``: any one of them)."""
        return not cls.needs or any(name in offers for name in cls.needs)

    def record(self) -> dict[str, Any]:
        """The intent's fields as plain JSON values, for the flight recorder (no secret is ever an intent)."""
        return {k: _plain(v) for k, v in _fields(self).items()}


def _fields(intent: Intent) -> dict[str, Any]:
    return {f.name: getattr(intent, f.name) for f in dataclasses.fields(intent)}


def _plain(value: Any) -> Any:
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):  # a map object of a change set
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    return repr(value)[:200]


# -- motion ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Stop(Intent):
    """Zero ratios and ``stop`` now, whatever the link looks like; also ends a navigation."""

    label: ClassVar[str] = "Stop"
    reason: str = "stop key"


@dataclass(frozen=True)
class TurnBy(Intent):
    """Turn in place by ``degrees`` (positive: left), the server's ``turnByAngle``."""

    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("turnByAngle",)
    label: ClassVar[str] = "Turn by an angle"
    degrees: float = 0.0


@dataclass(frozen=True)
class MoveDistance(Intent):
    """Drive ``mm`` straight (negative: backwards), the server's ``moveDist``."""

    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("moveDist",)
    label: ClassVar[str] = "Go a distance"
    mm: float = 0.0


@dataclass(frozen=True)
class SetSafeDrive(Intent):
    """Switch the server's safe drive (obstacle slow-down) on or off."""

    needs: ClassVar[tuple[str, ...]] = ("setSafeDrive",)
    label: ClassVar[str] = "Safe drive"
    on: bool = True


# -- navigation: the server drives ---------------------------------------------------------------
@dataclass(frozen=True)
class GotoGoal(Intent):
    """Drive to the map's goal ``name`` (``gotoGoal``; an LD robot's ``gotoRouteGoal``).

    ``route``: as one of an LD robot's route goals (``gotoRouteGoal``, where listed), as its routes
    panel sends it; otherwise ``gotoRouteGoal`` only where ``gotoGoal`` is not listed."""

    kind: ClassVar[Kind] = Kind.NAVIGATION
    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("gotoGoal", "gotoRouteGoal")
    label: ClassVar[str] = "Go to goal"
    name: str = ""
    route: bool = False


@dataclass(frozen=True)
class GotoPose(Intent):
    """Drive to (x, y) mm on the map, facing ``th`` degrees when given (``gotoPose``)."""

    kind: ClassVar[Kind] = Kind.NAVIGATION
    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("gotoPose",)
    label: ClassVar[str] = "Go to point"
    x: float = 0.0
    y: float = 0.0
    th: float | None = None


@dataclass(frozen=True)
class GoHome(Intent):
    kind: ClassVar[Kind] = Kind.NAVIGATION
    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("home",)
    label: ClassVar[str] = "Go home"


@dataclass(frozen=True)
class Dock(Intent):
    kind: ClassVar[Kind] = Kind.NAVIGATION
    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("dock",)
    label: ClassVar[str] = "Dock"


@dataclass(frozen=True)
class TourGoals(Intent):
    kind: ClassVar[Kind] = Kind.NAVIGATION
    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("tourGoals",)
    label: ClassVar[str] = "Tour goals"


@dataclass(frozen=True)
class Patrol(Intent):
    """Patrol one of an LD robot's routes (``patrol``)."""

    kind: ClassVar[Kind] = Kind.NAVIGATION
    moves: ClassVar[bool] = True
    needs: ClassVar[tuple[str, ...]] = ("patrol",)
    label: ClassVar[str] = "Patrol"
    route: str = ""


@dataclass(frozen=True)
class Localize(Intent):
    """Tell the server where the robot is (``localizeToPose``): it does not move the robot."""

    kind: ClassVar[Kind] = Kind.NAVIGATION
    needs: ClassVar[tuple[str, ...]] = ("localizeToPose",)
    label: ClassVar[str] = "Set position"
    x: float = 0.0
    y: float = 0.0
    th: float = 0.0


# -- the robot's voice, camera and head -----------------------------------------------------------
@dataclass(frozen=True)
class Say(Intent):
    """Text to speech on an LD robot (``say``)."""

    needs: ClassVar[tuple[str, ...]] = ("say",)
    label: ClassVar[str] = "Say"
    text: str = ""


def picture_source(offers: Iterable[str]) -> str | None:
    """The data a picture is asked with: the first ``getPicture…`` listed, else ``sendVideo``, else None.

    The one rule, for the window's enabling (from the offered names) and the client alike."""
    names = set(offers)
    pictures = sorted(n for n in names if n.startswith("getPicture"))
    if pictures:
        return pictures[0]
    return "sendVideo" if "sendVideo" in names else None


@dataclass(frozen=True)
class RequestPicture(Intent):
    """One camera picture (the first ``getPicture…``, else ``sendVideo``)."""

    @classmethod
    def offered(cls, offers: Collection[str]) -> bool:
        return picture_source(offers) is not None

    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Camera picture"


@dataclass(frozen=True)
class StartVideo(Intent):
    """Live video at up to ``fps`` frames a second and JPEG ``quality`` (None: keep the last)."""

    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Live video"
    fps: float | None = None
    quality: int | None = None

    @classmethod
    def offered(cls, offers: Collection[str]) -> bool:
        return picture_source(offers) is not None


@dataclass(frozen=True)
class StopVideo(Intent):
    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Live video"


@dataclass(frozen=True)
class PauseVideo(Intent):
    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Live video"
    paused: bool = True


@dataclass(frozen=True)
class VideoShown(Intent):
    """Backpressure: the window has painted live frame ``sequence`` (the next may be asked for)."""

    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Live video"
    sequence: int = 0


@dataclass(frozen=True)
class PtzMove(Intent):
    """Point the camera head: by (``relative``) or to pan/tilt degrees and zoom %; never moves the robot."""

    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Camera head"
    pan: float = 0.0
    tilt: float = 0.0
    zoom: float | None = None
    relative: bool = True


@dataclass(frozen=True)
class WatchPtz(Intent):
    """Poll the camera head's position while the camera page shows it (``on``)."""

    kind: ClassVar[Kind] = Kind.CAMERA
    label: ClassVar[str] = "Camera head"
    on: bool = True


# -- what the server shows and offers --------------------------------------------------------------
@dataclass(frozen=True)
class WatchStrings(Intent):
    """Ask for the server's status strings while the details table is open (``on``)."""

    label: ClassVar[str] = "Robot details"
    on: bool = True


@dataclass(frozen=True)
class ShowDrawing(Intent):
    """Show or hide one of the server's drawings: a hidden one is no longer asked for."""

    label: ClassVar[str] = "Layers"
    name: str = ""
    shown: bool = True


@dataclass(frozen=True)
class DrawingChoices(Intent):
    """The operator's remembered drawing choices for the server being connected to."""

    label: ClassVar[str] = "Layers"
    choices: Mapping[str, bool] = field(default_factory=dict)


@dataclass(frozen=True)
class LoadMap(Intent):
    kind: ClassVar[Kind] = Kind.MAP
    label: ClassVar[str] = "Map"


@dataclass(frozen=True)
class AnswerPopup(Intent):
    """The operator pressed ``button`` of the server's popup ``popup_id`` (``popupClicked``)."""

    kind: ClassVar[Kind] = Kind.SERVER
    label: ClassVar[str] = "Server message"
    popup_id: int = 0
    button: int = 0


@dataclass(frozen=True)
class ListServerCommands(Intent):
    """The simple and string commands this user may run (``listCommands``, ``listStringCommands``)."""

    label: ClassVar[str] = "Server commands"


@dataclass(frozen=True)
class RunServerCommand(Intent):
    """Run one of the server's own commands; it may drive the robot (``wander``), so it counts as moving."""

    moves: ClassVar[bool] = True
    label: ClassVar[str] = "Server command"
    name: str = ""
    argument: str | None = None
    string: bool = False
    """A string command (``listStringCommands``) takes ``argument``; a simple one takes none."""


@dataclass(frozen=True)
class FetchConfig(Intent):
    """The server's whole configuration (``getConfigBySections*``)."""

    label: ClassVar[str] = "Configuration"


@dataclass(frozen=True)
class SetConfig(Intent):
    """Change configuration values: section → parameter → text (``setConfig``, all or nothing).

    No ``needs``: the configuration feed says in plain words which configuration a robot has, also
    one RTMU cannot edit (an LD robot's ``setConfigValues``)."""

    label: ClassVar[str] = "Configuration"
    changes: Mapping[str, Mapping[str, str]] = field(default_factory=dict)


# -- commissioning: files, scans, map changes, configuration care ----------------------------------
FILE_LISTING = ("getDirListingMultiplePackets", "getDirListing")
FILE_DOWNLOAD = ("getFileWithTimestamp", "getFile")
FILE_UPLOAD = ("putFileWithTimestamp", "putFile", "putFileWithTimestampInterleaved", "putFileInterleaved")


@dataclass(frozen=True)
class ListFiles(Intent):
    """One folder on the robot (relative to the folder its ``ArServerFileUtils`` shares; "" is that one)."""

    needs: ClassVar[tuple[str, ...]] = FILE_LISTING
    label: ClassVar[str] = "Files on the robot"
    folder: str = ""


@dataclass(frozen=True)
class DownloadFile(Intent):
    """Fetch ``remote`` into the local file ``local`` (streamed to disk; the name taken only at the end).

    ``size``: the listed size, when the asker has it (the progress's total and the download's bound)."""

    needs: ClassVar[tuple[str, ...]] = FILE_DOWNLOAD
    label: ClassVar[str] = "Download"
    remote: str = ""
    local: str = ""
    size: int | None = None
    overwrite: bool = False


@dataclass(frozen=True)
class UploadFile(Intent):
    """Send the local file ``local`` to ``remote`` on the robot (the robot keeps its old file on refusal)."""

    needs: ClassVar[tuple[str, ...]] = FILE_UPLOAD
    label: ClassVar[str] = "Upload"
    local: str = ""
    remote: str = ""


@dataclass(frozen=True)
class DeleteFile(Intent):
    needs: ClassVar[tuple[str, ...]] = ("deleteFile",)
    label: ClassVar[str] = "Delete"
    remote: str = ""


@dataclass(frozen=True)
class StartScan(Intent):
    """Start logging a scan for a map into ``<name>.2d`` (``mappingStart``); the operator then drives."""

    kind: ClassVar[Kind] = Kind.MAP
    needs: ClassVar[tuple[str, ...]] = ("mappingStart",)
    label: ClassVar[str] = "Scan a map"
    name: str = ""


@dataclass(frozen=True)
class StopScan(Intent):
    """End the scan (``mappingEnd``); the answer is the scan's file name ("" when the robot does not say)."""

    kind: ClassVar[Kind] = Kind.MAP
    needs: ClassVar[tuple[str, ...]] = ("mappingEnd",)
    label: ClassVar[str] = "Stop the scan"


@dataclass(frozen=True)
class TagScanLoop(Intent):
    """Mark where a loop starts (``start``) or ends while scanning (``mappingLoopStart`` / ``…End``)."""

    kind: ClassVar[Kind] = Kind.MAP
    needs: ClassVar[tuple[str, ...]] = ("mappingLoopStart",)
    label: ClassVar[str] = "Loop tag"
    start: bool = True


@dataclass(frozen=True)
class ApplyMapChanges(Intent):
    """One change set to the map (``processMapChanges``): these objects deleted, these added.

    ``generation``: the published map the draft was made on; the feed refuses the change, sending
    nothing, when the map shown has changed since (the server would refuse it anyway)."""

    kind: ClassVar[Kind] = Kind.MAP
    needs: ClassVar[tuple[str, ...]] = ("processMapChanges",)
    label: ClassVar[str] = "Apply map changes"
    removed: tuple[MapObject, ...] = ()
    added: tuple[MapObject, ...] = ()
    generation: int = 0


@dataclass(frozen=True)
class SwitchMap(Intent):
    """Make the robot's file ``path`` its active map: ARNL's ``Files/Map`` parameter, then ``checkMap``."""

    kind: ClassVar[Kind] = Kind.MAP
    needs: ClassVar[tuple[str, ...]] = ("setConfig",)
    label: ClassVar[str] = "Switch map"
    path: str = ""


@dataclass(frozen=True)
class FetchConfigDefaults(Intent):
    """The factory value of every parameter (``getConfigDefaults``: only where the server keeps them)."""

    needs: ClassVar[tuple[str, ...]] = ("getConfigDefaults",)
    label: ClassVar[str] = "Factory values"


@dataclass(frozen=True)
class ResetConfig(Intent):
    """Put factory values back: section → parameter → factory text (one ``setConfigParam`` for a single
    parameter where offered, else one ``setConfig``)."""

    needs: ClassVar[tuple[str, ...]] = ("setConfig", "setConfigParam")
    label: ClassVar[str] = "Reset to default"
    changes: Mapping[str, Mapping[str, str]] = field(default_factory=dict)


# -- why won't it move? and the console -------------------------------------------------------------
FIXES_NEEDING_YES = frozenset({"safe_drive_off", "acknowledge_faults", "enable_motors"})
"""Fixes (``client.why_values.Fix.key``) that change how the robot protects itself or act on a robot
whose layouts are not public: the guard refuses :class:`ApplyFix` for them without ``confirmed``."""


@dataclass(frozen=True)
class AskWhy(Intent):
    """Why won't it move? Everything the server's own data says, plus our side, as one answer (reads only).

    The window says what only it knows: the drive asked for (``trans``/``rot`` in %: an obstacle then
    matters only that way), the link as it shows it, and whether a held key is ignored after a stop."""

    label: ClassVar[str] = "Why won't it move?"
    navigate: bool = False
    """The question is about navigation (a lost localization counts)."""
    trans: float = 0.0
    rot: float = 0.0
    link: str = ""
    """The link level the window shows (``LinkLevel`` value); "" when not known."""
    keys_blocked: bool = False


@dataclass(frozen=True)
class ApplyFix(Intent):
    """Carry out the fix of a cause "why won't it move?" found (``Fix.key``), then ask again.

    The network side finds the cause again from the server's data before it sends anything, so only a
    fix the robot still needs is made. Counted as moving: undocking backs the robot out, unlocking or
    acknowledging gives the drive back. ``confirmed``: the operator said yes to what it will do."""

    moves: ClassVar[bool] = True
    label: ClassVar[str] = "Fix"
    key: str = ""
    confirmed: bool = False
    navigate: bool = False


@dataclass(frozen=True)
class ConsoleList(Intent):
    """The server's whole data list with its descriptions, as the console reads it (``text``: a filter)."""

    label: ClassVar[str] = "Console"
    text: str = ""


@dataclass(frozen=True)
class ConsoleCall(Intent):
    """Call any data the server lists once, with the operator's words as its arguments.

    ``types`` names the arguments' types where the data's description does not; ``confirmed``: the
    operator said yes to a call that changes something (a motion request never goes without it)."""

    label: ClassVar[str] = "Console"
    name: str = ""
    arguments: tuple[str, ...] = ()
    types: tuple[str, ...] = ()
    confirmed: bool = False


@dataclass(frozen=True)
class ConsoleFollow(Intent):
    """Follow a data at ``interval_ms`` (−1: only what the server broadcasts), or stop following it (``on``).

    A data that changes something is never followed (it would be repeated at every interval)."""

    label: ClassVar[str] = "Console"
    name: str = ""
    interval_ms: int = 1000
    arguments: tuple[str, ...] = ()
    types: tuple[str, ...] = ()
    on: bool = True


@dataclass(frozen=True)
class ConsoleNext(Intent):
    """The replies that arrived for the followed data ``name``, waiting up to ``wait`` s for the first."""

    label: ClassVar[str] = "Console"
    name: str = ""
    wait: float = 0.5
