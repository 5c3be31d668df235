"""The configuration page's edit state without widgets: what the operator typed, what the server said.

Edits are kept by ``(section, name)`` until they are saved — across sections, pages, the
priority filter and refreshes — as the text ``setConfig`` sends. A fetched configuration that
already holds an edit's value (another client set exactly that) drops the edit; one that changed
under an open page is said in words, naming the operator's own unsaved edits it changed, and ends a
"✓ accepted" that is no longer the value held. A value out of its limits is never clamped silently:
the editor keeps the held value and the row says what was not taken and why. Saving
builds the :class:`~rtmu.values.intents.SetConfig` intent from the edits; the server's answer is
kept per parameter. The page (``ui.config_page``) only shows this state; keeping it GTK-free lets
the rules be tested without a display.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..base.i18n import _
from ..client.config_feed import ServerConfig, changed_values, check_value, names_param
from ..protocol.payloads.config import ConfigParam, ParamType, SetConfigReply
from ..values.intents import SetConfig

Key = tuple[str, str]
"""A parameter: (section name, parameter name)."""

MAX_CHANGES_NAMED = 5
"""Parameters named in the "another client changed …" note; the rest are counted."""


@dataclass(frozen=True, slots=True)
class RowNote:
    """What the page says beside a parameter: the words and their style (``edited``, ``error``, ``ok``)."""

    text: str = ""
    style: str = ""


def same_number(p: ConfigParam, text: str) -> bool:
    """A spin button's text for the value it started with ("2.00" for 2): not an edit."""
    if p.kind not in (ParamType.INT, ParamType.DOUBLE) or not isinstance(p.value, (int, float)):
        return False
    try:
        return float(text) == float(p.value)
    except ValueError:
        return False


def unchanged(p: ConfigParam, text: str) -> bool:
    """``text`` is the value the server holds for ``p`` (as it shows it, or as the same number)."""
    return text == p.value_text() or same_number(p, text)


class ConfigEdits:
    """See the module notes. ``config`` is the configuration last fetched (None before the first)."""

    def __init__(self) -> None:
        self.config: ServerConfig | None = None
        self.edits: dict[Key, str] = {}
        """Unsaved values (text, as ``setConfig`` sends them)."""
        self.answers: dict[Key, tuple[bool, str]] = {}
        """The server's last word on a parameter the operator saved: (accepted, text)."""
        self.accepted: dict[Key, str] = {}
        """The value each "✓ accepted" was for: another value fetched later ends that answer."""
        self.refused: dict[Key, str] = {}
        """A value the editor would not take (out of its limits), in words, until the next edit."""
        self._wrong: dict[Key, tuple[str, str]] = {}
        """The last wrong value typed in each editor, and why: said if the editor puts its value back."""
        self.fetches = 0

    # -- fetching ------------------------------------------------------------------------------
    def fetched(self, config: ServerConfig) -> None:
        """A newly fetched configuration: edits whose value the server now holds have nothing to save."""
        self.config = config
        self.fetches += 1
        for key, text in list(self.edits.items()):
            param = config.find(*key)
            if param is not None and unchanged(param, text):
                del self.edits[key]
        for key, text in list(self.accepted.items()):  # another client set something else since
            param = config.find(*key)
            if param is None or not unchanged(param, text):
                del self.accepted[key]
                self.answers.pop(key, None)

    def changes_note(self, old: ServerConfig, new: ServerConfig) -> str:
        """What another client changed between ``old`` and ``new``, and which unsaved edits it touched."""
        changed = changed_values(old, new)
        if not changed:
            return _("Another client saved the configuration; no value changed.")
        names = [_("{s}/{n} (now {v})").format(s=s, n=n, v=v) for s, n, v in changed[:MAX_CHANGES_NAMED]]
        more = (
            _(" and {value} more").format(value=len(changed) - MAX_CHANGES_NAMED)
            if len(changed) > MAX_CHANGES_NAMED
            else ""
        )
        text = _("Another client changed ") + ", ".join(names) + more + "."
        clashes = [f"{s}/{n}" for s, n, _now in changed if (s, n) in self.edits]
        if clashes:
            text += (
                _(" Your unsaved edit of ")
                + ", ".join(clashes[:MAX_CHANGES_NAMED])
                + _(" is kept: Save would overwrite their value.")
            )
        return text

    # -- editing -------------------------------------------------------------------------------
    def edit(self, key: Key, param: ConfigParam, text: str) -> bool:
        """The operator set ``param`` to ``text``; False when that changes nothing (an editor re-showing
        the value it holds, or the same edit again)."""
        was = self.edits.get(key)
        if unchanged(param, text):
            if was is None:
                return False
            del self.edits[key]
            wrong = self._wrong.pop(key, None)
            if wrong:  # the editor put its value back rather than take a wrong one: said, not silent
                self.refused[key] = _("✗ {value} not taken: {value2} (still {value_text})").format(
                    value=wrong[0], value2=wrong[1], value_text=param.value_text()
                )
        elif was == text:
            return False
        else:
            self.edits[key] = text
            self.refused.pop(key, None)
            typed = text.strip()
            why = check_value(param, text)
            if typed and why:  # (an editor empties itself before it shows a value: that is no typing)
                self._wrong[key] = (typed, why)
            elif typed:
                self._wrong.pop(key, None)
        self.answers.pop(key, None)
        self.accepted.pop(key, None)
        return True

    def invalid(self) -> dict[Key, str]:
        """Edits that are certainly wrong: key → why."""
        config = self.config
        out: dict[Key, str] = {}
        if config is None:
            return out
        for (section, name), text in self.edits.items():
            p = config.find(section, name)
            why = _("no longer offered by the server") if p is None else check_value(p, text)
            if why:
                out[(section, name)] = why
        return out

    def note(self, key: Key, param: ConfigParam) -> RowNote:
        """What the page says beside ``param``: an edit (or why it is wrong), else the server's answer."""
        if key in self.edits and key not in self.answers:
            why = check_value(param, self.edits[key])
            return RowNote(f"✗ {why}", "error") if why else RowNote("edited", "edited")
        if key in self.answers:
            ok, text = self.answers[key]
            return RowNote(text, "ok" if ok else "error")
        if key in self.refused:
            return RowNote(self.refused[key], "error")
        return RowNote()

    def can_save(self, saving: bool) -> bool:
        return bool(self.edits) and not self.invalid() and not saving

    def status(self) -> str:
        """The page's status line: how many parameters, left out, unsaved and invalid ("" before a fetch)."""
        config = self.config
        if config is None:
            return ""
        parts = [
            _("{param_count} parameters").format(param_count=config.param_count)
        ]  # separators are no parameters (param_count)
        if config.cut:
            parts.append(_("{cut} not shown (too many)").format(cut=config.cut))
        if self.edits:
            parts.append(_("{len} unsaved").format(len=len(self.edits)))
        bad = self.invalid()
        if bad:
            parts.append(_("{len} invalid").format(len=len(bad)))
        return ", ".join(parts)

    # -- saving --------------------------------------------------------------------------------
    def save_intent(self) -> tuple[dict[Key, str], SetConfig] | None:
        """Every edit as one ``SetConfig`` (all or nothing), with the edits it sends; None when there is
        nothing to save or an edit is certainly wrong."""
        if not self.edits or self.invalid():
            return None
        sent = dict(self.edits)
        changes: dict[str, dict[str, str]] = {}
        for (section, name), text in sent.items():
            changes.setdefault(section, {})[name] = text
        return sent, SetConfig(changes)

    def save_failed(self, sent: dict[Key, str], reason: str) -> None:
        """The set never got an answer (refused before sending, link lost): each edit says so and stays."""
        for key in sent:
            self.answers[key] = (False, _("✗ not saved: {reason}").format(reason=reason))

    def saved(self, sent: dict[Key, str], reply: SetConfigReply) -> str:
        """The server's answer to ``sent``; the words for the whole page when it blamed no parameter."""
        if reply.accepted:
            for key, text in sent.items():
                if self.edits.get(key) == text:  # typed again meanwhile: that edit is still to save
                    del self.edits[key]
                self.answers[key] = (True, _("✓ accepted"))
                self.accepted[key] = text
            return ""
        blamed = [k for k in sent if names_param(reply.error, *k)]
        for key in sent:
            self.answers[key] = (
                (False, f"✗ {reply.error}")
                if key in blamed
                else (False, _("not saved: the server refused the set"))
            )
        return "" if blamed else _("The server refused: {error}").format(error=reply.error)
