"""Banners say only what is true now (issue 21, "Banners that lie").

A link stop's banner ("Stopped: the link is stale") goes once the link is healthy again: the
operator's next drive never runs under it. The link is muted with a real fault-injecting proxy
between the window and the simulator; keys are real (xdotool).
"""

from __future__ import annotations

from linkfaults import TO_CLIENT, FaultProxy
from rtmu.model.observables import LinkLevel, Phase
from rtmu.sim import SimThread

from .harness import Gui, pump


def _hold_up_until_driving(gui: Gui, sim: SimThread) -> None:
    for _attempt in range(5):  # a press refused (the link not yet back to the controller): press again
        gui.keydown("Up")
        try:
            pump(lambda: abs(sim.snapshot().vel) > 1.0, 3, "the robot to drive")
            return
        except AssertionError:
            gui.keyup("Up")
    raise AssertionError("the held key never drove the robot")


def _link_banner(gui: Gui) -> str:
    return gui.window.banners.text("link") or ""


def test_a_link_stop_banner_goes_once_the_link_is_healthy(
    faulty_link: tuple[Gui, SimThread, FaultProxy],
) -> None:
    gui, sim, proxy = faulty_link
    _hold_up_until_driving(gui, sim)
    proxy.mute(TO_CLIENT)  # no status comes: the link goes stale, the window stops the robot
    pump(lambda: _link_banner(gui).startswith("Stopped: the link"), 5, "the link stop's banner")
    pump(lambda: sim.snapshot().trans_ratio == 0, 5, "the robot to be stopped")
    gui.shot("link-stop")
    gui.keyup("Up")

    proxy.restore()
    pump(
        lambda: gui.phase is Phase.CONNECTED and gui.model.health.value.level is LinkLevel.OK,
        15,
        "the link to be healthy again",
    )
    pump(lambda: not _link_banner(gui).startswith("Stopped"), 5, "the link stop's banner to go")
    assert _link_banner(gui) in ("", "The link is back: press a key to drive again"), _link_banner(gui)

    # Driving again on the healthy link: no banner says it is stopped.
    _hold_up_until_driving(gui, sim)
    gui.shot("driving-again")
    assert not _link_banner(gui).startswith("Stopped"), _link_banner(gui)
    gui.key("space")
    pump(lambda: sim.snapshot().trans_ratio == 0, 3, "Space to stop the robot")
    gui.keyup("Up")
