# ruff: noqa: E501
"""The simulator's catalogue of data, shaped like ARIA's serverDemo (protocol §2.7–2.8, Appendix A).

Names, command groups and flags follow serverDemo, in its registration order,
numbered from 256. Where serverDemo offers the same data, the description,
argument and return texts are the wire texts an ARIA server sends and clients
display, taken from a recording of serverDemo's list
(``tests/data/captures/clientCommandLister-serverDemoMap.pcap``; a test checks
them against it). Every text that appears in no capture — the popup data and
the simulator's own commands — is written in our own words. Data serverDemo
has that the simulator does not serve here (micro-controller pass-through,
the laser) are left out. Configuration editing (``CONFIG``) is answered by
:mod:`rtmu.sim.arconfig`.
"""

from __future__ import annotations

from rtmu.protocol.datalist import DataList

from .catalogue_camera import CAMERA
from .catalogue_row import Row

__all__ = ["CAMERA", "CONFIG", "CORE", "STRING_COMMANDS", "Row", "build_catalogue", "custom_commands"]

CORE: tuple[Row, ...] = (
    (
        "identSetSelfIdentifier",
        "Sets an arbitrary self identifier for this connection, this can be used by programs to send information back to the same client (if this and the identSetHereGoal)",
        "string: selfID",
        "none",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "identSetHereGoal",
        "Sets an string for the here goal for this connection, this can be used by programs to send information back to the same client (if this and the identSetSelfID match)",
        "string: hereGoal",
        "none",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "requestOnceReturnIsAlwaysTcp",
        "The presence of this command means that any requestOnce commands will have the data sent back to them as tcp... any requestOnceUdp will be returned either as tcp or udp (that is up to the callback sending the data)",
        "none",
        "none",
        "RobotInfo",
        "RETURN_NONE",
    ),
    (
        "idleProcessingPending",
        "The presence of this command means that the server will process packets flagged IDLE_PACKET only when the robot is idle.  This packet will be broadcast when the state of idle processing changes.",
        "none",
        "byte: 1 for idle processing pending, 0 for idle processing not pending",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "requestClientRestart",
        "If certain changes on the robot happen the clients may need to restart, this message is broadcast when those changes occur.",
        "none",
        "byte: restartNumber, which is 1 for a restart because of config changes (there will likely be more reasons later); string: human readable reason for restart.   (The restartNumber is intended for heavy weight clients, the string is intended for lighter weight clients.)",
        "RobotInfo",
        "RETURN_NONE",
    ),
    (
        "startRequestTransaction",
        "Special packet that marks the beginning of a multiple-packet request-response sequence. Must be followed by an endRequestTransaction packet upon completion.",
        "none",
        "",
        "RobotInfo",
        "RETURN_NONE",
    ),
    (
        "endRequestTransaction",
        "Special packet that marks the end of a multiple-packet request-response sequence. Idle processing does not proceed until transaction is ended.",
        "none",
        "",
        "RobotInfo",
        "RETURN_NONE",
    ),
    (
        "update",
        "gets an update about the important robot status (you should request this at an interval)... for bandwidth savings this is deprecated in favor of updateNumbers and updateStrings",
        "none",
        "string: status; string: mode; byte2: 10 * battery; byte4: x; byte4: y; byte2: th; byte2: transVel; byte2: rotVel, byte2: latVel, byte: temperature (deg c, -128 means unknown)",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "updateNumbers",
        "gets an update about the important robot status (you should request this at an interval)",
        "none",
        "byte2: 10 * battery; byte4: x; byte4: y; byte2: th; byte2: transVel; byte2: rotVel, byte2: latVel, byte: temperature (deg c, -128 means unknown)",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "updateStrings",
        "gets an update about the important robot status (you should ask for this at -1 interval since it is broadcast when the strings change)",
        "none",
        "string: status; string: mode; string: extended status (this has newlines)",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "batteryInfo",
        "gets the low battery voltage and shutdown voltage (you only need to request this once)",
        "none",
        "double: low battery voltage, double: shutdown battery voltage: ubyte: voltageIsStateOfCharge, if 0 voltage (including update voltage) is really voltage, if 1 voltage (including update voltage) is state of charge",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "physicalInfo",
        "gets the information about the physical robot (you only need to request this once)",
        "none",
        "string: robotType; string: robotSubType; byte2: robotWidth; byte2: robotLengthFront; byte2: robotLengthRear; byte: 0 means no lateral control, 1 means lateral control",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "activityTimeInfo",
        "Returns information about the active server mode's last activity time",
        "none",
        "byte4: seconds since",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "getSensorList",
        "gets a list of sensors attached to the robot",
        "none",
        "byte2: numSensors,  repeating for numSensors: string: sensorName",
        "SensorInfo",
        "RETURN_COMPLEX",
    ),
    (
        "getSensorCurrent",
        "gets the current sensor readings for requested sensors",
        "string: sensorName",
        "byte2: numReadings string: sensorName, repeating for numReadings times: byte4: x byte4: y.... if numReadings is -1 it means no sensor by that name",
        "SensorInfo",
        "RETURN_COMPLEX",
    ),
    (
        "getSensorCumulative",
        "gets the cumulative sensor readings for requested sensors",
        "string: sensorName",
        "byte2: numReadings string: sensorName, repeating for numReadings times: byte4: x byte4: y.... if numReadings is -1 it means no sensor by that name",
        "SensorInfo",
        "RETURN_COMPLEX",
    ),
    (
        "listDrawings",
        "Deprecated; use getDrawingList instead. Gets a list of things that can be drawn",
        "none",
        "byte4: numDrawings, <repeats numDrawings> string: name, string: shape, byte4: primaryColor(0RGB), byte4: size, byte4: layer, byte4: defaultRefreshTime(0 == don't request refresh), byte4: secondaryColor(0RGB)",
        "SensorInfo",
        "RETURN_SINGLE",
    ),
    (
        "getDrawingList",
        "Gets a list of items to be drawn on the map. Each packet contains one drawing.  Terminates on empty packet.",
        "none",
        "For each drawing, a packet that contains: string: name, string: shape, byte4: primaryColor(0RGB), byte4: size, byte4: layer, byte4: defaultRefreshTime(0 == don't request refresh), byte4: secondaryColor(0RGB), string: visibility",
        "SensorInfo",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getMapId",
        "Gets the ID of the map being used",
        "none",
        "string: map name (empty string if no maps)",
        "Map",
        "RETURN_SINGLE",
    ),
    (
        "getMapName",
        "gets the name of the map being used",
        "none",
        "string: map name (empty string if no maps)",
        "Map",
        "RETURN_SINGLE",
    ),
    (
        "getMapBinary",
        "gets the map objects as ascii and the data points as binary",
        "none",
        "packets of '<string>: line' for header, followed by packets of '<byte4>: numPtsInPacket, (<double>:x, <double>:y)*' until numPtsInPacket == 0",
        "Map",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getMapMultiScans",
        "Deprecated; getMapWithMaxCategory is preferred",
        "none",
        "packets of '<string>: line' for header, followed by packets of '<byte4>: numPtsInPacket, (<double>:x, <double>:y)*' until numPtsInPacket == 0",
        "Map",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getMapWithMaxCategory",
        "Requests the map with the specified maximum features; header and info are ascii, data points and lines are binary",
        "string: category (one of the constants defined in ArMapInterface)",
        "packets of '<string>: line' for header, followed by packets of '<byte4>: numPtsInPacket, (<double>:x, <double>:y)*' until numPtsInPacket == 0",
        "Map",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getMap",
        "gets the map as a set of ascii lines",
        "none",
        "packets of '<string>: line' followed by a packet with an empty string to denote end (if only empty string then no map)",
        "Map",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "mapUpdated",
        "a single packet is sent to this when the map is updated and this denotes a new getMap and getMapName should be requested",
        "none",
        "none",
        "Map",
        "RETURN_SINGLE",
    ),
    ("getGoals", "gets the list of goals", "none", "<repeat> string: goal", "Map", "RETURN_SINGLE"),
    (
        "goalsUpdated",
        "a single packet is sent to this when the goals are updated and this denotes a new getGoals should be requested",
        "none",
        "none",
        "Map",
        "RETURN_SINGLE",
    ),
    (
        "checkMap",
        "Requests that the server check whether the map needs to be read",
        "none",
        "none",
        "Map",
        "RETURN_NONE|IDLE_PACKET",
    ),
    (
        "getModeDataList",
        "Gets the list of commands associated with modes.",
        "none",
        "ubyte4: numData;  repeating numData times, string: mode; string: data",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "getModeInfo",
        "Gets the current mode active and if its locked and will or won't unlock (for lists of which commands are with which modes use getModeDataList) commands associated with modes.",
        "none",
        "string: mode; uByte: locked (1 == locked, 0 == unlocked); uByte: willUnlockIfRequested (1 == will, 0 == won't)",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    (
        "modeBusyChanged",
        "Broadcast when the busy state (non-zero idle time) of the active mode changes",
        "None",
        "byte: 1 if busy, 0 if idle",
        "RobotInfo",
        "RETURN_SINGLE",
    ),
    ("stop", "stops the robot", "none", "none", "Stop", "RETURN_NONE"),
    (
        "ratioDrive",
        "drives the robot as with a joystick",
        "double: transRatio (0,100); double: rotRatio (0,100); double: throttleRatio (0,100); [double: lateralRatio (0,100)] ",
        "none",
        "Movement",
        "RETURN_NONE",
    ),
    (
        "setSafeDrive",
        "sets whether we drive the robot safely or not",
        "byte: 1 == drive safely, 0 == drive unsafely",
        "none",
        "UnsafeMovement",
        "RETURN_NONE",
    ),
    (
        "getSafeDrive",
        "gets whether we drive the robot safely or not",
        "none",
        "byte: 1 == driving safely, 0 == driving unsafely",
        "Movement",
        "RETURN_SINGLE",
    ),
    ("wander", "makes the robot wander", "none", "none", "Movement", "RETURN_NONE"),
    (
        "moveDist",
        "drives the robot forward/backwards the given distance (mm)",
        "double: distanceToMove",
        "none",
        "Movement",
        "RETURN_NONE",
    ),
    (
        "turnByAngle",
        "rotate the robot by the given angle (deg)",
        "double: angleToTurn",
        "none",
        "Movement",
        "RETURN_NONE",
    ),
    (
        "turnToHeading",
        "rotate the robot to the given absolute heading (deg)",
        "double: heading",
        "none",
        "Movement",
        "RETURN_NONE",
    ),
    (
        "listCommands",
        "Gets a list of simple commands that can be sent to the server",
        "none",
        "byte2: numberOfCommands, <repeats numberOfCommands> string: name, string: description",
        "CustomCommands",
        "RETURN_SINGLE",
    ),
    (
        "listStringCommands",
        "Gets a list of commands that can be sent to the server with string arguments",
        "none",
        "byte2: numberOfCommands, <repeats numberOfCommands> string: name, string: description",
        "CustomCommands",
        "RETURN_SINGLE",
    ),
    (
        "ResetTripOdometer",
        "Resets the robot's trip odometer",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
)

SIM_COMMANDS: tuple[Row, ...] = (
    (
        "SimulatorResetPose",
        "Puts the simulated robot back on its home cairn, stopped",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorLowBattery",
        "Drains the simulated battery to just under the low-battery threshold (raises the low battery popup)",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorRecharge",
        "Recharges the simulated battery to full",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorSetBattery",
        "Sets the simulated battery voltage (string argument, volts)",
        "string: argumentToCommand",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorPopup",
        "Raises a popup on every client: title|message|button labels, comma separated|timeout in seconds",
        "string: argumentToCommand",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorPopupFlood",
        "Raises popups as fast as a hostile server would: popups per second, then seconds (e.g. 1000 3)",
        "string: argumentToCommand",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
)

VIDEO_COMMANDS: tuple[Row, ...] = (
    (
        "SimulatorVideo320x240",
        "Makes the simulated camera send 320x240 pictures (the default)",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorVideo640x480",
        "Makes the simulated camera send 640x480 pictures",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
)

UNSAFE_COMMANDS: tuple[Row, ...] = (
    (
        "safeRatioDrivingEnable",
        "Enables safe driving with ratioDrive, which will attempt to prevent collisions (default)",
        "none",
        "none",
        "UnsafeMovement",
        "RETURN_NONE",
    ),
    (
        "safeRatioDrivingDisable",
        "Disables safe driving with ratioDrive, this is UNSAFE and will let you drive your robot into things or down stairs, use at your own risk",
        "none",
        "none",
        "UnsafeMovement",
        "RETURN_NONE",
    ),
)

STRINGS: tuple[Row, ...] = (
    (
        "getStringsInfo",
        "Gets the information about the 'getStrings' command",
        "none",
        "uByte2: count; repeating count times  string: name, uByte2: maxlength",
        "NavigationInfo",
        "RETURN_SINGLE",
    ),
    (
        "getStrings",
        "Gets the strings, for info about them see getStringsInfo",
        "none",
        "repeating: string",
        "NavigationInfo",
        "RETURN_SINGLE",
    ),
)

_GET_RETURN = "Use ArClientHandlerConfig if desired."
_SET_RETURN = (
    "string: if empty setConfig worked, if the string isn't empty then it is the first error that occured "
    "(all non-error parameters are parsed, and only the first error is reported)"
)
CONFIG: tuple[Row, ...] = (
    # ARIA's own texts, as serverDemo lists them (tests/data/captures/clientCommandLister-serverDemoMap.pcap).
    (
        "getConfigBySectionsV4",
        "Gets the complete configuration information from the server",
        "none",
        "Advanced configuration retrieval, including handling of serializable.  " + _GET_RETURN,
        "ConfigEditing",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getConfigBySectionsV3",
        "Gets the complete configuration information from the server",
        "none",
        "Advanced configuration retrieval, including handling of very big sections.  " + _GET_RETURN,
        "ConfigEditing",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getConfigBySectionsV2",
        "Gets the complete configuration information from the server",
        "none",
        "Advanced configuration retrieval, including restart level and list objects.  " + _GET_RETURN,
        "ConfigEditing",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "getConfigBySections",
        "Gets the configuration information from the server",
        "none",
        "A single packet is sent for each config section.  Too complex to describe here.  " + _GET_RETURN,
        "ConfigEditing",
        "RETURN_UNTIL_EMPTY",
    ),
    (
        "setConfig",
        "takes a config back from the client to use",
        "Repeating pairs of strings which are parameter name and value to parse",
        _SET_RETURN,
        "ConfigEditing",
        "RETURN_SINGLE|IDLE_PACKET",
    ),
    (
        "configUpdated",
        "gets sent when the config is updated",
        "none",
        "none",
        "ConfigEditing",
        "RETURN_SINGLE",
    ),
    (
        "getConfigSectionFlags",
        "gets the flags for each section of the config",
        "none",
        "byte4: number of sections; repeating for number of sections (string: section; string: flags (separated by |))",
        "ConfigEditing",
        "RETURN_SINGLE",
    ),
    (
        "getLastEditablePriority",
        "Returns the last priority that may be edited by the user; e.g. EXPERT or FACTORY",
        "none",
        "byte: the last ArPriority::Priority value for which parameters may be edited",
        "ConfigEditing",
        "RETURN_SINGLE",
    ),
)

POPUPS: tuple[Row, ...] = (
    # No capture has ARIA's popup handler, so these texts are our own (names, groups and flags are ARIA's).
    (
        "popupCreate",
        "Broadcast when the robot raises a message box for the operator",
        "none (sent by the server only)",
        "byte4: popup id; string: ignoreIdentifier; string: title; string: message; byte: icon (0 none, 1 information, 2 warning, 3 critical, 4 question); string: label of button 0; string: label of button 1; string: label of button 2 (empty = no button); byte: default button; byte: escape button",
        "PopupGui",
        "RETURN_SINGLE",
    ),
    (
        "popupClose",
        "Broadcast when a message box is gone (answered or timed out)",
        "none (sent by the server only)",
        "byte4: popup id; string: text to show in its place",
        "PopupGui",
        "RETURN_SINGLE",
    ),
    (
        "popupClicked",
        "Tells the robot which button the operator pressed in a message box",
        "byte4: popup id; byte: button pressed (0-2)",
        "none",
        "PopupGui",
        "RETURN_NONE",
    ),
    (
        "popupList",
        "Asks for every message box still open, to show them after connecting",
        "none",
        "one popupCreate packet per open message box, then an empty packet",
        "PopupGui",
        "RETURN_NONE",
    ),
)

_DRAWING_DATA = "See getDrawingList for the information on how this drawing should be drawn, and the documentation in ArDrawingData for that information means."

DRAWINGS: tuple[Row, ...] = (
    ("sim_lms2xx_1Current", "", "none", _DRAWING_DATA, "SensorInfo", "RETURN_SINGLE"),
    ("sonarCurrent", "", "none", _DRAWING_DATA, "SensorInfo", "RETURN_SINGLE"),
)
"""The range devices' drawing data (``getDrawingList`` says how to draw each): laser, then sonar."""

STRING_COMMANDS = frozenset(
    {"SimulatorSetBattery", "SimulatorPopup", "SimulatorPopupFlood", "mappingLoopStart", "mappingLoopEnd"}
)
"""Simple commands that take one string argument (``listStringCommands``)."""


def custom_commands(camera: bool = True) -> tuple[Row, ...]:
    """What ``listCommands``/``listStringCommands`` list, in registration order."""
    rows = [r for r in CORE if r[0] == "ResetTripOdometer"]
    rows += SIM_COMMANDS
    if camera:
        rows += VIDEO_COMMANDS
    rows += UNSAFE_COMMANDS
    return tuple(rows)


def build_catalogue(camera: bool = True) -> DataList:
    """The data list a simulator serves; without a camera the video and camera data are absent."""
    rows = [*CORE, *SIM_COMMANDS]
    if camera:
        rows += VIDEO_COMMANDS
    rows += CONFIG
    rows += UNSAFE_COMMANDS
    if camera:
        rows += CAMERA
    rows += [*STRINGS, *POPUPS, *DRAWINGS]
    return DataList.build(rows)
