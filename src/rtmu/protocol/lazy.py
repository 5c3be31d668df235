"""A package whose names are imported from their modules on first use (PEP 562).

``from rtmu.protocol import PacketDecoder`` keeps working, but importing one module of the
package (``rtmu.protocol.commands`` for a constant) no longer loads every other one with it:
the package's ``__init__`` lists where each name lives and imports nothing itself. Here, at the
bottom of the layers, so that ``protocol``, ``capture`` and ``recorder`` all may use it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def exports(package: str, homes: Mapping[str, str]) -> Callable[[str], Any]:
    """The ``__getattr__`` of ``package``: ``homes`` maps each exported name to its module."""

    def __getattr__(name: str) -> Any:
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(f"{package}.{home}"), name)

    return __getattr__
