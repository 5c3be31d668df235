"""The window's words for the link's phases and levels, in the operator's language.

The enums' values (``connected``, ``stale``…) are names the code, the logs and the JSON share; what the
window shows goes through here so that it is translated and the values stay as they are.
"""

from __future__ import annotations

from ..base.i18n import N_, Said, _, error_words
from ..values.state import LinkLevel, Phase

_PHASES = {
    Phase.DISCONNECTED: N_("disconnected"),
    Phase.CONNECTING: N_("connecting"),
    Phase.CONNECTED: N_("connected"),
    Phase.RECONNECTING: N_("reconnecting"),
    Phase.FAILED: N_("failed"),
}
_LEVELS = {
    LinkLevel.DOWN: N_("down"),
    LinkLevel.OK: N_("ok"),
    LinkLevel.STALE: N_("stale"),
    LinkLevel.LOST: N_("lost"),
}


def phase_word(phase: Phase) -> str:
    """The connection's phase as the operator reads it (``connected``, ``reconnecting``…)."""
    return _(_PHASES[phase])


def level_word(level: LinkLevel) -> str:
    """The link's health as the operator reads it (``ok``, ``stale``, ``lost``, ``down``)."""
    return _(_LEVELS[level])


OFFERS_NONE = "this server does not offer "


def reason_words(reason: str) -> str:
    """Why a command is unavailable (``Command.unavailable``: marked English) in the operator's
    language; the server's request names it lists stay as the server spells them."""
    if reason.startswith(OFFERS_NONE):
        return _("this server does not offer {requests}").format(requests=reason.removeprefix(OFFERS_NONE))
    return _(reason) if reason else ""


def failure_words(error: BaseException | None) -> str:
    """Why a request came to nothing, in the operator's language: the error's own sentence (its
    :class:`Said` said in their language, else as raised), or "cancelled" when there is none."""
    return error_words(error) if error is not None else _("cancelled")


def sentence_words(sentence: str) -> str:
    """A "<problem> — <advice>" sentence of the client's (``client.diagnosis``) in the operator's
    language: each part its marked words translated, a part that names a host or a server's text as
    it is. A :class:`Said` sentence says itself, its values (numbers, names) included."""
    if isinstance(sentence, Said):
        return sentence.words()
    return " — ".join(_(part) for part in sentence.split(" — "))
