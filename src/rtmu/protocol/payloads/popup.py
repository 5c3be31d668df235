"""Server popups (protocol §4.9): the server asks the operator a question; the client answers.

Subscribe to ``popupCreate`` and ``popupClose`` with interval −1 to receive
them; ``popupList`` re-sends the open ones, then an empty ``popupList`` packet.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side, register


class PopupType(IntEnum):
    NONE = 0
    INFORMATION = 1
    WARNING = 2
    CRITICAL = 3
    QUESTION = 4


@register
@dataclass(frozen=True, slots=True)
class PopupCreate(Payload):
    """``popupCreate`` broadcast: one popup to show. Empty button labels mean "no such button"."""

    DATA_NAME = "popupCreate"
    SIDE = Side.REPLY

    popup_id: int
    ignore_identifier: str
    """Lets a client offer "don't show this again" per kind of popup."""
    title: str
    message: str
    popup_type: int = PopupType.INFORMATION
    """See :class:`PopupType` (kept as the wire's number)."""
    buttons: tuple[str, str, str] = ("OK", "", "")
    default_button: int = 0
    escape_button: int = 0

    def encode(self) -> bytes:
        if len(self.buttons) != 3:
            raise ValueError("a popup has exactly three button labels (empty = no button)")
        w = FieldWriter().byte4(self.popup_id).string(self.ignore_identifier).string(self.title)
        w.string(self.message).byte(self.popup_type)
        for label in self.buttons:
            w.string(label)
        return w.byte(self.default_button).byte(self.escape_button).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(
            r.byte4("popup id"),
            r.string("ignore identifier"),
            r.string("title"),
            r.string("message"),
            r.byte("popup type"),
            (r.string("button 0 label"), r.string("button 1 label"), r.string("button 2 label")),
            r.byte("default button"),
            r.byte("escape button"),
        )


@register
@dataclass(frozen=True, slots=True)
class PopupClose(Payload):
    """``popupClose`` broadcast: a popup went away (clicked, timed out); ``message`` says why."""

    DATA_NAME = "popupClose"
    SIDE = Side.REPLY

    popup_id: int
    message: str = ""

    def encode(self) -> bytes:
        return FieldWriter().byte4(self.popup_id).string(self.message).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte4("popup id"), r.string("close message"))


@register
@dataclass(frozen=True, slots=True)
class PopupClicked(Payload):
    """``popupClicked`` args: the operator pressed button 0–2 of a popup."""

    DATA_NAME = "popupClicked"
    SIDE = Side.ARGS

    popup_id: int
    button: int

    def encode(self) -> bytes:
        return FieldWriter().byte4(self.popup_id).byte(self.button).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte4("popup id"), r.byte("button"))


@register
@dataclass(frozen=True, slots=True)
class PopupListEnd(EmptyPayload):
    """``popupList`` reply: the empty packet after the re-sent ``popupCreate`` packets."""

    DATA_NAME = "popupList"
    SIDE = Side.REPLY
