"""RTMU's GTK4 window: the view layer over ``rtmu.control.controller`` and ``rtmu.model.observables``.

One module per job: ``app`` (entry points and options, no GTK import),
``application`` (Gtk.Application: settings, network thread, window, shutdown),
``window`` (the main window and the controller's ``View``), ``keys`` (the key
table and the capture-phase key router), ``toolbar`` + ``gauges`` (status),
``mapview`` (the map stage widget) over ``frame`` (one frame, GTK-free),
``viewport`` (screen/world maths), ``tiles`` (the static map rendered off the
GTK thread) and ``overlays`` (robot, trail, sonar, cairns), ``camera``,
``banners``, ``notes`` (the map note), ``settings_dialog``, ``move_dialogs``,
``dpad``, ``keys_window`` and ``style``. No module here touches a socket or a packet; ``viewport``, ``tiles``,
``overlays`` and ``frame`` run without a display (the benchmark uses them).
"""
