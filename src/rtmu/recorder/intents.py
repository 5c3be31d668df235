"""The operator's intents, as they leave the controller for the network side.

:class:`IntentTap` stands in front of a client link (the runner) and passes every
attribute through; calls to the link's operator actions are also handed to
``record`` with their arguments — ``connect`` without its password. Anything that is
no operator action (heartbeats, ages, blocking keyring calls) passes unrecorded.
"""

from __future__ import annotations

import contextlib
import inspect
from collections.abc import Callable
from typing import Any

NOT_INTENTS = frozenset(
    {
        "run_blocking", "ui_heartbeat", "status_age", "loop_lag", "sync", "call", "submit",
        "subscribe", "image_source", "start", "close", "stop_and_wait", "stop_flushing",
    }
)  # fmt: skip
"""Public link methods that are plumbing, not something the operator asked the robot for."""
SECRET = frozenset({"password", "secret", "token"})

Record = Callable[[str, dict[str, Any]], None]


class IntentTap:
    """``IntentTap(runner, recorder.intent)``: behaves as ``runner``; operator actions are recorded first."""

    def __init__(self, inner: object, record: Record) -> None:
        object.__setattr__(self, "_inner", inner)
        object.__setattr__(self, "_record", record)

    def __getattr__(self, name: str) -> Any:
        value = getattr(self._inner, name)
        if name.startswith("_") or name in NOT_INTENTS or not callable(value):
            return value
        record: Record = self._record

        def tapped(*args: Any, **kwargs: Any) -> Any:
            with contextlib.suppress(Exception):  # recording never stands between operator and robot
                record(name, _arguments(value, args, kwargs))
            return value(*args, **kwargs)

        return tapped

    def __setattr__(self, name: str, value: Any) -> None:
        setattr(self._inner, name, value)


def _arguments(fn: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]) -> dict[str, Any]:
    """The call's arguments by name (secrets left out), or positionally when the signature is unknown."""
    try:
        bound = inspect.signature(fn).bind_partial(*args, **kwargs)
        named = dict(bound.arguments)
    except (TypeError, ValueError):
        named = {"args": list(args), **kwargs}
    extra = named.pop("args", None)
    out = {k: _plain(v) for k, v in named.items() if k not in SECRET}
    if extra:
        out["args"] = [_plain(v) for v in extra]
    return out


def _plain(value: Any) -> Any:
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return repr(value)[:200]
