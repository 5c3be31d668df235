"""Configuration care in the real window: changed from default, reset to default, export and import.

Real window, real simulator (which keeps factory values), real X keys and clicks. Checked on the
simulator's own state: a value saved, seen as changed from default, reset with its own button back to
the factory value; an export written through the file chooser, a second export over it declined
(the file left as it was); an import of an edited export confirmed and taken in one set; a file
naming a parameter the server lacks refused whole, nothing sent.
"""

from __future__ import annotations

from pathlib import Path

import gi

from rtmu.client.config_file import FORMAT
from rtmu.sim import SimThread
from rtmu.ui.config_care_view import DefaultsWindow
from rtmu.ui.config_page import ConfigPage
from simulators import simulator

from .harness import Gui, idle, pump, scratch_dir

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from .stop_paths import owned_windows  # noqa: E402
from .test_config_page import answer, click, open_page, type_into  # noqa: E402

sim = simulator(map_path=None, camera=False, seed=1)


def timeout(sim: SimThread) -> float:
    return sim.call(lambda: sim.server.world.ratio_mode.timeout)  # type: ignore[no-any-return,union-attr]


def replace_question() -> Gtk.Window:
    """GTK's own "already exists" question over the save chooser."""
    found: list[Gtk.Window] = []

    def look() -> bool:
        found[:] = [
            w for w in Gtk.Window.list_toplevels() if isinstance(w, Gtk.MessageDialog) and w.get_mapped()
        ]
        return bool(found)

    pump(look, 5, "the chooser's replace question")
    return found[0]


def labels_under(widget: Gtk.Widget) -> list[str]:
    out = [widget.get_text()] if isinstance(widget, Gtk.Label) else []
    child = widget.get_first_child()
    while child is not None:
        out += labels_under(child)
        child = child.get_next_sibling()
    return out


def choose_file(gui: Gui, p: ConfigPage, path: Path, *, taken: bool = True) -> None:
    """The page's file chooser is open: type ``path`` into its name field (saving) or its location
    (ctrl+L, opening) and take it (Export; Return for a location)."""
    from gi.repository import GdkX11

    pump(lambda: p.care.chooser is not None and p.care.chooser.get_mapped(), 5, "the file chooser")
    chooser = p.care.chooser
    assert chooser is not None
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(chooser.get_surface())))
    if chooser.get_action() is not Gtk.FileChooserAction.SAVE:
        gui.key("ctrl+l")
    idle(0.3)
    gui.key("ctrl+a")
    gui.xdotool("type", "--delay", "15", str(path))
    idle(0.3)
    gui.screen_shot(f"chooser-{path.name}")
    if chooser.get_action() is Gtk.FileChooserAction.SAVE:
        click(gui, chooser.get_widget_for_response(Gtk.ResponseType.ACCEPT))
    else:
        gui.key("Return")  # the typed location is taken on Return (the button would only go there)
    idle(0.5)
    gui.screen_shot(f"chooser-{path.name}-taken")
    if taken:
        pump(lambda: p.care.chooser is None, 5, "the chooser to close")


def test_changed_from_default_and_reset_to_default(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    factory = timeout(sim)
    _param, spin, _label = p.rows[("Teleop", "Timeout")]
    type_into(gui, spin, "0.5")
    pump(lambda: p.edits.get(("Teleop", "Timeout")) == "0.50", 3, "the edit")
    click(gui, p.save_button)
    pump(lambda: answer(p, "Teleop", "Timeout") == "✓ accepted", 5, "the save")
    assert timeout(sim) == 0.5 != factory

    assert p.care.defaults_button.get_sensitive()
    click(gui, p.care.defaults_button)
    pump(lambda: isinstance(p.care.defaults, DefaultsWindow) and p.care.defaults.loads >= 1, 10, "the diff")
    view = p.care.defaults
    assert view is not None
    changed = {(d.section, d.name): (d.value, d.default) for d in view.differences}
    assert ("Teleop", "Timeout") in changed and changed[("Teleop", "Timeout")][0] == "0.5"
    gui.render(view, gui.shots / f"{gui.name}-changed-from-default.png")
    loads = view.loads
    click(gui, view.reset_buttons[("Teleop", "Timeout")])
    pump(lambda: view.loads > loads, 10, "the view read again after the reset")
    assert timeout(sim) == factory
    assert ("Teleop", "Timeout") not in {(d.section, d.name) for d in view.differences}
    pump(lambda: p.config is not None and p.config.find("Teleop", "Timeout").value == factory, 10, "the page")  # type: ignore[union-attr]
    gui.render(view, gui.shots / f"{gui.name}-after-reset.png")


def test_export_refuse_overwrite_then_import_an_edited_file(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    folder = scratch_dir("config-files-")
    target = folder / "robot.toml"
    click(gui, p.care.export_button)
    choose_file(gui, p, target)
    pump(target.is_file, 5, "the export on disk")
    text = target.read_text()
    assert f'format = "{FORMAT}"' in text and '"Timeout" = ' in text
    assert "Exported" in p.banner.get_text()
    gui.render(p, gui.shots / f"{gui.name}-exported.png")

    # a second export over it asks (GTK 4's save chooser names the file); Cancel leaves it as it was
    target.write_text(text + "# the operator's note\n")
    before = target.read_text()
    click(gui, p.care.export_button)
    choose_file(gui, p, target, taken=False)
    question = replace_question()
    assert "“robot.toml” already exists" in " ".join(labels_under(question))
    click(gui, question.get_widget_for_response(Gtk.ResponseType.CANCEL))
    pump(lambda: not question.get_mapped(), 5, "the question to close")
    assert p.care.chooser is not None  # back in the chooser, nothing written
    click(gui, p.care.chooser.get_widget_for_response(Gtk.ResponseType.CANCEL))
    pump(lambda: p.care.chooser is None, 5, "the chooser to close")
    assert target.read_text() == before
    # ... and asked directly (no chooser): RTMU's own question, Cancel keeps the file
    p.care.export_to(target)
    pump(lambda: p.care.confirm is not None and p.care.confirm.get_mapped(), 5, "RTMU's replace question")
    assert "“robot.toml” already exists" in p.care.confirm.question.get_text()  # type: ignore[union-attr]
    gui.render(p.care.confirm, gui.shots / f"{gui.name}-replace.png")  # type: ignore[arg-type]
    click(gui, p.care.confirm.cancel_button)  # type: ignore[union-attr]
    pump(lambda: not p.care.confirm.get_mapped(), 5, "the question to close")  # type: ignore[union-attr]
    assert target.read_text() == before

    # import an edited copy: asked with the count, then taken
    edited = folder / "edited.toml"
    lines = ['"Timeout" = "0.7"' if line.startswith('"Timeout" = ') else line for line in before.splitlines()]
    edited.write_text("\n".join(lines) + "\n")
    click(gui, p.care.import_button)
    choose_file(gui, p, edited)
    pump(lambda: p.care.confirm is not None and p.care.confirm.get_mapped(), 5, "the import question")
    assert "Import 1 value from “edited.toml”" in p.care.confirm.question.get_text()  # type: ignore[union-attr]
    click(gui, p.care.confirm.yes_button)  # type: ignore[union-attr]
    pump(lambda: timeout(sim) == 0.7, 10, "the imported value on the simulator")
    pump(lambda: "Imported 1 value from" in p.banner.get_text(), 5, "the import said")

    # a file naming what the server lacks: refused whole, nothing sent
    bad = folder / "bad.toml"
    bad.write_text(f'format = "{FORMAT}"\n["Teleop"]\n"Timeout" = "1.5"\n["Nowhere"]\n"Thing" = "1"\n')
    click(gui, p.care.import_button)
    choose_file(gui, p, bad)
    pump(lambda: "Not imported, nothing was sent" in p.banner.get_text(), 5, "the refusal")
    assert "no section 'Nowhere'" in p.banner.get_text() and p.banner.has_css_class("error")
    assert timeout(sim) == 0.7
    assert [w for w in owned_windows(gui.window) if w is not p] == []
    gui.render(p, gui.shots / f"{gui.name}-import-refused.png")


def test_a_changed_parameter_has_its_own_reset_button_on_the_page(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    factory = timeout(sim)
    pump(lambda: p.care.factory is not None, 10, "the factory values")
    assert ("Teleop", "Timeout") not in p.care.resets or p.care.resets[
        ("Teleop", "Timeout")
    ].get_parent() is None
    _param, spin, _label = p.rows[("Teleop", "Timeout")]
    type_into(gui, spin, "0.5")
    pump(lambda: p.edits.get(("Teleop", "Timeout")) == "0.50", 3, "the edit")
    click(gui, p.save_button)
    pump(lambda: answer(p, "Teleop", "Timeout") == "✓ accepted", 5, "the save")
    pump(
        lambda: ("Teleop", "Timeout") in p.care.resets and p.care.resets[("Teleop", "Timeout")].get_mapped(),
        10,
        "the row's reset button",
    )
    button = p.care.resets[("Teleop", "Timeout")]
    assert "Reset to default (2)" in (button.get_tooltip_text() or "")
    gui.render(p, gui.shots / f"{gui.name}-row-reset.png")
    click(gui, button)
    pump(lambda: timeout(sim) == factory, 10, "the factory value on the simulator")
    pump(lambda: "back to its factory value" in p.banner.get_text(), 5, "the reset said")
    pump(lambda: not button.get_mapped(), 10, "the button gone with the difference")
