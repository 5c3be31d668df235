"""Why won't it move? — in the window: the one sentence, what to do, and the fix behind a confirmation.

Opened from the menu or its key (``?``), or from the hint a still held drive raises (``why_hint``).
It asks the selected robot (:class:`~rtmu.values.intents.AskWhy`, reads only: asking never moves
the robot) with what only the window knows — the drive held, the link as shown, a key ignored after
a stop — and shows the answer ``rtmu why`` gives: the first cause as one sentence and its advice,
the other causes, the server data each was read from, notes, and an LD robot's raw values (labelled
raw: their layouts are not public). A safety fact (a login that may not stop) is marked ⚠, and shown in
the error colour when it is the answer.

Where the cause has a fix (ask a locked mode to unlock, undock, end the server's navigation, switch
safe drive off, acknowledge an LD robot's faults, enable its motors) a button offers it; the button
only asks (``confirm_bar``) and the yes sends :class:`~rtmu.values.intents.ApplyFix` with
``confirmed`` — the network side finds the cause again before it sends anything, and the new answer
is shown. Its own window (transient for the main one): typing here never drives, Space still stops.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _, words  # noqa: E402
from ..base.textsafe import visible  # noqa: E402
from ..client.why_values import Answer, Fix  # noqa: E402
from ..control.intent_rules import FIX_WORDS  # noqa: E402
from ..values.intents import ApplyFix, AskWhy, Intent  # noqa: E402
from .confirm_bar import ConfirmBar  # noqa: E402
from .layout import fit_default_size, wrapping_row  # noqa: E402
from .state_words import failure_words, sentence_words  # noqa: E402

Request = Callable[[Intent], "concurrent.futures.Future[Any]"]
MAX_SHOWN = 600
"""Characters of one server-made text shown (a hostile server's words are bounded)."""
FIX_BUTTONS = {
    "unlock": N_("Ask the mode to unlock…"),
    "undock": N_("Undock…"),
    "stop": N_("Stop the navigation…"),
    "safe_drive_off": N_("Switch safe drive off…"),
    "acknowledge_faults": N_("Acknowledge the faults…"),
    "enable_motors": N_("Enable the motors…"),
}


def _short(text: str) -> str:
    text = visible(text)
    return text if len(text) <= MAX_SHOWN else text[: MAX_SHOWN - 1] + "…"


def answer_details(answer: Answer) -> str:
    """Everything below the sentence, as plain lines: the other causes, evidence, notes, raw values."""
    lines: list[str] = []
    first = answer.primary
    if first is not None and first.evidence:
        lines.append(_("Read from: ") + "; ".join(_short(words(e)) for e in first.evidence[:6]))
    for reason in answer.reasons[1:6]:
        lines.append(("⚠ " if reason.loud else _("Also: ")) + _short(sentence_words(reason.sentence())))
    lines += [_("Note: {short}").format(short=_short(words(n))) for n in answer.notes[:6]]
    lines += [_short(v.text()) for v in answer.raw[:10]]
    return "\n".join(lines)


def confirm_question(fix: Fix) -> str:
    """What the confirmation says: the fix in words, what is sent, and why a yes is asked."""
    risk = FIX_WORDS.get(fix.key, "")
    warn = _(" Careful: {risk}.").format(risk=_(risk)) if risk else ""
    return _("{short}. RTMU will send {sends} to the robot.{warn} Go ahead?").format(
        short=_short(words(fix.label)), sends=fix.sends, warn=warn
    )


class WhyWindow(Gtk.Window):
    """See the module notes. ``question()`` is the AskWhy with the window's side filled in now."""

    def __init__(self, parent: Gtk.Window | None, request: Request, question: Callable[[], AskWhy]) -> None:
        super().__init__(
            title=_("Why won't it move?"), transient_for=parent, modal=False, destroy_with_parent=True
        )
        fit_default_size(self, 560, 300)  # a 360 px phone: the window takes its width, no more
        self._request, self._question = request, question
        self.answer: Answer | None = None
        self.asking = False
        self.closed = False
        self.fix: Fix | None = None
        self._again = False
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=8)
        for side in ("start", "end", "top", "bottom"):
            getattr(box, f"set_margin_{side}")(12)
        self.sentence = Gtk.Label(wrap=True, xalign=0.0)
        self.sentence.add_css_class("title-3")
        self.sentence.set_max_width_chars(60)
        self.details = Gtk.Label(wrap=True, xalign=0.0, selectable=True)
        self.details.add_css_class("dim-label")
        self.details.set_max_width_chars(70)
        self.status = Gtk.Label(wrap=True, xalign=0.0)
        self.status.set_max_width_chars(60)  # a long answer wraps: never wider than a small screen
        for label in (self.sentence, self.details, self.status):
            label.set_wrap_mode(Pango.WrapMode.WORD_CHAR)  # a word longer than the line (a path) breaks too
        self.confirm = ConfirmBar()
        buttons = wrapping_row(at_most=3)  # on a phone, or in longer words, they wrap onto more lines
        self.fix_button = Gtk.Button(visible=False)
        self.fix_button.connect("clicked", lambda _b: self._offer_fix())
        self.again_button = Gtk.Button(label=_("Ask again"))
        self.again_button.connect("clicked", lambda _b: self.ask())
        close = Gtk.Button(label=_("Close"))
        close.connect("clicked", lambda _b: self.close())
        for button in (self.fix_button, self.again_button, close):
            buttons.append(button)
        # The answer scrolls, the confirmation and the buttons stay in view: on a small screen in a
        # language with longer words the window still fits, and a question asked is never scrolled away.
        answer = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=8)
        for label in (self.sentence, self.details, self.status):
            answer.append(label)
        scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_child(answer)
        for part in (scroller, self.confirm, buttons):
            box.append(part)
        self.set_child(box)
        self.set_focus(self.again_button)  # not the selectable details: focused, their text is all selected
        self.connect("close-request", self._closing)
        self.ask()

    # -- asking -------------------------------------------------------------------------------------
    def ask(self) -> None:
        """Ask the selected robot again (the answer replaces the one shown)."""
        if self.asking:
            self._again = True  # asked meanwhile (another robot selected): once more when this is in
            return
        self.asking = True
        self.confirm.cancel()
        self.status.set_text(_("Asking the robot…"))
        future = self._request(self._question())
        future.add_done_callback(lambda f: GLib.idle_add(self._answered, f))

    def _answered(self, future: concurrent.futures.Future[Any]) -> bool:
        self.asking = False
        if self.closed:
            return False
        if self._again:
            self._again = False
            self.ask()
            return False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self.status.set_text(_("No answer: {short}").format(short=_short(failure_words(error))))
            return False
        self.show_answer(future.result())
        self.status.set_text("")
        return False

    def show_answer(self, answer: Answer) -> None:
        self.answer = answer
        sentence = _short(sentence_words(answer.sentence()))  # problem — advice, each part translated
        first = answer.primary
        loud = first is not None and first.loud  # a safety fact (a login that may not stop): said loudly
        self.sentence.set_text(("⚠ " if loud else "") + sentence[:1].upper() + sentence[1:])
        if loud:
            self.sentence.add_css_class("error")
        else:
            self.sentence.remove_css_class("error")
        self.details.set_text(answer_details(answer))
        self.fix = first.fix if first is not None else None
        self.fix_button.set_visible(self.fix is not None)
        if self.fix is not None:
            self.fix_button.set_label(
                _(FIX_BUTTONS[self.fix.key]) if self.fix.key in FIX_BUTTONS else f"{self.fix.key}…"
            )

    # -- fixing -------------------------------------------------------------------------------------
    def _offer_fix(self) -> None:
        fix = self.fix
        if fix is None or self.asking:
            return
        self.confirm.ask(confirm_question(fix), _("Yes, send it"), lambda: self._apply(fix))

    def _apply(self, fix: Fix) -> None:
        self.asking = True
        self.status.set_text(_("Sending {sends}…").format(sends=fix.sends))
        navigate = self._question().navigate
        future = self._request(ApplyFix(key=fix.key, confirmed=True, navigate=navigate))
        future.add_done_callback(lambda f: GLib.idle_add(self._fixed, f))

    def _fixed(self, future: concurrent.futures.Future[Any]) -> bool:
        self.asking = False
        if self.closed:
            return False
        error = None if future.cancelled() else future.exception()
        if future.cancelled() or error is not None:
            self.status.set_text(_("Not done: {short}").format(short=_short(failure_words(error))))
            return False
        report = future.result()
        self.show_answer(report.answer)
        self.status.set_text(_short(report.message))
        if self._again:  # another robot was selected meanwhile: ask it
            self._again = False
            self.ask()
        return False

    def _closing(self, *_a: object) -> bool:
        self.closed = True
        return False
