"""ArNetworking's control command numbers and small enumerations (protocol §2.2, §2.6).

The same number means different things in each direction (5 is TCP_ONLY from a
client but CONNECTED from a server), so there is one enum per direction.
Data numbers (256 and up) are assigned by each server at run time and are never
hard-coded: look them up by name in the data list.
"""

from __future__ import annotations

from enum import IntEnum

FIRST_DATA_NUMBER = 256

VERSION_TAG = "alpha"
"""The version string a server puts in its introduction (ARIA 2.9.1's servers send this one)."""


class ClientCommand(IntEnum):
    """Client → server control commands (``ArClientCommands.h``)."""

    SHUTDOWN = 1
    INTRODUCTION = 2
    UDP_INTRODUCTION = 3
    UDP_CONFIRMATION = 4
    TCP_ONLY = 5
    LIST = 128
    REQUEST = 129
    REQUESTSTOP = 130


class ServerCommand(IntEnum):
    """Server → client control commands (``ArServerCommands.h``)."""

    SHUTDOWN = 1
    INTRODUCTION = 2
    UDP_INTRODUCTION = 3
    UDP_CONFIRMATION = 4
    CONNECTED = 5
    REJECTED = 6
    TCP_ONLY = 7
    LIST = 129
    LISTSINGLE = 130
    LISTARGRET = 131
    LISTARGRETSINGLE = 132
    LISTGROUPANDFLAGS = 133
    LISTGROUPANDFLAGSSINGLE = 134


class ClientType(IntEnum):
    """The client type byte of the client INTRODUCTION (``ArServerCommands::Type``)."""

    UNSPECIFIED = 0
    REAL = 1
    SIMULATED = 2
    NONE = 3


class RejectReason(IntEnum):
    """Why a server refused a login (the ``byte2`` of REJECTED)."""

    BAD_USER_OR_PASSWORD = 1
    USING_CENTRAL_SERVER = 2
    CLIENT_PROTOCOL_MISMATCH = 3
    PROTOCOL_VERSION_MISMATCH = 4
    TOO_MANY_CLIENTS = 5
    CLIENT_TYPE_MISMATCH = 6

    @property
    def explanation(self) -> str:
        return _REJECT_TEXT[self]


_REJECT_TEXT = {
    RejectReason.BAD_USER_OR_PASSWORD: "wrong user name or password",
    RejectReason.USING_CENTRAL_SERVER: "the robot is managed by a central server",
    RejectReason.CLIENT_PROTOCOL_MISMATCH: "the server's protocol version does not match ours",
    RejectReason.PROTOCOL_VERSION_MISMATCH: "the server refuses our protocol version",
    RejectReason.TOO_MANY_CLIENTS: "the server has too many clients connected",
    RejectReason.CLIENT_TYPE_MISMATCH: "the server refuses this client type (real or simulated)",
}


def describe_reject(reason: int, text: str = "") -> str:
    """A readable sentence for a REJECTED packet, for operators and logs."""
    try:
        base = RejectReason(reason).explanation
    except ValueError:
        base = f"refused for an unknown reason ({reason})"
    return f"{base}: {text}" if text else base


def is_control_command(command: int) -> bool:
    return command < FIRST_DATA_NUMBER
