"""The headless ArNetworking client: asyncio connection, link health, drive lease, reconnect.

One job per module:

* ``errors``     — typed errors an operator understands, each with its CLI exit code.
* ``connection`` — :class:`AriaClient`, one logged-in connection on asyncio streams.
* ``health``     — RTT, status age, dropped packets → OK / STALE / LOST, and why.
* ``lease``      — the drive lease the UI renews and the governor that turns it into packets.
* ``lease_keeper`` — credits a renewing UI thread with the time it only waited for a CPU.
* ``reconnect``  — backoff policy.
* ``session``    — everything that runs on the network loop for one operator session.
* ``runner``     — :class:`ClientRunner`: the network thread and its thread-safe facade for a UI.

Nothing here imports GTK or the UI thread's state (``rtmu.model.observables``): the runner
publishes typed changes (``rtmu.values.state``) and notices (``rtmu.base.notices``) to a
sink it is given. The package imports none of its modules eagerly, so a caller
that needs the lease does not load the connection code.

A window does not wire these itself: ``rtmu.fleet.sessions.RobotSession`` puts one robot's
model, runner and controller together::

    session = RobotSession(operator, post=GLib.idle_add).start()   # network thread
    GLib.timeout_add(100, lambda: session.controller.tick() or True)  # renews the drive lease
    session.controller.select_profile(profile); session.controller.connect()
    ...
    session.close()                                   # stops the robot, unhooks, ends the thread

The safety design (lease, governor, loop heartbeat, server watchdog) is written up in ``runner``.

Scripts without a UI use :class:`AriaClient` directly under ``asyncio.run`` (see ``rtmu.subcommands``).
"""
