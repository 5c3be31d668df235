"""What the network subcommands share: ``HOST[:PORT]``, login options, exit codes, one-line errors.

Every network subcommand takes ``HOST[:PORT]`` (default port 7272; ``[::1]:7272``
for IPv6), ``--user``, ``--password-file`` (or a prompt — a password is never
accepted on the command line, where other users could read it in ``ps``) and
``--timeout``. Failures print ONE line on stderr (``rtmu NAME: what went wrong``)
and exit with a code scripts can rely on (constants in ``rtmu.cli``):

====  =========================================================
0     ok
2     usage error (bad arguments)
3     connection or login failure (refused, unreachable, rejected, closed)
4     the server does not offer what is needed
5     timeout
====  =========================================================
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import getpass
import sys
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

from ..cli import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..client.connection import CONNECT_TIMEOUT, DEFAULT_PORT, AriaClient
from ..client.errors import ClientError
from ..protocol.errors import ProtocolError

MAX_PASSWORD_FILE = 4096


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


def add_connection_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "server", type=host_port, metavar="HOST[:PORT]", help="robot server (port 7272 by default)"
    )
    parser.add_argument("--user", default="", help="user name, if the server has a user file")
    parser.add_argument(
        "--password-file",
        type=Path,
        metavar="FILE",
        help="read the password from the first line of FILE (else it is asked for when --user is given)",
    )
    parser.add_argument(
        "--timeout",
        type=positive_float,
        default=CONNECT_TIMEOUT,
        metavar="S",
        help=f"seconds to wait for the server at each step (default {CONNECT_TIMEOUT:g})",
    )


class UsageError(Exception):
    """Bad arguments discovered after parsing (exit 2)."""


def read_password(args: argparse.Namespace) -> str:
    """From ``--password-file``, else a prompt on the terminal (or one line of stdin when piped)."""
    path: Path | None = getattr(args, "password_file", None)
    if path is not None:
        try:
            with path.open("rb") as f:
                data = f.read(MAX_PASSWORD_FILE)
        except OSError as exc:
            raise UsageError(f"cannot read the password file {path}: {exc.strerror or exc}") from None
        return data.decode("utf-8", "replace").splitlines()[0] if data else ""
    if not args.user:
        return ""
    if sys.stdin is not None and sys.stdin.isatty():
        return getpass.getpass(f"Password for {args.user}@{args.server[0]}: ")
    line = sys.stdin.readline() if sys.stdin is not None else ""
    return line.rstrip("\r\n")


def _cancel_on_terminate() -> None:
    """SIGTERM (e.g. ``timeout``, a service manager) ends a command like Ctrl-C does: through the
    ``finally`` blocks, so ``rtmu drive`` always sends its stop before the process goes."""
    import signal

    task = asyncio.current_task()
    if task is None:
        return
    loop = asyncio.get_running_loop()
    with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
        loop.add_signal_handler(signal.SIGTERM, task.cancel)


def fail(name: str, message: str, code: int) -> int:
    print(f"rtmu {name}: {message}", file=sys.stderr)
    return code


def run_with_client(name: str, args: argparse.Namespace, body: Callable[[AriaClient], Awaitable[int]]) -> int:
    """Log in, run ``body(client)``, always disconnect; map every failure to an exit code and one line."""
    try:
        password = read_password(args)
    except UsageError as exc:
        return fail(name, str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail(name, "cancelled", EXIT_USAGE)

    async def main() -> int:
        host, port = args.server
        client = AriaClient()
        _cancel_on_terminate()
        try:
            await client.connect(host, port, args.user, password, timeout=args.timeout)
            return await body(client)
        finally:
            await client.disconnect()

    try:
        return asyncio.run(main())
    except ClientError as exc:
        return fail(name, str(exc), exc.exit_code)
    except ProtocolError as exc:  # a reply that does not decode, wherever a command looked at it
        return fail(name, f"the server sent something malformed: {exc}", EXIT_CONNECTION)
    except UsageError as exc:
        return fail(name, str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, asyncio.CancelledError):
        print(file=sys.stderr)
        return EXIT_OK
    except BrokenPipeError:  # e.g. piped into ``head``: the reader has what it wanted
        _silence_stdout()
        return EXIT_OK
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
    import json

    print(json.dumps(obj, separators=(",", ":"), ensure_ascii=False), flush=True)


STATUS_KEYS = ("x", "y", "th", "vel", "rot_vel", "battery_v", "status", "mode")
"""The documented keys of a status object: mm, mm, degrees, mm/s, deg/s, volts (or % charge), text, text."""


def status_object(numbers: Any, status: str, mode: str) -> dict[str, Any]:
    """One status as the JSON object ``rtmu status`` and ``rtmu drive`` print."""
    return {
        "x": numbers.x,
        "y": numbers.y,
        "th": numbers.th,
        "vel": numbers.vel,
        "rot_vel": numbers.rot_vel,
        "battery_v": numbers.battery,
        "status": status,
        "mode": mode,
    }


def status_line(obj: dict[str, Any]) -> str:
    return (
        f"x={obj['x']} mm  y={obj['y']} mm  th={obj['th']}°  vel={obj['vel']} mm/s  "
        f"rot={obj['rot_vel']}°/s  battery={obj['battery_v']:.1f}  {obj['status']} ({obj['mode']})"
    )


async def fetch_status(client: AriaClient, timeout: float) -> dict[str, Any]:
    """One status from ``updateNumbers`` + ``updateStrings`` (or the old ``update``)."""
    from ..client.errors import NotSupported
    from ..protocol.payloads.robot import Update, UpdateNumbers, UpdateStrings

    if client.supports("updateNumbers"):
        numbers = (await client.request_once("updateNumbers", timeout=timeout)).decode()
        assert isinstance(numbers, UpdateNumbers)
        status = mode = ""
        if client.supports("updateStrings"):
            strings = (await client.request_once("updateStrings", timeout=timeout)).decode()
            assert isinstance(strings, UpdateStrings)
            status, mode = strings.status, strings.mode
        return status_object(numbers, status, mode)
    if client.supports("update"):
        update = (await client.request_once("update", timeout=timeout)).decode()
        assert isinstance(update, Update)
        return status_object(update.numbers, update.status, update.mode)
    raise NotSupported("updateNumbers", "this server offers no robot status (updateNumbers or update)")
