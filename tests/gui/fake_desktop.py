"""The desktop's side of the window's calls, on the test's session bus: it answers and tells the test.

Under Xvfb there is no session manager and no notification server, so this small real D-Bus service
stands in for both. ``Gtk.Application.inhibit`` asks ``org.gnome.SessionManager`` (when that name is on
the bus at the application's start-up) to hold off idling and suspend: ``RegisterClient``, ``Inhibit``
(a new cookie), ``Uninhibit``. ``Gio.Notification`` goes to ``org.freedesktop.Notifications`` (GLib's
fallback backend when no ``org.gtk.Notifications`` is on the bus): ``Notify``, ``CloseNotification``.
Each call is printed as one JSON line on stdout, after a first ``{"ready": true}`` once it owns both
names.
"""

from __future__ import annotations

import json
import sys
from typing import Any

import gi

gi.require_version("Gio", "2.0")
from gi.repository import Gio, GLib  # noqa: E402

NAME = "org.gnome.SessionManager"
NOTIFICATIONS = "org.freedesktop.Notifications"
NOTIFY_XML = """
<node>
  <interface name="org.freedesktop.Notifications">
    <method name="Notify">
      <arg type="s" direction="in"/><arg type="u" direction="in"/><arg type="s" direction="in"/>
      <arg type="s" direction="in"/><arg type="s" direction="in"/><arg type="as" direction="in"/>
      <arg type="a{sv}" direction="in"/><arg type="i" direction="in"/><arg type="u" direction="out"/>
    </method>
    <method name="CloseNotification"><arg type="u" direction="in"/></method>
    <method name="GetCapabilities"><arg type="as" direction="out"/></method>
    <method name="GetServerInformation">
      <arg type="s" direction="out"/><arg type="s" direction="out"/><arg type="s" direction="out"/>
      <arg type="s" direction="out"/>
    </method>
    <signal name="NotificationClosed"><arg type="u"/><arg type="u"/></signal>
    <signal name="ActionInvoked"><arg type="u"/><arg type="s"/></signal>
  </interface>
</node>
"""
XML = """
<node>
  <interface name="org.gnome.SessionManager">
    <method name="RegisterClient">
      <arg type="s" direction="in"/><arg type="s" direction="in"/><arg type="o" direction="out"/>
    </method>
    <method name="Inhibit">
      <arg type="s" direction="in"/><arg type="u" direction="in"/><arg type="s" direction="in"/>
      <arg type="u" direction="in"/><arg type="u" direction="out"/>
    </method>
    <method name="Uninhibit"><arg type="u" direction="in"/></method>
    <method name="IsInhibited"><arg type="u" direction="in"/><arg type="b" direction="out"/></method>
  </interface>
</node>
"""
CLIENT_XML = """
<node>
  <interface name="org.gnome.SessionManager.ClientPrivate">
    <method name="EndSessionResponse"><arg type="b" direction="in"/><arg type="s" direction="in"/></method>
  </interface>
</node>
"""


def say(record: dict[str, Any]) -> None:
    print(json.dumps(record), flush=True)


def main() -> int:
    cookies = iter(range(1, 1_000_000))
    held: set[int] = set()
    client_info = Gio.DBusNodeInfo.new_for_xml(CLIENT_XML).interfaces[0]

    def call(conn, _sender, _path, _iface, method, params, invocation) -> None:  # type: ignore[no-untyped-def]
        args = params.unpack()
        if method == "RegisterClient":
            path = "/org/gnome/SessionManager/Client1"
            conn.register_object(path, client_info, lambda *a: a[-1].return_value(None), None, None)
            invocation.return_value(GLib.Variant("(o)", (path,)))
        elif method == "Inhibit":
            cookie = next(cookies)
            held.add(cookie)
            say({"call": "Inhibit", "app": args[0], "reason": args[2], "flags": args[3], "cookie": cookie})
            invocation.return_value(GLib.Variant("(u)", (cookie,)))
        elif method == "Uninhibit":
            held.discard(args[0])
            say({"call": "Uninhibit", "cookie": args[0]})
            invocation.return_value(None)
        else:
            invocation.return_value(GLib.Variant("(b)", (bool(held),)))

    ids = iter(range(1, 1_000_000))

    def notify(conn, _sender, _path, _iface, method, params, invocation) -> None:  # type: ignore[no-untyped-def]
        args = params.unpack()
        if method == "Notify":
            ident = next(ids)
            urgency = args[6].get("urgency")
            say({"call": "Notify", "summary": args[3], "body": args[4], "urgency": urgency, "id": ident})
            invocation.return_value(GLib.Variant("(u)", (ident,)))
        elif method == "CloseNotification":
            say({"call": "CloseNotification", "id": args[0]})
            invocation.return_value(None)
        elif method == "GetCapabilities":
            invocation.return_value(GLib.Variant("(as)", (["body", "actions"],)))
        else:
            invocation.return_value(GLib.Variant("(ssss)", ("fake", "rtmu-tests", "1", "1.2")))

    owned: set[str] = set()

    def acquired(_conn: Gio.DBusConnection, name: str) -> None:
        owned.add(name)
        if owned == {NAME, NOTIFICATIONS}:
            say({"ready": True})

    def lost(_conn: Gio.DBusConnection, name: str) -> None:
        say({"lost": name})  # another owns it: the test would hear nothing, and says so

    def bus(conn: Gio.DBusConnection, _name: str) -> None:
        info = Gio.DBusNodeInfo.new_for_xml(XML).interfaces[0]
        conn.register_object("/org/gnome/SessionManager", info, call, None, None)
        notify_info = Gio.DBusNodeInfo.new_for_xml(NOTIFY_XML).interfaces[0]
        conn.register_object("/org/freedesktop/Notifications", notify_info, notify, None, None)
        Gio.bus_own_name_on_connection(conn, NOTIFICATIONS, Gio.BusNameOwnerFlags.NONE, acquired, lost)

    Gio.bus_own_name(Gio.BusType.SESSION, NAME, Gio.BusNameOwnerFlags.NONE, bus, acquired, lost)
    GLib.MainLoop().run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
