"""Typed payloads of the standard ArNetworking services (protocol §4).

Importing this package registers every type, so :func:`payload_type_for`
finds a decoder by data name.
"""

from . import camera, drive, map, mapstream, robot, sensors
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
    "decode_payload",
    "drive",
    "map",
    "mapstream",
    "payload_type",
    "payload_type_for",
    "register",
    "registered",
    "robot",
    "sensors",
]
