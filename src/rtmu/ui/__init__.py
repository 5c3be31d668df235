"""RTMU's GTK4 window: the view layer over ``rtmu.controller`` and ``rtmu.model``.

One module per job: ``app`` (Gtk.Application, actions, entry points), ``window``
(the main window and the controller's ``View``), ``keys`` (the key table and the
capture-phase key router), ``toolbar`` + ``gauges`` (status), ``mapview`` (the
map stage) over ``viewport`` (pure screen/world maths), ``tiles`` (the static
map rendered off the GTK thread) and ``overlays`` (robot, trail, sonar, cairns),
``camera``, ``banners``, ``settings_dialog``, ``move_dialogs``, ``dpad`` and
``shortcuts``. No module here touches a socket or a packet; GTK is imported only
by the widget modules (``viewport``, ``tiles`` and ``overlays`` run headless too).
"""
