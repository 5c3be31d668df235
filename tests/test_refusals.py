"""A refused login in the operator's words (``base.refusals``), the same English the codec describes."""

from __future__ import annotations

import pytest

from rtmu.base.refusals import REFUSALS, protocol_refusal, refusal
from rtmu.protocol.commands import RejectReason, describe_reject


@pytest.mark.parametrize("reason", [*RejectReason, 9])
@pytest.mark.parametrize("text", ["", "Server rejecting connection"])
def test_the_english_is_the_codecs_for_every_reason(reason: int, text: str) -> None:
    """One English for a refusal: ``--json``, logs and ``rtmu decode`` read what the operator's words
    translate."""
    assert str(refusal(reason, text)) == describe_reject(reason, text)


def test_every_reason_the_codec_knows_has_words() -> None:
    assert set(REFUSALS) == {int(r) for r in RejectReason}


def test_a_refusal_reads_german_and_the_servers_own_text_stays_as_sent(german: None) -> None:
    said = refusal(RejectReason.TOO_MANY_CLIENTS, "Server rejecting connection (max 1)")
    assert said.words() == "am Server sind zu viele Clients angemeldet: Server rejecting connection (max 1)"
    assert str(said) == "the server has too many clients connected: Server rejecting connection (max 1)"
    assert refusal(42).words() == "aus unbekanntem Grund abgelehnt (42)"


def test_a_protocol_refusal_names_the_string_wanted_in_either_language(german: None) -> None:
    said = protocol_refusal("6MTX", "5MTX")
    assert str(said) == (
        "the server refuses our protocol version: it wants protocol '6MTX'; we sent '5MTX'. "
        "Use --protocol 6MTX"
    )
    assert said.words() == (
        "der Server lehnt unsere Protokollversion ab: er will Protokoll '6MTX'; wir sandten '5MTX'. "
        "--protocol 6MTX verwenden"
    )
