"""The headless ArNetworking client: asyncio connection, link health, drive lease, reconnect.

One job per module:

* ``errors``     — typed errors an operator understands (and the CLI's exit codes).
* ``connection`` — :class:`AriaClient`, one logged-in connection on asyncio streams.
* ``health``     — RTT, status age, dropped packets → OK / STALE / LOST.
* ``lease``      — the drive lease the UI renews and the governor that turns it into packets.
* ``reconnect``  — backoff policy.
* ``session``    — everything that runs on the network loop for one operator session.
* ``runner``     — :class:`ClientRunner`: the network thread and its thread-safe facade for a UI.

Nothing here imports GTK.
"""
