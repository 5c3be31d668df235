"""Why a robot's server refused a login, in the operator's words: ARIA's REJECTED reasons as sentences.

The codec keeps the same English for the wire's description (``RejectReason.explanation``: ``rtmu
decode``'s fields, logs); here it is marked for translation, so the command line, the window and the
guardian — which imports no client code — say a refusal in the operator's language, and ``--json``
and logs still read the English. ``tests/test_refusals.py`` keeps the two Englishes one.
"""

from __future__ import annotations

from .i18n import N_, Said, as_said

REFUSALS: dict[int, str] = {
    1: N_("wrong user name or password"),
    2: N_("the robot is managed by a central server"),
    3: N_("the server's protocol version does not match ours"),
    4: N_("the server refuses our protocol version"),
    5: N_("the server has too many clients connected"),
    6: N_("the server refuses this client type (real or simulated)"),
}
"""REJECTED's reason code (its ``byte2``) → the sentence (marked; translated where it is shown)."""
PROTOCOL_MISMATCH = 4


def refusal(reason: int, text: str = "") -> Said:
    """The refusal ``reason`` (a REJECTED code) with the server's own ``text`` after it, as sent."""
    known = REFUSALS.get(reason)
    said = as_said(known) if known else Said(N_("refused for an unknown reason ({reason})"), reason=reason)
    return Said(N_("{refusal}: {text}"), refusal=said, text=text) if text else said


def protocol_refusal(wanted: str, sent: str) -> Said:
    """A reason-4 refusal, and what to do about it: the protocol string the server wants (when it said)."""
    if wanted:
        return Said(
            N_("{refusal}: it wants protocol {wanted}; we sent {sent}. Use --protocol {option}"),
            refusal=refusal(PROTOCOL_MISMATCH),
            wanted=repr(wanted),
            sent=repr(sent),
            option=wanted,
        )
    return Said(
        N_(
            "{refusal}: we sent {sent} and it does not say which it wants; "
            "try --protocol 6MTX (Omron LD robots; older ones 5MTX)"
        ),
        refusal=refusal(PROTOCOL_MISMATCH),
        sent=repr(sent),
    )
