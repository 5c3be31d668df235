"""Server popups in the real window: cards over the map, answered by real clicks, never the focus.

Real window, real simulator, real X input. What is checked: the card's texts exactly as the server
sent them (markup is not parsed), the simulator's record of the popupClicked it heard, the card
going with the server's popupClose, a drive key held while a card appears still driving, and a
hostile server's flood (1 000 popups a second) costing bounded widgets and memory while the window
keeps answering keys.
"""

from __future__ import annotations

import resource
import time
from typing import Any

from rtmu.sim import SimThread
from rtmu.ui.popups import MAX_CARDS
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump

sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def raise_popup(sim: SimThread, title: str, message: str, **kw: Any) -> int:
    world = sim.server.world  # type: ignore[union-attr]
    return int(sim.call(lambda: world.create_popup(title, message, **kw)).id)


def card_texts(gui: Gui, pid: int) -> list[str]:
    """Every label's text on the card, as Pango lays it out (markup, if parsed, would be gone)."""
    from gi.repository import Gtk

    card = gui.window.popup_stack.cards[pid]
    texts, stack = [], [card.box]
    while stack:
        w = stack.pop()
        child = w.get_first_child()
        while child is not None:
            stack.append(child)
            child = child.get_next_sibling()
        if isinstance(w, Gtk.Label):
            assert not w.get_use_markup()
            texts.append(w.get_layout().get_text())
    return texts


def told(gui: Gui, text: str) -> bool:
    """The window showed ``text`` in a banner (the server's closing words, a Kind.SERVER notice)."""
    return any(t == text for _topic, _level, t in gui.window.banners.history)


def moving(sim: SimThread) -> bool:
    return abs(sim.snapshot().vel) > 1.0


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 1e6


def test_a_card_shows_the_popup_and_a_click_answers_it(gui: Gui, sim: SimThread) -> None:
    stack = gui.window.popup_stack
    pid = raise_popup(
        sim, "Door closed", "The lab door is shut. Open it?", kind=4, buttons=("Open", "Wait", "Skip"),
        pressed=("Opening", "Waiting", "Skipped"),
    )  # fmt: skip
    pump(lambda: pid in stack.cards, 5, "the card")
    texts = card_texts(gui, pid)
    assert "Door closed" in texts and "The lab door is shut. Open it?" in texts
    assert {"Open", "Wait", "Skip"} <= set(texts)
    card = stack.cards[pid]
    assert not any(b.get_focusable() for b in card.buttons), "a card never takes the keyboard"
    gui.shot("card")
    gui.click(card.buttons[1])
    world = sim.server.world  # type: ignore[union-attr]
    pump(lambda: (pid, 1) in sim.call(lambda: list(world.popup_clicks)), 5, "popupClicked at the simulator")
    pump(lambda: pid not in stack.cards, 5, "the card to go with popupClose")
    pump(lambda: told(gui, "Door closed: Waiting"), 3, "the closing words")
    gui.shot("answered")


def test_popup_close_from_the_server_removes_the_card_with_its_text(gui: Gui, sim: SimThread) -> None:
    stack = gui.window.popup_stack
    pid = raise_popup(sim, "Charging", "Docked and charging", kind=1)
    pump(lambda: pid in stack.cards, 5, "the card")
    world = sim.server.world  # type: ignore[union-attr]
    assert sim.call(lambda: world.close_popup(pid, "Charged: 13.1 V"))
    pump(lambda: pid not in stack.cards, 5, "the card to go")
    pump(lambda: told(gui, "Charging: Charged: 13.1 V"), 3, "the closing words")
    assert not stack.get_visible()
    gui.shot("closed-by-server")


def test_markup_in_server_text_is_shown_literally(gui: Gui, sim: SimThread) -> None:
    title, message = "<b>Bold</b> & <i>sure</i>", "a &amp; b <span foreground='red'>red</span> &lt;"
    pid = raise_popup(sim, title, message, kind=3, buttons=("<u>OK</u>", "", ""))
    pump(lambda: pid in gui.window.popup_stack.cards, 5, "the card")
    texts = card_texts(gui, pid)
    assert title in texts and message in texts and "<u>OK</u>" in texts
    gui.shot("markup-literal")


def test_a_held_drive_key_keeps_driving_while_a_card_appears(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    gui.keydown("Up")
    try:
        pump(lambda: moving(sim), 8, "the robot to move")
        pid = raise_popup(sim, "Obstacle ahead", "Something is in the way", kind=2)
        pump(lambda: pid in window.popup_stack.cards, 5, "the card")
        before = sim.call(lambda: sim.server.world.ratio_drives_received)  # type: ignore[union-attr]
        idle(1.0)
        after = sim.call(lambda: sim.server.world.ratio_drives_received)  # type: ignore[union-attr]
        assert window.is_active(), "the window keeps the keyboard"
        focus = window.get_focus()
        assert focus is None or not focus.is_ancestor(window.popup_stack), "the card took the focus"
        assert window.controller.held, "the key is still held"
        assert after - before >= 5, f"only {after - before} ratioDrive in a second while the key was held"
        assert moving(sim)
        gui.shot("driving-with-card")
    finally:
        gui.keyup("Up")
    pump(lambda: not moving(sim), 8, "the robot to stop after the release")


def key_latency(gui: Gui, key: str, changed: Any) -> float:
    started = time.monotonic()
    gui.key(key)
    pump(changed, 5, f"{key} to take effect")
    return time.monotonic() - started


def test_a_flood_of_popups_stays_bounded_plain_and_the_window_keeps_answering(
    gui: Gui, sim: SimThread
) -> None:
    window, stack = gui.window, gui.window.popup_stack
    world = sim.server.world  # type: ignore[union-attr]
    idle(0.5)
    rss_before = rss_mb()
    rebuilds_before = stack.rebuilds
    sim.call(lambda: world.flood_popups(1000, 4.0))
    pump(lambda: window.model.popups.value.dropped > 0, 10, "the flood to fill the list")
    latencies, widgets = [], []
    speed = gui.operator.speed
    for key in ("plus", "minus", "plus", "minus"):
        was = speed.value.percent
        latencies.append(key_latency(gui, key, lambda was=was: speed.value.percent != was))
        widgets.append(stack.widget_count())
        assert len(stack.cards) <= MAX_CARDS
        assert stack.more.get_visible() and stack.more.get_text().startswith("+")
    gui.shot("flood")
    shown = list(stack.cards)
    assert shown and all(any("<b>" in t for t in card_texts(gui, pid)) for pid in shown), "plain text"
    pump(lambda: sim.call(lambda: world.popup_flood) is None, 15, "the flood to end")
    made = sim.call(lambda: world._next_popup_id)
    assert made > 3000, f"only {made} popups: no flood"
    rebuilds = stack.rebuilds - rebuilds_before
    assert rebuilds < made / 5, f"{rebuilds} rebuilds for {made} popups"
    assert max(widgets) < 60, f"{max(widgets)} widgets under the popup stack"
    assert max(latencies) < 1.5, f"key presses took {latencies} s during the flood"
    pump(lambda: not window.model.popups.value.open, 15, "the flood's popups to time out")
    pump(lambda: not stack.get_visible(), 5, "the cards and their '+K more' to go")
    growth = rss_mb() - rss_before
    assert growth < 60, f"the window grew by {growth:.0f} MB during the flood"
    print(f"flood: {made} popups, {rebuilds} rebuilds, key latency {max(latencies) * 1000:.0f} ms max, "
          f"{max(widgets)} widgets max, RSS +{growth:.1f} MB")  # fmt: skip
    gui.shot("after-flood")
