"""RTMU's one stylesheet: legible at 800×480 and at arm's length, greyed means stale.

Every widget's style is here, in sections named for the modules that use the classes, and it is
installed once per display by :func:`install_css` (the application's start-up): no widget module
loads CSS of its own, so a colour is defined once and a new widget adds its rules here.
"""

from __future__ import annotations

import weakref

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402

CSS = """
.status-toolbar { background: @theme_bg_color; border-bottom: 1px solid alpha(black, 0.14);
                  padding: 1px 4px; }
.status-toolbar flowboxchild { padding: 0; }
.status-cell { padding: 1px 3px; border-radius: 6px; }
.status-cell .caption { font-size: 7.5pt; opacity: 0.62; }
.status-cell .value { font-size: 10.5pt; font-weight: bold; font-feature-settings: "tnum"; }
.status-cell.stale .value { opacity: 0.4; }  /* same weight: a fixed column keeps its width */
.status-cell.low .value { color: #b56d00; }
.status-cell.critical { background: alpha(#c01c28, 0.14); }
.status-cell.critical .value { color: #c01c28; }
.status-cell.alarm .value { color: #c01c28; }
.status-cell.link-ok .value { color: #1e7a3f; }
.status-cell.link-stale .value { color: #b56d00; opacity: 1; }
.status-cell.link-lost .value { color: #c01c28; opacity: 1; }
.status-cell.loc-good .value { color: #1e7a3f; }
.status-cell.loc-poor .value { color: #b56d00; }
.status-cell.loc-lost { background: alpha(#c01c28, 0.14); }
.status-cell.loc-lost .value { color: #c01c28; }

.fullscreen-bar { background: @theme_bg_color; padding: 4px 6px;
                  border-bottom: 1px solid alpha(black, 0.14); }
.fullscreen-bar .subtitle { font-size: 9pt; opacity: 0.75; margin: 0 6px; }
.title-box .title { font-weight: bold; }
.title-box .subtitle { font-size: 8.5pt; opacity: 0.7; }
button.connect-button { min-width: 96px; }
button.stop-button { min-width: 92px; font-weight: bold; letter-spacing: 1px; }

.banner { background: alpha(#242424, 0.90); color: white; border-radius: 10px;
          padding: 4px 4px 4px 12px; box-shadow: 0 2px 8px alpha(black, 0.35); }
.banner.warning { background: alpha(#9c5300, 0.94); }
.banner.error { background: alpha(#a51d2d, 0.95); }
.banner label { font-size: 10.5pt; }
.banner button { color: white; min-height: 24px; min-width: 24px; }
.banner levelbar block.filled { background: #62a0ea; }

.map-osd { background: alpha(#242424, 0.62); border-radius: 10px; padding: 3px; }
.map-osd button, .map-osd label { color: white; }
.map-osd label.zoom-label { min-width: 56px; font-feature-settings: "tnum"; font-weight: bold; }
.map-osd togglebutton:checked { background: alpha(#3584e4, 0.85); }
.motion { border-radius: 8px; padding: 3px 10px; box-shadow: 0 1px 4px alpha(black, 0.3); }
.motion label { color: white; }
.motion .motion-title { font-weight: bold; font-size: 10.5pt; }
.motion .motion-detail { font-size: 9.5pt; }
.motion .motion-hint { font-size: 8pt; opacity: 0.85; }
.motion.motion-autonomous { background: alpha(#00797d, 0.92); }  /* teal: the path's colour */
.motion.motion-held { background: alpha(#1c71d8, 0.92); }
.pose-bar { background: alpha(#242424, 0.88); border-radius: 10px; padding: 4px 4px 4px 12px; }
.pose-bar > label { color: white; font-weight: bold; }
menubutton.goals-button > button { min-width: 20px; padding-left: 3px; padding-right: 3px; }
.goal-list row.current-goal label { font-weight: bold; color: #00797d; }
.map-note { background: alpha(white, 0.88); border-radius: 8px; padding: 6px 12px; color: #333; }

.dpad-button { background: alpha(#242424, 0.45); color: white; border-radius: 16px; }
.dpad-button.held { background: #1c71d8; box-shadow: 0 0 0 3px alpha(#99c1f1, 0.8); }
.dpad-button.stop { background: alpha(#c01c28, 0.82); font-weight: bold; }
.dpad-button:disabled { opacity: 0.35; }

.camera-page { background: #111; color: white; }
.camera-picture.dimmed { opacity: 0.4; }
.camera-status { background: alpha(black, 0.6); border-radius: 10px; padding: 12px 18px; }
.camera-bar { padding: 6px 8px; background: #1d1d1d; }
.camera-bar button { color: white; background: alpha(white, 0.12); border-color: alpha(white, 0.25);
                     box-shadow: none; text-shadow: none; }
.camera-bar button:hover { background: alpha(white, 0.2); }
.camera-bar button:disabled { color: alpha(white, 0.4); }
.camera-bar label { color: alpha(white, 0.85); }
/* Its popovers (the gear's frame rate and quality, their drop-down lists) are inside the dark bar:
   dark too, or its white words land on the theme's white popover. */
.camera-bar popover > contents, .camera-bar popover > arrow { background: #2a2a2a; color: white;
                                                             border-color: alpha(white, 0.25); }
.camera-bar popover listview, .camera-bar popover list { background: transparent; color: white; }
.camera-inset { border: 2px solid alpha(white, 0.85); border-radius: 6px;
                box-shadow: 0 2px 8px alpha(black, 0.4); background: black; }
.camera-inset.stale { opacity: 0.8; border-color: alpha(#9c5300, 0.9); }
.camera-inset.stale picture { filter: grayscale(1); }
.camera-inset .inset-age { background: alpha(black, 0.62); color: white; font-size: 8.5pt;
                           padding: 0 4px; border-radius: 4px; margin: 3px; }
.camera-inset.stale .inset-age { background: alpha(#9c5300, 0.92); }
.pip .pip-close { min-height: 18px; min-width: 18px; padding: 0 5px; margin: 3px; border-radius: 9px;
                  color: white; background: alpha(black, 0.55); border: none; box-shadow: none; }
.pip .pip-grip { color: alpha(white, 0.9); font-size: 9pt; margin: 1px 2px; }
.video-caption { background: alpha(black, 0.62); color: white; font-size: 9pt; padding: 1px 6px;
                 border-radius: 4px; }

/* The keys window (keys_window): each key a cap */
.keys-window .keycap { font-size: 9pt; min-width: 14px; padding: 1px 6px; border-radius: 5px;
                       border: 1px solid alpha(currentColor, 0.3);
                       box-shadow: inset 0 -2px alpha(currentColor, 0.15); }
.keys-list { background: none; }

.field-error { color: #c01c28; font-size: 9pt; margin-bottom: 4px; }
entry.error { border-color: #c01c28; }

/* Server popups over the map (popups) */
.popup-card { background: alpha(@theme_bg_color, 0.96); border-radius: 10px; padding: 8px 10px;
              border: 1px solid alpha(black, 0.18); box-shadow: 0 2px 6px alpha(black, 0.25); }
.popup-card.warning { border-left: 5px solid #e5a50a; }
.popup-card.critical { border-left: 5px solid #c01c28; }
.popup-card .popup-title { font-weight: bold; }
.popup-card .popup-age { font-size: 8pt; opacity: 0.6; font-feature-settings: "tnum"; }
.popup-more { background: alpha(#242424, 0.62); color: white; border-radius: 8px; padding: 2px 8px; }

/* The server's configuration page (config_page): the answer colours — the theme's own
   .success/.error differ between themes */
.config-ok { color: #26a269; font-weight: bold; }
.config-error { color: #c01c28; }
.config-edited { color: #1c71d8; }
.config-banner { background: alpha(#e5a50a, 0.25); padding: 4px 8px; border-radius: 4px; }

/* Handheld (handheld): the gamepad pill, the phone's status strip and narrower STOP */
.gamepad-status { background: alpha(#242424, 0.80); color: white; border-radius: 8px; padding: 3px 10px; }
.gamepad-status.deadman-held { background: alpha(#1c71d8, 0.92); }
.gamepad-status.deadman-latched { background: alpha(#9c5300, 0.94); }
.status-strip { background: @theme_bg_color; border-bottom: 1px solid alpha(black, 0.14); padding: 2px 6px; }
.status-strip label { font-size: 10pt; font-weight: bold; font-feature-settings: "tnum"; }
.status-strip label.low { color: #b56d00; }
.status-strip label.critical, .status-strip label.lost { color: #c01c28; }
.status-strip label.stale { color: #b56d00; }
.status-strip label.ok { color: #1e7a3f; }
window.phone button.stop-button { min-width: 72px; }

/* The fleet's robot list (robot_list): the selected row */
.robot-row.robot-selected { background-color: alpha(@theme_selected_bg_color, 0.3); border-radius: 6px; }
"""


_INSTALLED: weakref.WeakSet[Gdk.Display] = weakref.WeakSet()
"""Displays that have the stylesheet (a process can open several apps, and tests several displays)."""


def install_css(display: Gdk.Display | None = None) -> None:
    """:data:`CSS` on ``display`` (the default display), once."""
    display = display or Gdk.Display.get_default()
    if display is None or display in _INSTALLED:
        return
    provider = Gtk.CssProvider()
    provider.load_from_data(CSS, -1)
    Gtk.StyleContext.add_provider_for_display(display, provider, Gtk.STYLE_PROVIDER_PRIORITY_APPLICATION)
    _INSTALLED.add(display)
