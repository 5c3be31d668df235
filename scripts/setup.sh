#!/usr/bin/env bash
# Prepare this checkout to run RTMU on Debian 12 / Ubuntu, from nothing, without questions:
#   1. the system packages GTK 4 and the PyGObject build need (apt, only when some are missing);
#   2. a virtualenv in .venv;
#   3. the project and its dev tools in it, at the versions in constraints.txt (pip, only when
#      pyproject.toml or constraints.txt changed since last time).
# Every make target runs this first, so a re-run must stay quick: it checks and skips.
# Environment: PYTHON picks the interpreter (default python3, needs >= 3.11).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive

APT_PACKAGES=(
    gir1.2-gtk-4.0 gir1.2-adw-1 libgirepository1.0-dev libcairo2-dev pkg-config
    python3-dev python3-venv build-essential xvfb xdotool
)
VENV=.venv
STAMP="$VENV/.rtmu-setup-stamp"
CONSTRAINTS=constraints.txt
PYTHON="${PYTHON:-python3}"

say() { printf 'setup: %s\n' "$*"; }
die() { printf 'setup: error: %s\n' "$*" >&2; exit 1; }

# Run a noisy command silently; show the end of its output only if it fails.
quiet() {
    local log rc=0
    log=$(mktemp)
    "$@" >"$log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || tail -n 40 "$log" >&2
    rm -f "$log"
    return "$rc"
}

# -- 1. system packages ---------------------------------------------------------------------
missing_packages() {
    # One dpkg-query for all; packages dpkg has never heard of are simply absent from its output.
    local installed
    installed=$(dpkg-query -W -f='${Package} ${db:Status-Status}\n' "${APT_PACKAGES[@]}" 2>/dev/null |
        awk '$2 == "installed" { print $1 }' || true)
    local p
    for p in "${APT_PACKAGES[@]}"; do
        grep -qxF "$p" <<<"$installed" || printf '%s\n' "$p"
    done
}

ensure_system_packages() {
    if ! command -v dpkg-query >/dev/null 2>&1; then
        say "not a Debian-like system: make sure the equivalents of ${APT_PACKAGES[*]} are installed"
        return
    fi
    local missing
    mapfile -t missing < <(missing_packages)
    if [ "${#missing[@]}" -eq 0 ]; then
        say "system packages present (${#APT_PACKAGES[@]} checked)"
        return
    fi
    local install=(apt-get install -y -q -o Dpkg::Options::=--force-confdef -o Dpkg::Options::=--force-confold
        "${missing[@]}")
    local -a sudo=()
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
            sudo=(sudo -n env DEBIAN_FRONTEND=noninteractive)
        else
            printf 'setup: missing system packages: %s\n' "${missing[*]}" >&2
            printf 'setup: run this, then try again:\n  sudo apt-get update && sudo apt-get install -y %s\n' \
                "${missing[*]}" >&2
            exit 1
        fi
    fi
    say "installing system packages: ${missing[*]}"
    quiet "${sudo[@]}" apt-get update -q || die "apt-get update failed"
    quiet "${sudo[@]}" "${install[@]}" || die "apt-get install ${missing[*]} failed"
    mapfile -t missing < <(missing_packages)
    [ "${#missing[@]}" -eq 0 ] || die "still missing after apt-get: ${missing[*]}"
}

# -- 2. virtualenv --------------------------------------------------------------------------
ensure_venv() {
    if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c '' 2>/dev/null; then
        say "virtualenv $VENV present"
        return
    fi
    command -v "$PYTHON" >/dev/null 2>&1 || die "$PYTHON not found (install python3, or set PYTHON=...)"
    "$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 11))' ||
        die "RTMU needs Python >= 3.11; $PYTHON is $("$PYTHON" -V 2>&1) (set PYTHON=python3.11 or newer)"
    rm -rf "$VENV"
    "$PYTHON" -m venv "$VENV" || die "'$PYTHON -m venv' failed (on Debian/Ubuntu: apt-get install python3-venv)"
    rm -f "$STAMP"
    say "virtualenv $VENV created with $("$VENV/bin/python" -V 2>&1)"
}

# -- 3. the project -------------------------------------------------------------------------
ensure_project() {
    local want
    want="$(sha256sum pyproject.toml "$CONSTRAINTS" | cut -d' ' -f1 | tr '\n' ' ')$("$VENV/bin/python" -V 2>&1)"
    if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$want" ] && [ -x "$VENV/bin/rtmu" ]; then
        say "python packages up to date"
        return
    fi
    say "installing rtmu and its dev tools into $VENV (PyGObject builds from source: a minute or two)"
    "$VENV/bin/python" -m pip install -q --disable-pip-version-check -c "$CONSTRAINTS" -e '.[dev]' </dev/null ||
        die "pip install -c $CONSTRAINTS -e '.[dev]' failed (see above)"
    printf '%s\n' "$want" >"$STAMP"
    say "python packages installed"
}

ensure_system_packages
ensure_venv
ensure_project
bash scripts/install-desktop.sh || say "the desktop entry was not installed (RTMU still runs as .venv/bin/rtmu)"
