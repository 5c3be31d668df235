"""The Layers panel: one switch per drawing the server lists, remembered per server.

A card over the map (View → Layers…); its switches take the focus by Tab (``keyboard_nav``) while
the arrow keys keep driving and Space keeps stopping (the window's key router and stop keys catch
them first). Each drawing of :attr:`~rtmu.model.observables.RobotModel.drawings` gets a check button labelled
with its name exactly as sent (plain text: no markup, no mnemonic underscores). A drawing the
server keeps always on or off, or whose shape RTMU cannot draw, is listed greyed with the reason.
Turning one off tells the network side to stop asking for it (``set_drawing_shown``) and
records the choice for this server (``host:port``) in the settings' ``layers`` table, which is
handed to the network side again before the next connection to that server lists its drawings.
"""

from __future__ import annotations

from collections.abc import Callable, MutableMapping

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..model.observables import ConnectionState, DrawingsState, Observable, Phase  # noqa: E402
from ..values.intents import DrawingChoices, Intent, ShowDrawing  # noqa: E402
from ..values.state import DrawingLayer  # noqa: E402
from . import accessible  # noqa: E402

MAX_LABEL = 60
"""Characters of a name shown (the whole name is the button's tooltip)."""


def server_key(connection: ConnectionState) -> str:
    return f"{connection.host}:{connection.port}"


def row_label(layer: DrawingLayer) -> str:
    """The name as sent (cut to :data:`MAX_LABEL`), and why it cannot be switched where that is so."""
    name = layer.name if len(layer.name) <= MAX_LABEL else layer.name[: MAX_LABEL - 1] + "…"
    if not layer.drawable:
        return _("{name} — shape {value!r} not drawn").format(name=name, value=layer.shape[:30])
    if not layer.may_toggle:
        return _("{name} — always {value}").format(name=name, value="on" if layer.shown else "off")
    if layer.problem:
        return _("{name} — bad data").format(name=name)
    return name


class LayersPanel(Gtk.Box):
    """See the module notes. ``choices`` is the settings' per-server table (shared, mutated in place)."""

    def __init__(
        self,
        drawings: Observable[DrawingsState],
        connection: Observable[ConnectionState],
        ask: Callable[[Intent], object],
        choices: MutableMapping[str, dict[str, bool]] | None = None,
    ) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL, spacing=2)
        self.add_css_class("layers-panel")
        self.add_css_class("popup-card")  # the look of the server popups' cards (their CSS)
        self.set_halign(Gtk.Align.START)
        self.set_valign(Gtk.Align.START)
        self.set_margin_start(10)
        self.set_margin_top(10)
        self.set_focusable(False)
        self.set_visible(False)
        self._drawings = drawings
        self._connection = connection
        self._ask = ask
        """The selected robot's intents (``SelectedRobot.ask``)."""
        self.choices: MutableMapping[str, dict[str, bool]] = {} if choices is None else choices
        self.on_closed: Callable[[], None] = lambda: None
        self.buttons: dict[str, Gtk.CheckButton] = {}
        self._shape: tuple[tuple[str, bool, bool, bool, bool], ...] | None = None
        self._server = ""

        head = Gtk.Box(spacing=6)
        title = Gtk.Label(label=_("Layers"), xalign=0.0, hexpand=True)
        title.add_css_class("heading")
        head.append(title)
        close = Gtk.Button(icon_name="window-close-symbolic", tooltip_text=_("Close"))
        close.add_css_class("flat")
        close.set_focusable(False)
        accessible.name(close, _("Close layers"))
        close.connect("clicked", lambda _b: self.close())
        head.append(close)
        self.append(head)
        self.rows = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=0)
        self.append(self.rows)
        self.empty = Gtk.Label(label=_("This server lists no drawings"), xalign=0.0)
        self.empty.add_css_class("dim-label")
        self.append(self.empty)

        self._unobserve = [
            drawings.observe(lambda _old, _new: self._refresh()),
            connection.observe(self._on_connection),
        ]
        self._refresh()

    def use_choices(self, choices: MutableMapping[str, dict[str, bool]]) -> None:
        """Keep the choices in this table (the settings'), and hand the current server's over now."""
        self.choices = choices
        self._send_choices()

    def unobserve(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

    def open(self) -> None:
        self.set_visible(True)

    def close(self) -> None:
        self.set_visible(False)
        self.on_closed()

    # -- the model ---------------------------------------------------------------------------
    def _on_connection(self, old: ConnectionState, new: ConnectionState) -> None:
        if new.phase in (Phase.CONNECTING, Phase.CONNECTED) and server_key(new) != self._server:
            self._server = server_key(new)
            self._send_choices()

    def _send_choices(self) -> None:
        if self._server:
            self._ask(DrawingChoices(dict(self.choices.get(self._server, {}))))

    def _refresh(self) -> None:
        layers = self._drawings.value.layers
        shape = tuple((d.name, d.shown, d.may_toggle, d.drawable, bool(d.problem)) for d in layers)
        if shape == self._shape:  # new points only: nothing to rebuild
            return
        self._shape = shape
        while (child := self.rows.get_first_child()) is not None:
            self.rows.remove(child)
        self.buttons = {}
        for layer in layers:
            button = Gtk.CheckButton()
            label = Gtk.Label(label=row_label(layer), xalign=0.0, use_markup=False, use_underline=False)
            label.set_ellipsize(Pango.EllipsizeMode.END)
            button.set_child(label)  # our own plain-text label: the server's name is never markup
            accessible.name(button, row_label(layer))  # GTK 4.8 names no check button by a child label
            button.set_focusable(False)
            button.set_active(layer.shown)
            button.set_sensitive(layer.may_toggle)
            button.set_tooltip_text(layer.problem or layer.name)
            button.connect("toggled", self._toggled, layer.name)
            self.rows.append(button)
            self.buttons[layer.name] = button
        self.empty.set_visible(not layers)

    def label_text(self, name: str) -> str:
        """The row's text as Pango laid it out (what the operator reads)."""
        label = self.buttons[name].get_child()
        assert isinstance(label, Gtk.Label)
        return str(label.get_layout().get_text())

    def _toggled(self, button: Gtk.CheckButton, name: str) -> None:
        shown = button.get_active()
        current = {d.name: d for d in self._drawings.value.layers}.get(name)
        if current is None or current.shown == shown:
            return
        if self._server:
            self.choices.setdefault(self._server, {})[name] = shown
        self._ask(ShowDrawing(name, shown))
