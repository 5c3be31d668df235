"""Typed payloads of the standard ArNetworking services (protocol §4).

The payload modules (``robot``, ``camera``, ``map`` …) are imported when first needed: by name
(``from rtmu.protocol.payloads import robot``) or by the registry, when
:func:`payload_type_for` is asked for one of their data names (:mod:`.names` says which module
holds which). :func:`registered` imports them all.
"""

from .base import (
    NameMatch,
    Payload,
    Side,
    decode_payload,
    load_all,
    payload_type,
    payload_type_for,
    register,
    registered,
)

__all__ = [
    "NameMatch",
    "Payload",
    "Side",
    "decode_payload",
    "load_all",
    "payload_type",
    "payload_type_for",
    "register",
    "registered",
]
