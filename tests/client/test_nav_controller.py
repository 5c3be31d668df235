"""The operator always wins over navigation: the controller's rules, on a fake clock (no GTK, no sockets).

The server navigates on its own (ARNL). A STOP or a drive key cancels it with a stop and nothing else;
the next press drives as usual; focus loss ends held drives only; sending the robot somewhere ends a
held drive first. End-to-end against the simulator: test_navigation_client.py.
"""

from __future__ import annotations

from rtmu.base.notices import Kind
from rtmu.client.lease import EndReason
from rtmu.control.commands import COMMANDS
from rtmu.model.observables import NavState
from rtmu.values.intents import Dock, GoHome, GotoGoal, GotoPose, Localize, TourGoals

from .test_controller import ALL, Rig

NAV = ALL | {"gotoGoal", "gotoPose", "home", "dock", "tourGoals", "localizeToPose"}


def navigating(rig: Rig, target: str = "Lab B") -> None:
    rig.model.navigation.set(NavState(navigating=True, target=target, goals=("Lab A", "Lab B")))


def test_a_drive_key_while_navigating_only_stops_and_the_next_press_drives() -> None:
    rig = Rig(NAV)
    navigating(rig)
    rig.ctl.press("forward")
    assert rig.link.names() == ["stop"]  # the stop, and nothing else: no lease, no ratioDrive
    assert not rig.lease.live
    assert "Navigation cancelled. Press again to drive." in rig.view.texts()
    assert Kind.NAVIGATION in rig.view.kinds
    rig.ctl.press("forward")  # auto-repeat of the same key: still nothing
    assert rig.link.names() == ["stop"] and not rig.lease.live
    rig.ctl.release("forward")
    # The server has not said "Stopped" yet, but our stop is out: a fresh press drives.
    rig.ctl.press("forward")
    assert rig.lease.live and rig.link.names() == ["stop"]


def test_a_second_key_while_the_server_still_says_navigating_drives_after_our_stop() -> None:
    rig = Rig(NAV)
    navigating(rig)
    rig.ctl.press("left")
    rig.ctl.press("forward")  # another key, after the stop went out
    assert rig.lease.live and rig.link.names() == ["stop"]


def test_stop_cancels_navigation_and_the_next_key_drives() -> None:
    rig = Rig(NAV)
    navigating(rig)
    rig.ctl.run("stop")
    assert rig.link.names() == ["stop"]
    rig.ctl.press("right")
    assert rig.lease.live


def test_without_navigation_a_key_drives_at_once() -> None:
    rig = Rig(NAV)
    rig.ctl.press("forward")
    assert rig.lease.live and rig.link.names() == []


def test_a_new_navigation_is_cancelled_by_a_key_again() -> None:
    rig = Rig(NAV)
    navigating(rig)
    rig.ctl.stop()
    rig.model.navigation.set(NavState(navigating=False))  # the server said "Stopped"
    rig.ctl.ask(GotoGoal("Lab A"))
    navigating(rig, "Lab A")
    rig.ctl.press("backward")
    assert rig.link.names() == ["stop", "goto_goal", "stop"] and not rig.lease.live


def test_focus_loss_does_not_stop_a_navigation_but_ends_a_held_drive() -> None:
    rig = Rig(NAV)
    navigating(rig)
    rig.ctl.focus_lost()
    assert rig.link.names() == []  # autonomy on the server goes on
    rig.model.navigation.set(NavState())
    rig.ctl.focus_gained()
    rig.ctl.press("forward")
    rig.ctl.focus_lost()
    assert rig.link.names() == ["stop"] and rig.link.lease.ended is EndReason.STOPPED


def test_a_stale_link_does_not_stop_a_navigation() -> None:
    from rtmu.model.observables import LinkHealth, LinkLevel

    rig = Rig(NAV)
    navigating(rig)
    rig.model.health.set(LinkHealth(LinkLevel.STALE))
    assert "stop" not in rig.link.names()


def test_sending_the_robot_somewhere_ends_a_held_drive_first() -> None:
    rig = Rig(NAV)
    rig.ctl.press("forward")
    assert rig.lease.live
    rig.ctl.ask(GotoPose(4000, 6000, 90))
    assert not rig.lease.live and rig.link.lease.ended is EndReason.STOPPED
    assert rig.link.calls[-1] == ("goto_pose", 4000.0, 6000.0, 90.0)
    rig.ctl.release("forward")
    rig.ctl.ask(GoHome())
    rig.ctl.ask(Dock())
    rig.ctl.ask(TourGoals())
    rig.ctl.ask(Localize(1000, 2000, 45))
    assert rig.link.names()[-4:] == ["home", "dock", "tour_goals", "localize"]


def test_an_unknown_goal_is_refused_before_anything_is_sent() -> None:
    rig = Rig(NAV)
    rig.model.navigation.set(NavState(goals=("Lab A",)))
    rig.ctl.ask(GotoGoal("Nowhere"))
    assert rig.link.names() == []
    assert any("no goal called 'Nowhere'" in t for t in rig.view.texts())
    rig.ctl.ask(GotoGoal("Lab A"))
    assert rig.link.calls == [("goto_goal", "Lab A")]


def test_an_ld_robot_without_goto_goal_may_be_sent_to_a_goal() -> None:
    """The guard lets a goal through where either request is listed; the navigation feed picks
    ``gotoRouteGoal`` on an LD robot (tests/client/test_ld_model.py sees it on the wire)."""
    rig = Rig((ALL - {"gotoGoal"}) | {"gotoRouteGoal"})
    rig.ctl.ask(GotoGoal("Lab A"))
    assert rig.link.calls == [("goto_goal", "Lab A")]


def test_a_server_without_navigation_says_so() -> None:
    rig = Rig()
    rig.ctl.ask(GotoGoal("Lab A"))
    rig.ctl.ask(GotoPose(1, 2))
    rig.ctl.ask(GoHome())
    rig.ctl.ask(Localize(1, 2, 3))
    assert rig.link.calls == []
    assert "This server does not offer gotoGoal" in rig.view.texts()
    assert "This server does not offer localizeToPose" in rig.view.texts()


def test_home_dock_and_tour_are_registry_commands_enabled_only_where_listed() -> None:
    rig = Rig(ALL | {"home"})
    states = rig.ctl.command_states()
    assert states["home"].enabled
    assert not states["dock"].enabled and "dock" in states["dock"].reason
    assert not states["tour_goals"].enabled
    for name in ("home", "dock", "tour_goals"):
        assert COMMANDS.get(name).menu and COMMANDS.get(name).group == "Navigation"
    assert rig.ctl.run("home") and rig.link.names() == ["home"]
    assert not rig.ctl.run("dock") and rig.link.names() == ["home"]
