"""Typed payloads of the standard ArNetworking services (protocol §4).

Importing this package registers every type, so :func:`payload_type_for`
finds a decoder by data name.
"""

from . import (
    camera,
    central,
    commands,
    config,
    configcare,
    control,
    drawings,
    drive,
    files,
    ld,
    map,
    mapchange,
    mapping,
    mapstream,
    navigation,
    popup,
    robot,
    sensors,
    server,
    strings,
)
from .base import (
    NameMatch,
    Payload,
    Side,
    decode_payload,
    payload_type,
    payload_type_for,
    register,
    registered,
)

__all__ = [
    "NameMatch",
    "Payload",
    "Side",
    "camera",
    "central",
    "commands",
    "config",
    "configcare",
    "control",
    "decode_payload",
    "drawings",
    "drive",
    "files",
    "ld",
    "map",
    "mapchange",
    "mapping",
    "mapstream",
    "navigation",
    "payload_type",
    "payload_type_for",
    "popup",
    "register",
    "registered",
    "robot",
    "sensors",
    "server",
    "strings",
]
