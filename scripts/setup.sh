#!/usr/bin/env bash
# Prepare this checkout to run RTMU on Debian 12 / Ubuntu, from nothing, without questions:
#   0. a Python >= 3.11 (python3 where the distribution's is new enough; Ubuntu 22.04's is 3.10, so
#      there python3.11 from its archive);
#   1. the system packages that Python, GTK 4 and the PyGObject build need (apt, only when some are
#      missing);
#   2. a virtualenv in .venv;
#   3. the project and its dev tools in it, at the versions in constraints.txt (pip, only when
#      pyproject.toml or constraints.txt changed since last time).
# ./rtmu-dev runs this before every command, so a re-run must stay quick: it checks and skips.
# Needs only bash (and apt on a bare machine). Environment: PYTHON picks the interpreter (>= 3.11).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive

APT_PACKAGES=(
    gir1.2-gtk-4.0 gir1.2-adw-1 gir1.2-manette-0.2 libgirepository1.0-dev libcairo2-dev pkg-config
    build-essential xvfb xdotool openbox x11-utils xxd bsdextrautils
    appstream desktop-file-utils dbus git
    at-spi2-core python3-pyatspi
)
# Every program the app, tests, bench and scripts start -> the package above that installs it
# ("essential": in every Debian install). tests/test_setup_programs.py keeps this true.
# A program may come from a direct dependency of the package named (dbus brings the session bus's
# daemon on both: see SPLIT_PACKAGES). Not dbus-x11: its
# dbus-launch makes GLib start a stray bus of its own wherever DBUS_SESSION_BUS_ADDRESS is unset.
# at-spi2-core's at-spi-bus-launcher starts an accessibility bus (the AT-SPI test starts its own on a
# private session bus); python3-pyatspi is what that test reads the window with, as a screen reader does
# (linked into the venv below: it is a system package only).
PROGRAM_PACKAGES=(
    Xvfb=xvfb xdotool=xdotool openbox=openbox xwininfo=x11-utils xprop=x11-utils bash=essential
    at-spi-bus-launcher=at-spi2-core
    xxd=xxd hexdump=bsdextrautils od=essential
    appstreamcli=appstream desktop-file-validate=desktop-file-utils
    dbus-daemon=dbus dbus-run-session=dbus git=git
)
# Packages that one distribution splits out and another does not: named where apt knows them. Debian 12
# ships the session bus's daemon as dbus-daemon (dbus depends on it); Ubuntu 22.04's dbus holds it.
SPLIT_PACKAGES=(
    dbus-daemon
)
VENV=.venv
STAMP="$VENV/.rtmu-setup-stamp"
CONSTRAINTS=constraints.txt
PYTHON="${PYTHON:-}"
PYTHON_PACKAGES=()
APT_PYTHON3=
SUDO=()
APT_UPDATED=0

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

have() { command -v "$1" >/dev/null 2>&1; }

# -- 0. which Python ------------------------------------------------------------------------
python_ok() { # python_ok CMD: CMD runs and is Python >= 3.11
    have "$1" && "$1" -c 'import sys; sys.exit(sys.version_info < (3, 11))' >/dev/null 2>&1
}

packages_for_python() { # the apt packages behind an interpreter name: python3 or python3.N
    case "$1" in
        python3) PYTHON_PACKAGES=(python3 python3-venv python3-dev) ;;
        python3.[0-9]*) PYTHON_PACKAGES=("$1" "$1-venv" "$1-dev") ;;
        *) PYTHON_PACKAGES=() ;; # an interpreter of the user's own (a path, pyenv...): theirs to equip
    esac
}

apt_candidate() { # apt_candidate PACKAGE: the version apt would install, or nothing
    LC_ALL=C apt-cache policy "$1" 2>/dev/null | awk '$1 == "Candidate:" && $2 != "(none)" { print $2; exit }'
}

version_at_least_3_11() { # version_at_least_3_11 DEBIAN_VERSION (e.g. 3.10.6-1~22.04, 3.11.2-1+b1)
    local v="${1#*:}" major minor
    major="${v%%.*}"
    minor="${v#*.}"
    minor="${minor%%[!0-9]*}"
    [[ "$major" =~ ^[0-9]+$ && "$minor" =~ ^[0-9]+$ ]] || return 1
    [ "$major" -gt 3 ] || { [ "$major" -eq 3 ] && [ "$minor" -ge 11 ]; }
}

no_python_hint() {
    printf 'setup: no Python >= 3.11 found. Install one, then try again:\n' >&2
    printf '  Debian 12:    sudo apt-get update && sudo apt-get install -y python3 python3-venv python3-dev\n' >&2
    printf '  Ubuntu 22.04: sudo apt-get update && sudo apt-get install -y python3.11 python3.11-venv python3.11-dev\n' >&2
    exit 1
}

# Sets PYTHON and PYTHON_PACKAGES. No apt query when a good interpreter is already installed.
choose_python() {
    if [ -n "$PYTHON" ]; then
        packages_for_python "$PYTHON"
        return
    fi
    local v
    for v in python3 python3.11 python3.12 python3.13 python3.14; do
        if python_ok "$v"; then
            PYTHON=$v
            packages_for_python "$v"
            return
        fi
    done
    # Nothing suitable installed: ask apt (after an update when its lists are empty or too old to say).
    have apt-cache || die "no Python >= 3.11 found: install one (with its venv module), or set PYTHON=..."
    python_from_apt && return
    can_be_root || no_python_hint
    apt_update
    python_from_apt ||
        die "no Python >= 3.11 installed or available from apt (python3: ${APT_PYTHON3:-none}); install one, set PYTHON=..."
}

# Debian 12's python3 is 3.11; Ubuntu 22.04's is 3.10 and its archive has python3.11 beside it.
python_from_apt() {
    APT_PYTHON3=$(apt_candidate python3)
    if [ -n "$APT_PYTHON3" ] && version_at_least_3_11 "$APT_PYTHON3"; then
        PYTHON=python3
        packages_for_python python3
        return 0
    fi
    local v
    for v in python3.11 python3.12 python3.13; do
        if [ -n "$(apt_candidate "$v")" ] && [ -n "$(apt_candidate "$v-venv")" ]; then
            say "the distribution's python3 is ${APT_PYTHON3:-not available}; using $v"
            PYTHON=$v
            packages_for_python "$v"
            return 0
        fi
    done
    return 1
}

# -- 1. system packages ---------------------------------------------------------------------
can_be_root() { # sets SUDO when needed; false when apt cannot be run without a password
    [ "$(id -u)" -eq 0 ] && return 0
    have sudo && sudo -n true 2>/dev/null || return 1
    SUDO=(sudo -n env DEBIAN_FRONTEND=noninteractive)
}

need_root() { # need_root PACKAGE...: be able to run apt, or print the command to run and stop
    can_be_root && return
    printf 'setup: missing system packages: %s\n' "$*" >&2
    printf 'setup: run this, then try again:\n  sudo apt-get update && sudo apt-get install -y %s\n' "$*" >&2
    exit 1
}

apt_update() { # callers made sure apt can run (need_root, can_be_root)
    [ "$APT_UPDATED" -eq 0 ] || return 0
    say "apt-get update"
    quiet "${SUDO[@]}" apt-get update -q || die "apt-get update failed"
    APT_UPDATED=1
}

missing_packages() {
    # One dpkg-query for all; packages dpkg has never heard of are simply absent from its output.
    local installed all=("${PYTHON_PACKAGES[@]}" "${APT_PACKAGES[@]}")
    installed=$(dpkg-query -W -f='${Package} ${db:Status-Status}\n' "${all[@]}" 2>/dev/null |
        awk '$2 == "installed" { print $1 }' || true)
    local p
    for p in "${all[@]}"; do
        grep -qxF "$p" <<<"$installed" || printf '%s\n' "$p"
    done
}

add_split_packages() { # SPLIT_PACKAGES this system knows (installed, or a candidate of apt's) join APT_PACKAGES
    local p
    for p in "${SPLIT_PACKAGES[@]}"; do
        [[ " ${APT_PACKAGES[*]} " == *" $p "* ]] && continue # already joined (a second run)
        if dpkg-query -W -f='${Package} ${db:Status-Status}\n' "$p" 2>/dev/null | grep -qxF "$p installed" ||
            [ -n "$(apt_candidate "$p")" ]; then
            APT_PACKAGES+=("$p")
        fi
    done
}

ensure_system_packages() {
    if ! have dpkg-query; then
        say "not a Debian-like system: make sure the equivalents of ${APT_PACKAGES[*]} are installed"
        [ -n "$PYTHON" ] || PYTHON=python3
        return
    fi
    choose_python
    add_split_packages
    local missing
    mapfile -t missing < <(missing_packages)
    if [ "${#missing[@]}" -eq 0 ]; then
        say "system packages present ($((${#PYTHON_PACKAGES[@]} + ${#APT_PACKAGES[@]})) checked)"
        return
    fi
    need_root "${missing[@]}"
    apt_update
    say "installing system packages: ${missing[*]}"
    quiet "${SUDO[@]}" apt-get install -y -q -o Dpkg::Options::=--force-confdef \
        -o Dpkg::Options::=--force-confold "${missing[@]}" || die "apt-get install ${missing[*]} failed"
    mapfile -t missing < <(missing_packages)
    [ "${#missing[@]}" -eq 0 ] || die "still missing after apt-get: ${missing[*]}"
}

# -- 2. virtualenv --------------------------------------------------------------------------
ensure_venv() {
    if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c '' 2>/dev/null; then
        say "virtualenv $VENV present"
        return
    fi
    have "$PYTHON" || die "$PYTHON not found (install Python >= 3.11, or set PYTHON=...)"
    python_ok "$PYTHON" ||
        die "RTMU needs Python >= 3.11; $PYTHON is $("$PYTHON" -V 2>&1) (set PYTHON=python3.11 or newer)"
    rm -rf "$VENV"
    "$PYTHON" -m venv "$VENV" || die "'$PYTHON -m venv' failed (on Debian/Ubuntu: apt-get install $PYTHON-venv)"
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
    # pygobject-stubs builds its stubs for the GTK named here at install time; no pip cache, so a wheel
    # once built for GTK 3 (its default) cannot come back from ~/.cache/pip.
    export PYGOBJECT_STUB_CONFIG=Gtk4,Gdk4
    "$VENV/bin/python" -m pip install -q --no-cache-dir --disable-pip-version-check -c "$CONSTRAINTS" -e '.[dev]' </dev/null ||
        die "pip install -c $CONSTRAINTS -e '.[dev]' failed (see above)"
    printf '%s\n' "$want" >"$STAMP"
    say "python packages installed"
}

# -- 4. the system's pyatspi in the venv ----------------------------------------------------------
# pyatspi is pure Python over GObject introspection and exists only as a distribution package, not on
# PyPI. The venv (without --system-site-packages, so the system's other Python packages never shadow the
# pinned ones) gets a link to that one package; the venv's own PyGObject loads the Atspi typelib.
ensure_pyatspi() {
    have dpkg-query || return 0
    local init src site
    init=$(dpkg-query -L python3-pyatspi 2>/dev/null | grep -m1 '/pyatspi/__init__.py$' || true)
    [ -n "$init" ] || return 0 # not a Debian-like system, or not installed: the AT-SPI test says so
    src=${init%/__init__.py}
    for site in "$VENV"/lib/python3*/site-packages; do
        [ -d "$site" ] || continue # no venv yet (or another layout): nothing to link into
        [ "$(readlink "$site/pyatspi" 2>/dev/null)" = "$src" ] && continue
        ln -sfn "$src" "$site/pyatspi"
        say "linked the system's pyatspi into $site"
    done
}

main() {
    ensure_system_packages
    ensure_venv
    ensure_project
    ensure_pyatspi
    # Nothing is installed into the user's desktop from here: that is 'rtmu --install-desktop', on request.
}

# Sourcing this file (to try its functions) defines them without running anything.
if [ "${BASH_SOURCE[0]}" = "$0" ]; then
    main
fi
