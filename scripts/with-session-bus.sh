#!/usr/bin/env bash
# Run a command with a D-Bus session bus: the desktop's own when there is one, else a private bus that
# lives exactly as long as the command (dbus-run-session, from the dbus package setup.sh installs).
# Why: GTK registers the application on the session bus; a bare X server (Xvfb, a kiosk, ssh -X) has
# none, and every start then warned "Unable to acquire session bus". ./rtmu-dev demo runs through this.
set -euo pipefail

[ "$#" -gt 0 ] || { echo "usage: scripts/with-session-bus.sh COMMAND [ARGS...]" >&2; exit 2; }
if [ -n "${DBUS_SESSION_BUS_ADDRESS:-}" ] || [ -S "${XDG_RUNTIME_DIR:-/nonexistent}/bus" ]; then
    exec "$@"
fi
if ! command -v dbus-run-session >/dev/null 2>&1; then
    echo "with-session-bus: no session bus and no dbus-run-session (apt-get install dbus); going on without" >&2
    exec "$@"
fi
exec dbus-run-session -- "$@"
