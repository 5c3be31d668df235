#!/usr/bin/env bash
# Install RTMU's desktop entry and icon for the current user, so it shows up in the application menu.
# Idempotent (rewrites only what changed), touches nothing outside $XDG_DATA_HOME (~/.local/share),
# and does nothing when CI=true. The entry runs this checkout's .venv/bin/rtmu when there is one,
# else the rtmu on PATH.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
[ "${CI:-}" = "true" ] && exit 0

APP_ID=io.github.rtmu.Rtmu
DATA_HOME="${XDG_DATA_HOME:-$HOME/.local/share}"
APPS="$DATA_HOME/applications"
ICONS="$DATA_HOME/icons/hicolor/scalable/apps"

if [ -x .venv/bin/rtmu ]; then
    program="$(pwd)/.venv/bin/rtmu"
elif command -v rtmu >/dev/null 2>&1; then
    program="$(command -v rtmu)"
else
    program=rtmu
fi
# Desktop Entry quoting: wrap in double quotes, escape \ " ` $ inside.
quoted="\"$(printf '%s' "$program" | sed -e 's/[\\"`$]/\\&/g')\""

changed=0
install_if_changed() { # install_if_changed SOURCE_TEXT_FILE TARGET
    if ! cmp -s "$1" "$2"; then
        mkdir -p "$(dirname "$2")"
        install -m 0644 "$1" "$2"
        changed=1
    fi
}

entry=$(mktemp)
trap 'rm -f "$entry"' EXIT
# Escape the replacement for sed (\ & and the | delimiter).
replacement=$(printf '%s' "$quoted" | sed -e 's/[\\&|]/\\&/g')
sed -e "s|^Exec=rtmu|Exec=$replacement|" "data/desktop/$APP_ID.desktop" >"$entry"
install_if_changed "$entry" "$APPS/$APP_ID.desktop"
install_if_changed "data/desktop/$APP_ID.svg" "$ICONS/$APP_ID.svg"

if [ "$changed" -eq 1 ]; then
    command -v update-desktop-database >/dev/null 2>&1 && update-desktop-database -q "$APPS" || true
    command -v gtk-update-icon-cache >/dev/null 2>&1 &&
        [ -f "$DATA_HOME/icons/hicolor/index.theme" ] && gtk-update-icon-cache -q "$DATA_HOME/icons/hicolor" || true
    printf 'setup: desktop entry and icon installed in %s\n' "$DATA_HOME"
else
    printf 'setup: desktop entry up to date\n'
fi
