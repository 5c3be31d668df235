"""What the network subcommands share: ``HOST[:PORT]``, login options, exit codes, one-line errors.

Every network subcommand takes ``HOST[:PORT]`` (default port 7272; ``[::1]:7272``
for IPv6), ``--user``, ``--password-file``, ``--password-stdin`` (or a prompt on a terminal —
a password is never accepted on the command line, where other users could read it in ``ps``,
nor read from a pipe unless ``--password-stdin`` says so) and ``--timeout``. Failures print
ONE line on stderr (``rtmu NAME: what went wrong``) and exit with a code of the one table in
:mod:`rtmu.base.exit_codes` (printed by every ``--help``).

Signals: SIGINT, SIGTERM, SIGHUP (a closed terminal or SSH session), SIGQUIT, SIGUSR1/2 and
SIGALRM end a command through its ``finally`` blocks — ``rtmu drive`` always sends zero ratios and
``stop`` before it goes. SIGTSTP (Ctrl-Z) first runs the command's suspend hooks
(``rtmu drive``: stop the robot), then suspends the process as usual.
"""

from __future__ import annotations

import argparse
import contextlib
import contextvars
import getpass
import inspect
import os
import signal
import sys
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from ..base.exit_codes import EXIT_CONNECTION, EXIT_SIGPIPE, EXIT_USAGE
from ..base.i18n import N_, Said, _, as_said, error_words
from ..client.defaults import CONNECT_TIMEOUT, DEFAULT_PORT
from ..client.errors import ClientError
from ..client.roles import Role
from ..protocol.errors import ProtocolError
from ..values.target import Target

if TYPE_CHECKING:
    import asyncio

    from ..client.connection import AriaClient

MAX_PASSWORD_FILE = 4096
T = TypeVar("T")


def host_port(text: str) -> tuple[str, int]:
    """``host``, ``host:port``, ``[v6]:port`` or a bare IPv6 address → (host, port)."""
    text = text.strip()
    if not text:
        raise argparse.ArgumentTypeError("empty host")
    if text.startswith("["):
        host, sep, rest = text[1:].partition("]")
        if not sep or (rest and not rest.startswith(":")):
            raise argparse.ArgumentTypeError(f"bad address {text!r}: use [v6addr]:port")
        port_text = rest[1:]
    elif text.count(":") == 1:
        host, port_text = text.split(":")
    else:
        host, port_text = text, ""  # a name, an IPv4 address, or a bare IPv6 address
    if not host:
        raise argparse.ArgumentTypeError(f"no host in {text!r}")
    if not port_text:
        return host, DEFAULT_PORT
    if not port_text.isdigit() or not 1 <= int(port_text) <= 65535:
        raise argparse.ArgumentTypeError(f"bad port {port_text!r}: use 1…65535")
    return host, int(port_text)


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0 or value != value or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number: {text!r}")
    return value


class _RefusePassword(argparse.Action):
    """``--password``: refused without repeating the value (it would land in the error and in logs)."""

    def __call__(
        self, parser: argparse.ArgumentParser, namespace: Any, values: Any, option: Any = None
    ) -> None:
        parser.error(
            "a password is never accepted on the command line (other users can read it with ps); "
            "use --password-file FILE, --password-stdin, or give --user alone to be asked for it"
        )


def _refuse_unknown_quietly(parser: argparse.ArgumentParser) -> None:
    """Unknown arguments are an error that names the options but not the values around them.

    argparse would repeat ``--pass hunter2`` verbatim in "unrecognized arguments"; a value
    typed after a mistyped option may be a password.
    """
    parse_known = parser.parse_known_args

    def parse_known_args(args: Any = None, namespace: Any = None) -> tuple[argparse.Namespace, list[str]]:
        namespace, extras = parse_known(args, namespace)
        if extras:
            options = [a.split("=", 1)[0] for a in extras if a.startswith("-")]
            others = len(extras) - len(options)
            shown = " ".join(options)
            if others:
                shown += f"{' and ' if options else ''}{others} other argument{'s' if others > 1 else ''}"
            parser.error(f"unrecognized arguments: {shown} (values not shown)")
        return namespace, extras

    parser.parse_known_args = parse_known_args  # type: ignore[method-assign,assignment]


def add_connection_arguments(parser: argparse.ArgumentParser, *, robot: bool = True) -> None:
    """``HOST[:PORT]``, the login options, ``--timeout``; ``robot``: also ``--robot NAME`` (through a
    central server), which a command that lists the central server's robots itself does not take."""
    # No abbreviations: "--password secret" must not be taken for "--password-file secret".
    parser.allow_abbrev = False
    _refuse_unknown_quietly(parser)
    _resolve_robot_first(parser)
    parser.add_argument(
        "server", type=host_port, metavar="HOST[:PORT]", help=_("robot server (port 7272 by default)")
    )
    parser.add_argument(
        "--user", default="", metavar="USER", help=_("user name, if the server has a user file")
    )
    parser.add_argument("--password", nargs="?", action=_RefusePassword, help=argparse.SUPPRESS)
    parser.add_argument(
        "--password-file",
        type=Path,
        metavar="FILE",
        help=_(
            "read the password from the first line of FILE (else it is asked for on the terminal when "
            "--user is given)"
        ),
    )
    parser.add_argument(
        "--password-stdin",
        action="store_true",
        help=_(
            "read the password from the first line of standard input (for scripts; nothing else reads "
            "a password from a pipe)"
        ),
    )
    parser.add_argument(
        "--protocol",
        metavar="STRING",
        default=None,
        help=_(
            "protocol string to log in with (default: the one the server advertises, e.g. 6MTX on "
            "Omron LD robots)"
        ),
    )
    parser.add_argument(
        "--timeout",
        type=positive_float,
        default=CONNECT_TIMEOUT,
        metavar="S",
        help=f"seconds to wait for the server at each step (default {CONNECT_TIMEOUT:g})",
    )
    if robot:
        parser.add_argument(
            "--robot",
            metavar="NAME",
            default=None,
            help=_(
                "HOST[:PORT] is an ARIA central server: act on its robot NAME, through the port it "
                "forwards that robot on ('rtmu fleet HOST' lists them)"
            ),
        )


def _resolve_robot_first(parser: argparse.ArgumentParser) -> None:
    """With ``--robot NAME``, the subcommand's handler first resolves NAME through the central server.

    The handler then sees ``args.server`` as the robot's forwarded address, so every subcommand (and a
    drive's guardian, which logs in to ``args.server`` too) reaches that robot without knowing.
    """
    parse_known = parser.parse_known_args

    def parse_known_args(args: Any = None, namespace: Any = None) -> tuple[argparse.Namespace, list[str]]:
        namespace, extras = parse_known(args, namespace)
        handler = getattr(namespace, "handler", None)
        robot = getattr(namespace, "robot", None)
        if robot is not None and handler is not None and not getattr(handler, "resolves_robot", False):
            namespace.handler = _through_central(handler)
        return namespace, extras

    parser.parse_known_args = parse_known_args  # type: ignore[method-assign,assignment]


def _through_central(handler: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    def resolved(args: argparse.Namespace) -> int:
        code = resolve_robot(args)
        return code if code is not None else handler(args)

    resolved.resolves_robot = True  # type: ignore[attr-defined]
    return resolved


def resolve_robot(args: argparse.Namespace) -> int | None:
    """Point ``args.server`` at robot ``args.robot`` behind the central server ``args.server``.

    None when done; else the exit code, after one line on stderr: 2 for a name the central server
    does not list (naming the ones it does), 3/4/5 as for any login.
    """
    from ..base.textsafe import visible
    from ..client.central import AmbiguousRobot, find_robot, list_robots

    name = str(getattr(args, "subcommand", None) or "rtmu")
    try:
        password = read_password(args)
    except UsageError as exc:
        return fail(name, str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail(name, "cancelled", EXIT_USAGE)
    host, port = args.server
    try:
        robots = run_interruptibly(lambda: list_robots(host, port, args.user, password, timeout=args.timeout))
    except ClientError as exc:
        return fail(name, f"central server {host}:{port}: {exc}", exc.exit_code)
    except ProtocolError as exc:
        return fail(name, f"central server {host}:{port} sent a malformed robot list: {exc}", EXIT_CONNECTION)
    except Interrupted as exc:
        return fail(name, error_words(exc), exc.exit_code)
    wanted = args.robot
    try:
        found = find_robot(robots, wanted)  # without case, as ARIA compares; several: refused
    except AmbiguousRobot as exc:
        return fail(name, str(exc), EXIT_USAGE)
    if found is None:
        listed = visible(", ".join(e.name for e, _ in robots) or "none")
        where = f"behind the central server {host}:{port}"
        return fail(name, f"no robot {wanted!r} {where} (robots: {listed})", EXIT_USAGE)
    args.server = (found.host, found.port)
    return None


class UsageError(Exception):
    """Bad arguments discovered after parsing (exit 2)."""


def read_password(args: argparse.Namespace) -> str:
    """From ``--password-file``, ``--password-stdin`` or a prompt on the terminal; :class:`UsageError`
    (exit 2, with the reason) when ``--user`` is given and none of them can supply it."""
    cached = getattr(args, "password_read", None)
    if isinstance(cached, str):  # asked already (for the central server of --robot): never twice
        return cached
    password = _read_password(args)
    args.password_read = password
    return password


def _read_password(args: argparse.Namespace) -> str:
    path: Path | None = getattr(args, "password_file", None)
    if path is not None:
        try:
            with path.open("rb") as f:
                data = f.read(MAX_PASSWORD_FILE)
        except FileNotFoundError:
            # Not named: what was typed there may be the password itself rather than a file name.
            raise UsageError(
                _(
                    "cannot read the password file given with --password-file: no such file "
                    "(its name is not shown, in case a password was typed there)"
                )
            ) from None
        except OSError as exc:
            said = _("cannot read the password file {path}: {error}").format(
                path=path, error=exc.strerror or exc
            )
            raise UsageError(said) from None
        return data.decode("utf-8", "replace").splitlines()[0] if data else ""
    if getattr(args, "password_stdin", False):
        line = sys.stdin.readline() if sys.stdin is not None else ""
        if not line:
            raise UsageError(_("--password-stdin: standard input ended without a password line"))
        return line.rstrip("\r\n")
    if not args.user:
        return ""
    if sys.stdin is not None and sys.stdin.isatty():
        return getpass.getpass(_("Password for {user}@{host}: ").format(user=args.user, host=args.server[0]))
    raise UsageError(
        _(
            "--user {user} needs a password and there is no terminal to ask on: give --password-file "
            "FILE or --password-stdin (one line on standard input)"
        ).format(user=args.user)
    )


INTERRUPT_SIGNALS = (
    signal.SIGINT,
    signal.SIGTERM,
    signal.SIGHUP,
    signal.SIGQUIT,
    signal.SIGUSR1,
    signal.SIGUSR2,
    signal.SIGALRM,
)
"""Every catchable signal whose default action would end the process on the spot: each ends a
command through its ``finally`` blocks instead (exit 128 + the signal's number)."""


class Interrupted(Exception):
    """The command was ended by a signal; ``exit_code`` is 128 + its number, as shells report it."""

    def __init__(self, signum: int, detail: str = "") -> None:
        self.signum = signum
        self.exit_code = 128 + signum
        self.detail = detail
        name = signal_name(signum)
        said = (
            Said(N_("interrupted by {signal}; {detail}"), signal=name, detail=as_said(detail))
            if detail
            else Said(N_("interrupted by {signal}"), signal=name)
        )
        super().__init__(said)  # the operator reads it in their language (``error_words``)


async def until_stop_signal() -> int:
    """Wait for Ctrl-C, SIGTERM or SIGHUP: how a long-running server (``rtmu sim``) is told to stop
    cleanly. Returns the exit code that says which came (128 + its number, as every command)."""
    import asyncio

    stop = asyncio.Event()
    came: list[int] = []
    loop = asyncio.get_running_loop()

    def caught(signum: int) -> None:
        came.append(signum)
        stop.set()

    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        with contextlib.suppress(NotImplementedError, RuntimeError):
            loop.add_signal_handler(sig, caught, sig)
    await stop.wait()
    return 128 + came[0]


def signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


class Interrupts:
    """Turns the ending signals into a cancel of the command's task, remembering which one came.

    ``signum`` is the first ending signal (None until one arrives). ``take()`` lets a command
    that caught the cancel carry on cleaning up (stop, print a last status) before it raises
    :class:`Interrupted`. ``on_suspend(hook)`` registers what must happen before Ctrl-Z
    suspends the process (``rtmu drive`` stops the robot and waits, briefly, until the stop
    has left); ``end_on_resume`` makes the command end once the process runs again.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self.suspending = False
        """True from Ctrl-Z until the process runs again: nothing may start motion meanwhile."""
        self._task: asyncio.Task[Any] | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._suspend_hooks: list[Callable[[], Awaitable[Any] | None]] = []
        self._end_on_resume = False
        self._suspender: asyncio.Task[None] | None = None

    def install(self) -> None:
        """Handle the signals on the running loop, for the current task (call from that task)."""
        import asyncio

        self._task = asyncio.current_task()
        self._loop = asyncio.get_running_loop()
        for signum in INTERRUPT_SIGNALS:
            with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
                self._loop.add_signal_handler(signum, self.interrupt, signum)
        with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
            self._loop.add_signal_handler(signal.SIGTSTP, self._on_tstp)

    def interrupt(self, signum: int) -> None:
        """End the command as if ``signum`` had arrived (a second signal cancels again)."""
        if self.signum is None:
            self.signum = signum
        if self._task is not None and not self._task.done():
            self._task.cancel()

    def take(self) -> int | None:
        """The signal behind the cancel just caught, accepting it (None: not ours, re-raise it)."""
        if self.signum is None:
            return None
        if self._task is not None and self._task.cancelling():
            self._task.uncancel()
        return self.signum

    def on_suspend(self, hook: Callable[[], Awaitable[Any] | None], *, end_on_resume: bool = False) -> None:
        """Run ``hook`` (plain or async, bounded by :data:`SUSPEND_HOOK_TIMEOUT`) before Ctrl-Z suspends."""
        self._suspend_hooks.append(hook)
        self._end_on_resume = self._end_on_resume or end_on_resume

    def _on_tstp(self) -> None:
        if self._loop is None or self.suspending:
            return
        self.suspending = True
        self._suspender = self._loop.create_task(self._suspend())

    async def _suspend(self) -> None:
        import asyncio

        loop = self._loop
        assert loop is not None
        try:
            for hook in list(self._suspend_hooks):
                try:
                    result = hook()
                    if inspect.isawaitable(result):
                        async with asyncio.timeout(SUSPEND_HOOK_TIMEOUT):
                            await result
                except Exception as exc:  # the suspension must happen anyway
                    print(
                        _("rtmu: before suspending: {value}").format(value=exc or type(exc).__name__),
                        file=sys.stderr,
                    )
            # Suspend for real (the default action); we are back here after fg / SIGCONT.
            loop.remove_signal_handler(signal.SIGTSTP)
            os.kill(os.getpid(), signal.SIGTSTP)
            with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
                loop.add_signal_handler(signal.SIGTSTP, self._on_tstp)
        finally:
            self.suspending = False
        if self._end_on_resume:
            self.interrupt(signal.SIGTSTP)


SUSPEND_HOOK_TIMEOUT = 0.5
"""At most this long for the suspend hooks (e.g. until a stop has left) before Ctrl-Z suspends."""


_INTERRUPTS: contextvars.ContextVar[Interrupts | None] = contextvars.ContextVar(
    "rtmu_interrupts", default=None
)


def current_interrupts() -> Interrupts:
    """The running command's :class:`Interrupts` (a fresh, uninstalled one outside a command)."""
    found = _INTERRUPTS.get()
    return found if found is not None else Interrupts()


_PASSWORD: contextvars.ContextVar[str] = contextvars.ContextVar("rtmu_password", default="")


def current_password() -> str:
    """The running command's password, for its guardian's own login (``rtmu drive``), never asked twice."""
    return _PASSWORD.get()


def fail(name: str, message: str, code: int) -> int:
    from ..base.textsafe import visible

    print(_("rtmu {name}: {visible}").format(name=name, visible=visible(message)), file=sys.stderr)
    return code


def run_interruptibly(main: Callable[[], Awaitable[T]]) -> T:
    """``asyncio.run(main())`` with every ending signal (:data:`INTERRUPT_SIGNALS`) turned into
    :class:`Interrupted` — exit 128 + N — after the command's ``finally`` blocks ran, whenever it comes
    (before the handlers are in place, mid-command, or while the command is already ending)."""
    import asyncio

    interrupts = Interrupts()

    async def guarded() -> T:
        interrupts.install()
        _INTERRUPTS.set(interrupts)
        try:
            return await main()
        except asyncio.CancelledError:
            signum = interrupts.take()
            if signum is None:
                raise
            raise Interrupted(signum) from None

    try:
        return asyncio.run(guarded())
    except (KeyboardInterrupt, asyncio.CancelledError):
        raise Interrupted(interrupts.signum or signal.SIGINT) from None


def run_with_client(
    name: str, args: argparse.Namespace, body: Callable[[AriaClient], Awaitable[int]], *, role: Role
) -> int:
    """Log in as ``role``, run ``body(client)``, always disconnect; every failure → an exit code and one line.

    Every command says its role: an OBSERVER's client cannot send a motion request on any path.
    """
    import asyncio

    from ..client.connection import AriaClient

    try:
        password = read_password(args)
    except UsageError as exc:
        return fail(name, str(exc), EXIT_USAGE)
    except KeyboardInterrupt:
        return fail(name, "cancelled", 128 + signal.SIGINT)
    except EOFError:
        return fail(name, "cancelled", EXIT_USAGE)

    async def main() -> int:
        host, port = args.server
        client = AriaClient()
        _PASSWORD.set(password)
        try:
            target = Target(host, port, args.user, password, protocol=args.protocol)
            await client.connect(target, timeout=args.timeout, role=role)
            return await body(client)
        except asyncio.CancelledError:
            signum = current_interrupts().take()
            if signum is None:
                raise
            raise Interrupted(signum) from None
        finally:
            await client.disconnect()

    try:
        return run_interruptibly(main)
    except Interrupted as exc:
        return fail(name, error_words(exc), exc.exit_code)
    except ClientError as exc:
        return fail(name, error_words(exc), exc.exit_code)
    except ProtocolError as exc:  # a reply that does not decode, wherever a command looked at it
        said = _("the server sent something malformed: {error}").format(error=exc)
        return fail(name, said, EXIT_CONNECTION)
    except UsageError as exc:
        return fail(name, str(exc), EXIT_USAGE)
    except BrokenPipeError:  # e.g. piped into ``head``: the reader has what it wanted
        _silence_stdout()
        return EXIT_SIGPIPE
    except OSError as exc:  # e.g. writing the output file
        return fail(name, str(exc), EXIT_CONNECTION if isinstance(exc, ConnectionError) else EXIT_USAGE)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush does not complain again."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def print_json(obj: Any) -> None:
    """One JSON line: the exact strings, with characters that act on a terminal as ``\\uXXXX``."""
    import json

    from ..base.textsafe import json_safe

    print(json_safe(json.dumps(obj, separators=(",", ":"), ensure_ascii=False)), flush=True)


def known_name(command: str, kind: str, name: str, known: tuple[str, ...]) -> str | None:
    """The server's own spelling of ``name`` among ``known``, compared case-insensitively as ARIA
    compares goal names (an exact match first); None, with one line on stderr naming what the
    server does list, when it has no such name — the user's mistake (exit 2)."""
    if name in known:
        return name
    folded = [k for k in known if k.casefold() == name.casefold()]
    if len(folded) == 1:
        return folded[0]
    from ..base.textsafe import visible

    listed = visible(", ".join(known)) if known else _("none")
    print(
        _(UNKNOWN_NAME[kind]).format(command=command, visible=visible(repr(name)), listed=listed),
        file=sys.stderr,
    )
    return None


UNKNOWN_NAME = {
    "goal": N_("rtmu {command}: no goal {visible} on this server (goals: {listed})"),
    "route": N_("rtmu {command}: no route {visible} on this server (routes: {listed})"),
    "command": N_("rtmu {command}: no command {visible} on this server (commands: {listed})"),
}
"""What :func:`known_name` says for each kind of name (marked: a whole sentence per kind, so each language
can say it with its own words and grammar)."""
