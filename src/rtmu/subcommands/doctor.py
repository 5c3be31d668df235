"""``rtmu doctor HOST[:PORT]``: walk the whole way to a robot and say, step by step, what worked.

"It doesn't connect and I can't tell why" is what owners of ARIA robots ask most. The doctor
tries each step on its own — name resolution, TCP connect, the server's introduction (its version
tag and protocol string), the login, the data list (and which RTMU features the server offers),
UDP, the first status and the status stream's timing (what RTMU learns from it: how long a drive
waits for status before it stops) — and for the first step that fails says in plain words what went wrong
and what to do next (the same words the window uses, :mod:`rtmu.client.diagnosis`). It stops
there; the exit code names the step (10 name … 15 status; UDP never fails it, RTMU uses TCP).
Connected, it asks the last question with a login of its own: why won't it move? — ``rtmu why``'s
answer (:mod:`rtmu.client.why`); that step fails with the cause's own code (20–39).
"""

from __future__ import annotations

import argparse
import contextlib
import socket
import sys
import time
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import (
    ENDED,
    EXIT_DOCTOR_DATALIST,
    EXIT_DOCTOR_INTRODUCTION,
    EXIT_DOCTOR_LOGIN,
    EXIT_DOCTOR_RESOLVE,
    EXIT_DOCTOR_STATUS,
    EXIT_DOCTOR_TCP,
    EXIT_INTERNAL,
    EXIT_OK,
    EXIT_USAGE,
    WHY_ASKED,
)
from ..base.i18n import N_, Said, _
from ..base.link_timing import STATUS_CEILING
from ..base.textsafe import visible
from ..base.units import Quantity
from ..values.target import Target
from ._common import (
    Interrupted,
    UsageError,
    add_connection_arguments,
    print_json,
    read_password,
    run_interruptibly,
)
from .doctor_link import READ_CHUNK, check_udp, learn_link_timing
from .doctor_steps import StepFailed, StepResult, fail, features_of, report_lines

if TYPE_CHECKING:
    import asyncio

    from ..client.diagnosis import Step
    from ..protocol.client_connection import ClientConnection
    from ..protocol.events import ServerIntroduction

EXITS = (
    EXIT_OK, EXIT_INTERNAL, EXIT_USAGE, EXIT_DOCTOR_RESOLVE, EXIT_DOCTOR_TCP, EXIT_DOCTOR_INTRODUCTION,
    EXIT_DOCTOR_LOGIN, EXIT_DOCTOR_DATALIST, EXIT_DOCTOR_STATUS, *WHY_ASKED, *ENDED,
)  # fmt: skip
NOT_ARIA_AFTER = 4096
"""Bytes without a single valid packet after which the peer is taken for something else."""
LINK_SECONDS = 3.0
"""How long the status step watches the status stream to learn the link's timing (``--link-seconds``)."""
ADVICE_LINK_STALLS = (
    "the link held status back longer than RTMU waits before stopping a drive: check the robot's "
    "Wi-Fi (signal, roaming, a crowded channel) before driving far"
)


class Doctor:
    """One walk to one server; :meth:`run` fills :attr:`steps` and returns the exit code."""

    def __init__(
        self,
        host: str,
        port: int,
        user: str,
        password: str,
        protocol: str | None,
        timeout: float,
        link_seconds: float = LINK_SECONDS,
    ):
        self.host, self.port, self.user = host, port, user
        self.link_seconds = link_seconds
        self._password = password
        self._motion_password = password
        """Kept for the motion step's own login, forgotten once it has logged in."""
        self.protocol = protocol
        self.timeout = timeout
        self.steps: list[StepResult] = []
        self.features: dict[str, bool] = {}
        self.conn: ClientConnection | None = None
        self.reader: asyncio.StreamReader | None = None
        self.writer: asyncio.StreamWriter | None = None
        self.address = ""

    def ok(self, step: Step, summary: str, result: str = "ok", advice: str = "", **details: Any) -> None:
        self.steps.append(StepResult(step, result, summary, advice, dict(details)))

    async def run(self) -> int:
        from ..client.diagnosis import Step

        try:
            await self._resolve()
            await self._connect()
            intro = await self._introduction()
            await self._login(intro)
            await self._data_list()
            await check_udp(self.address, intro, self.ok)
            await self._status()
            await self._close()  # one login at a time: a robot may take few clients
            await self._motion()
        except StepFailed as exc:
            self.steps.append(exc.result)
            done = {s.step for s in self.steps}
            for step in Step:
                if step not in done:
                    self.steps.append(
                        StepResult(step, "skipped", Said(N_("not tried (an earlier step failed)")))
                    )
            return int(exc.result.details.get("exit_code", exc.result.step.value))
        finally:
            self._motion_password = ""
            await self._close()
        return EXIT_OK

    # -- steps ------------------------------------------------------------------------------------
    async def _resolve(self) -> None:
        import asyncio

        from ..client.diagnosis import ADVICE, Step

        loop = asyncio.get_running_loop()
        try:
            async with asyncio.timeout(self.timeout):
                infos = await loop.getaddrinfo(self.host, self.port, type=socket.SOCK_STREAM)
        except TimeoutError:
            raise fail(
                Step.RESOLVE,
                Said(
                    N_("looking up {host} took over {timeout}"),
                    host=repr(self.host),
                    timeout=Quantity(self.timeout, "s", None),
                ),
                ADVICE["resolve"],
            ) from None
        except socket.gaierror as exc:
            raise fail(
                Step.RESOLVE,
                Said(N_("cannot find host {host}: {error}"), host=repr(self.host), error=exc.strerror or exc),
                ADVICE["resolve"],
            ) from None
        addresses = sorted({str(info[4][0]) for info in infos})
        self.address = addresses[0]
        self.ok(
            Step.RESOLVE,
            Said(N_("{host} is {addresses}"), host=self.host, addresses=", ".join(addresses)),
            addresses=addresses,
        )

    async def _connect(self) -> None:
        import asyncio

        from ..client.diagnosis import ADVICE, Step

        where = f"{self.host}:{self.port}"
        started = time.monotonic()
        try:
            async with asyncio.timeout(self.timeout):
                self.reader, self.writer = await asyncio.open_connection(self.host, self.port)
        except TimeoutError:
            raise fail(
                Step.TCP,
                Said(
                    N_("connecting to {where} timed out after {timeout}"),
                    where=where,
                    timeout=Quantity(self.timeout, "s", None),
                ),
                ADVICE["connect_timeout"],
            ) from None
        except ConnectionRefusedError:
            raise fail(
                Step.TCP, Said(N_("{where} refused the connection"), where=where), ADVICE["refused"]
            ) from None
        except OSError as exc:
            raise fail(
                Step.TCP,
                Said(N_("cannot connect to {where}: {error}"), where=where, error=exc.strerror or exc),
                ADVICE["unreachable"],
            ) from None
        ms = (time.monotonic() - started) * 1000.0
        said = Said(N_("connected to {where} in {time}"), where=where, time=Quantity(ms, "ms"))
        self.ok(Step.TCP, said, connect_ms=round(ms, 1))

    async def _read_events(self, step: Step, what: str) -> list[Any]:
        """The next events from the server, or the step fails (EOF, timeout, not ArNetworking)."""
        import asyncio

        from ..client.diagnosis import ADVICE, Step
        from ..client.login import TEXT_BANNERS
        from ..protocol.errors import ProtocolError

        assert self.reader is not None and self.conn is not None
        while True:
            try:
                async with asyncio.timeout(self.timeout):
                    data = await self.reader.read(READ_CHUNK)
            except TimeoutError:
                advice = ADVICE["no_introduction"] if step is Step.INTRODUCTION else ADVICE["login_timeout"]
                raise fail(
                    step,
                    Said(
                        N_("no {what} within {timeout}"), what=what, timeout=Quantity(self.timeout, "s", None)
                    ),
                    advice,
                ) from None
            except OSError as exc:
                raise fail(
                    step,
                    Said(N_("the connection broke: {error}"), error=exc.strerror or exc),
                    ADVICE["closed_early"],
                ) from None
            if not data:
                raise fail(
                    step,
                    Said(N_("the server closed the connection before its {what}"), what=what),
                    ADVICE["closed_early"],
                )
            if self._received == 0 and data.startswith(TEXT_BANNERS):
                said = data[:40].split(b"\n")[0].decode("ascii", "replace").strip()
                raise fail(
                    step,
                    Said(N_("the server said {said}: that is not ArNetworking"), said=repr(said)),
                    ADVICE["not_aria"],
                )
            self._received += len(data)
            try:
                events = self.conn.receive_data(data)
            except ProtocolError as exc:
                raise fail(
                    step,
                    Said(N_("the server's {what} is not ArNetworking: {error}"), what=what, error=exc),
                    ADVICE["not_aria"],
                ) from None
            if self._received >= NOT_ARIA_AFTER and self.conn.decoder.stats.packets == 0:
                raise fail(
                    step,
                    Said(N_("{count} bytes without a single ArNetworking packet"), count=self._received),
                    ADVICE["not_aria"],
                )
            self._flush()
            if events:
                return events

    def _flush(self) -> None:
        assert self.writer is not None and self.conn is not None
        out = self.conn.data_to_send()
        if out:
            self.writer.write(out)

    async def _introduction(self) -> ServerIntroduction:
        from ..client.diagnosis import Step
        from ..protocol.client_connection import ClientConnection
        from ..protocol.events import ServerIntroduction

        self.conn = ClientConnection(self.user, self._password, protocol_version=self.protocol)
        self._password = ""
        self._received = 0
        while True:
            for event in await self._read_events(Step.INTRODUCTION, Said(N_("introduction"))):
                if isinstance(event, ServerIntroduction):
                    return self._describe_intro(event)

    def _describe_intro(self, intro: ServerIntroduction) -> ServerIntroduction:
        from ..client.diagnosis import Step

        wanted = intro.protocol_version
        assert self.conn is not None
        sent = self.conn.sent_protocol_version or ""
        if wanted:
            proto = Said(
                N_("protocol string {wanted} (enforced; we answer {sent})"),
                wanted=repr(wanted),
                sent=repr(sent),
            )
        else:
            proto = Said(N_("no protocol string (not enforced)"))
        udp = (
            Said(N_("UDP port {port}"), port=intro.udp_port)
            if intro.udp_port
            else Said(N_("no UDP (TCP only)"))
        )
        self.ok(
            Step.INTRODUCTION,
            Said(
                N_("an ArNetworking server (tag {tag}), {protocol}, {udp}"),
                tag=repr(intro.version_tag),
                protocol=proto,
                udp=udp,
            ),
            version_tag=intro.version_tag,
            protocol=wanted,
            sent_protocol=sent,
            udp_port=intro.udp_port,
        )
        return intro

    async def _login(self, intro: ServerIntroduction) -> None:
        from ..client.diagnosis import ADVICE, Step, login_finding
        from ..protocol.events import Connected, DataListReady, PeerShutdown, Rejected

        assert self.conn is not None
        while True:
            for event in await self._read_events(Step.LOGIN, Said(N_("answer to our login"))):
                if isinstance(event, Rejected):
                    finding = login_finding(
                        event.reason,
                        event.text,
                        intro.protocol_version,
                        self.conn.sent_protocol_version or "",
                    )
                    raise fail(
                        Step.LOGIN, finding.problem, finding.advice, reason=event.reason, text=event.text
                    )
                if isinstance(event, PeerShutdown):
                    raise fail(
                        Step.LOGIN, Said(N_("the server shut the connection down")), ADVICE["closed_early"]
                    )
                if isinstance(event, Connected):
                    said = (
                        Said(N_("logged in as {user}"), user=repr(self.user))
                        if self.user
                        else Said(N_("logged in without a user name"))
                    )
                    self.ok(Step.LOGIN, said, user=self.user)
                    return
                if isinstance(event, DataListReady):  # CONNECTED came in the same read
                    return

    async def _data_list(self) -> None:
        from ..client.config_feed import ConfigApi, config_api
        from ..client.diagnosis import Step

        assert self.conn is not None
        while not self.conn.datalist.complete:
            await self._read_events(Step.DATA_LIST, Said(N_("data list")))
        entries = list(self.conn.datalist)
        names = {e.name for e in entries}
        self.features = features_of(names)
        groups = {e.command_group for e in entries}
        have = [k for k, v in self.features.items() if v]
        missing = [k for k, v in self.features.items() if not v]
        summary = Said(
            N_("{count} data in {groups} groups; RTMU can use: {have}{missing}{ld}"),
            count=len(entries),
            groups=len(groups),
            have=", ".join(have) or Said(N_("nothing")),
            missing=Said(N_("; not offered: {names}"), names=", ".join(missing)) if missing else "",
            ld=Said(
                N_("; its configuration is Omron LD's (getConfigValues): RTMU cannot show or edit it yet")
            )
            if config_api(names) is ConfigApi.OMRON_LD
            else "",
        )
        advice = ""
        if not self.features["teleop"] and self.user:
            advice = N_("driving is not offered to this user: log in as a user whose groups include Movement")
        self.ok(
            Step.DATA_LIST,
            summary,
            "ok" if not advice else "warn",
            advice,
            count=len(entries),
            groups=len(groups),
            features=self.features,
        )

    async def _status(self) -> None:
        from ..client.diagnosis import ADVICE, Step, central_server_words
        from ..client.robot_status import read_status

        conn = self.conn
        assert conn is not None
        name = "updateNumbers" if "updateNumbers" in conn.datalist else "update"
        if name not in conn.datalist:
            if "clientList" in conn.datalist:  # it lists robots instead of being one
                where = f"{self.host}:{self.port}"
                raise fail(Step.STATUS, central_server_words(where), ADVICE["central_server"])
            raise fail(Step.STATUS, Said(N_("the server offers no robot status")), ADVICE["status_missing"])
        robot = await read_status(self._once, conn.datalist)
        if robot is None:
            raise fail(
                Step.STATUS,
                Said(N_("the server's {name} reply does not decode"), name=name),
                ADVICE["status_timeout"],
            )
        soc, status, mode = robot.battery_is_soc, robot.status, robot.mode
        x, y, th, level = int(robot.x), int(robot.y), int(robot.th), robot.battery_v or 0.0
        battery = (
            Said(N_("{percent} charge"), percent=Quantity(level, "%")) if soc else Quantity(level, "V", 1)
        )
        text = Said(
            N_("robot at ({x}, {y}) mm, {th}, battery {battery}{status}"),
            x=Quantity(x, ""),
            y=Quantity(y, ""),
            th=Quantity(th, "deg"),
            battery=battery,
            status=f", {status} ({mode})" if status else "",
        )
        details: dict[str, Any] = {"x": x, "y": y, "th": th, "status": status}
        details["battery_pct" if soc else "battery_v"] = level
        advice = ""
        if self.link_seconds > 0:
            assert self.conn is not None and self.reader is not None
            link = await learn_link_timing(self.conn, self.reader, self._flush, name, self.link_seconds)
            details["link"] = link
            text = Said(
                N_(
                    "{status}; status every {every} for {watched}: longest gap {gap}, learned jitter "
                    "{jitter}, so driving stops after {limit} without status"
                ),
                status=text,
                every=Quantity(link["status_every_ms"], "ms", None),
                watched=Quantity(self.link_seconds, "s", None),
                gap=Quantity(link["longest_gap_ms"], "ms", None),
                jitter=Quantity(link["jitter_ms"], "ms", None),
                limit=Quantity(link["stale_after_s"], "s", 2),
            )
            if link["longest_gap_ms"] > STATUS_CEILING * 1000:
                advice = ADVICE_LINK_STALLS
        self.ok(Step.STATUS, text, advice=advice, **details)

    async def _motion(self) -> None:
        """``rtmu why``'s answer, asked over a login of its own (the steps above use the bare codec)."""
        from ..client.connection import AriaClient
        from ..client.diagnosis import Step
        from ..client.errors import ClientError
        from ..client.roles import Role
        from ..client.why import diagnose
        from ..client.why_gather import gather

        client = AriaClient()
        try:
            await client.connect(
                Target(self.host, self.port, self.user, self._motion_password, protocol=self.protocol),
                timeout=self.timeout,
                role=Role.OBSERVER,
            )
            answer = diagnose(await gather(client, self.timeout))
        except ClientError as exc:
            self.ok(Step.MOTION, Said(N_("could not ask: {error}"), error=exc), "warn")
            return
        finally:
            self._motion_password = ""
            await client.disconnect()
        reason = answer.primary
        if reason is None:
            self.ok(Step.MOTION, answer.sentence())
            return
        others = [r.sentence() for r in answer.reasons[1:]]
        raise fail(
            Step.MOTION,
            reason.problem,
            reason.advice,
            cause=reason.cause.key,
            exit_code=reason.cause.value,
            also=others,
        )

    async def _once(self, name: str) -> Any:
        from ..client.diagnosis import ADVICE, Step
        from ..protocol.errors import ProtocolError
        from ..protocol.events import DataReceived, PeerShutdown
        from ..protocol.payloads import Side, decode_payload

        conn = self.conn
        assert conn is not None
        number = conn.number_of(name)
        conn.request_once(name)
        self._flush()
        while True:
            for event in await self._read_events(Step.STATUS, Said(N_("{name} reply"), name=name)):
                if isinstance(event, DataReceived) and event.command == number:
                    try:
                        return decode_payload(name, Side.REPLY, event.payload)
                    except (ProtocolError, ValueError) as exc:
                        raise fail(Step.STATUS, f"the server's {name} reply does not decode: {exc}") from None
                if isinstance(event, PeerShutdown):
                    raise fail(
                        Step.STATUS, Said(N_("the server shut the connection down")), ADVICE["closed_early"]
                    )

    async def _close(self) -> None:
        import asyncio

        if self.writer is None:
            return
        with contextlib.suppress(Exception):
            if self.conn is not None:
                self.conn.shutdown()
                self._flush()
        writer, self.writer = self.writer, None  # closed once, whoever asks again
        with contextlib.suppress(Exception):
            writer.close()
            async with asyncio.timeout(1.0):
                await writer.wait_closed()


# -- command line -------------------------------------------------------------------------------------
def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "doctor",
        help=_("find out why a robot does not connect, step by step"),
        description=_(
            "Walk the whole way to a robot and say, step by step, what worked: name resolution, "
            "TCP connect, the server's introduction (its version tag and protocol string), the login, the "
            "data list (and which RTMU features the server offers), UDP, the first status. For the first "
            "step that fails it says in plain words what went wrong and what to do next (the words the "
            "window uses), and stops there; the exit code names the step. UDP never fails it: RTMU uses TCP. "
            "Connected, it asks last why the robot would not move (rtmu why's answer); that step fails with "
            "the cause's own code."
        ),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json",
        action="store_true",
        help=_(
            'one JSON object: {"server", "ok", "failed_step", "exit_code", "features", "steps": '
            '[{"step", "title", "result", "summary", "advice", ...}]}'
        ),
    )
    p.add_argument(
        "--link-seconds",
        type=float,
        default=LINK_SECONDS,
        metavar="S",
        help=f"watch the status stream this long to learn its timing (default {LINK_SECONDS:g}; 0: skip)",
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..settings.last_doctor import save_last_doctor

    host, port = args.server
    try:
        password = read_password(args)
    except UsageError as exc:
        print(_("rtmu doctor: {visible}").format(visible=visible(exc)), file=sys.stderr)
        return EXIT_USAGE
    doctor = Doctor(host, port, args.user, password, args.protocol, args.timeout, max(0.0, args.link_seconds))
    try:
        code = run_interruptibly(doctor.run)
    except Interrupted as exc:
        print(_("rtmu doctor: {exc}").format(exc=exc), file=sys.stderr)
        return exc.exit_code
    failed = next((s for s in doctor.steps if s.result == "fail"), None)
    lines = report_lines(doctor.steps, host, port, args.user, failed, code)
    save_last_doctor(lines)  # for the window's About ▸ debug information
    if args.json:
        print_json(
            {
                "server": f"{host}:{port}",
                "ok": failed is None,
                "failed_step": failed.step.key if failed else None,
                "exit_code": code,
                "features": doctor.features,
                "steps": [s.as_json() for s in doctor.steps],
            }
        )
        return code
    for line in lines:
        print(line)
    return code
