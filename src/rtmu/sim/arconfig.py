"""The simulator's own configuration (ArConfig), served and changed through ARIA's config packets.

Every parameter is bound to the live simulation: a ``setConfig`` that passes validation changes the
ratio-drive watchdog, the speed limits, the camera's frame size, the battery drain or the Wi-Fi model
at once. Validation is all-or-nothing: the first error (naming ``Section/Parameter``) is the answer
and nothing changes, which is what an ARIA server ends up with too (it reloads its file after a
refused set). A set that changed something is broadcast as ``configUpdated`` to the other clients.

``SimConfig.config_filler`` adds that many extra parameters (markup in their texts, many sections)
so clients can be tried on a hostile configuration.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads.config import (
    ConfigParam,
    ConfigRequest,
    ConfigSectionFlags,
    ConfigSectionPacket,
    ConfigUpdated,
    LastEditablePriority,
    ParamType,
    Priority,
    SetConfig,
    SetConfigReply,
    Value,
    value_text,
)
from rtmu.protocol.payloads.config import ConfigSectionPacketV1 as V1
from rtmu.protocol.payloads.config import ConfigSectionPacketV2 as V2
from rtmu.protocol.payloads.config import ConfigSectionPacketV3 as V3

from . import map_switch, p3dx

if TYPE_CHECKING:
    from .context import ArConfigStore, SimHost
    from .handlers import Call, Handler, Reply

LAST_EDITABLE = Priority.EXPERT
"""As ARIA's handler without factory permission: FACTORY parameters are shown, never changed."""
CAMERA_SIZES = {"320x240": (320, 240), "640x480": (640, 480)}
FILLER_PER_SECTION = 1000
FILLER_CONTROL_SECTION = "Line\rbreak\nand \x1b[2Jescape"
"""A hostile section name with filler: a CR, a newline and a terminal escape in it."""
MIN_TIMEOUT = 0.1
"""A watchdog shorter than a client's resend period would stop every held drive: refused (0 is "off")."""


@dataclass
class SimParam:
    """One parameter: its description for the wire, and how it reads and changes the simulation."""

    section: str
    template: ConfigParam
    get: Callable[[], Value]
    set: Callable[[Value], None]
    check: Callable[[Value], str] | None = None
    """Why a value that fits the type cannot be taken ("" when it can): ``Files/Map`` names a missing file."""

    def current(self) -> ConfigParam:
        return replace(self.template, value=self.get())


class SimArConfig:
    """The sections and parameters of one simulator, bound to its world."""

    def __init__(self, host: SimHost, filler: int = 0) -> None:
        self.host = host
        self.comments: dict[str, str] = {}
        self.params: list[SimParam] = []
        self._by_key: dict[tuple[str, str], SimParam] = {}
        self.sets = 0
        """Accepted ``setConfig``s (for tests)."""
        self._filler_sections: set[str] = set()
        self._filler_packets: dict[tuple[str, int, int, bool], list[bytes]] = {}
        """Encoded filler sections (thousands of parameters take a while: not on every request)."""
        self._build()
        self._fill(filler)
        self.defaults = self.values()
        """The factory values (``getConfigDefaults``): every parameter as the simulator started with it."""
        if filler:
            self.packets(4, ConfigRequest())  # encode them now, not in a client's first request

    # -- what there is ------------------------------------------------------------------------------
    def _add(
        self,
        section: str,
        template: ConfigParam,
        get: Callable[[], Value],
        put: Callable[[Value], None],
        check: Callable[[Value], str] | None = None,
    ) -> None:
        p = SimParam(section, template, get, put, check)
        self.params.append(p)
        if template.kind is not ParamType.SEPARATOR:
            self._by_key[(section.lower(), template.name.lower())] = p

    def _build(self) -> None:
        world = self.host.world
        ratio, body, ap = world.ratio_mode, world.body, world.access_point
        none = lambda: None  # noqa: E731
        ignore = lambda v: None  # noqa: E731

        def setter(obj: object, attr: str) -> Callable[[Value], None]:
            return lambda v: setattr(obj, attr, float(v or 0))

        self.comments["Teleop"] = "Driving by hand (ratioDrive)"
        self._add(
            "Teleop",
            ConfigParam(
                "Timeout",
                ParamType.DOUBLE,
                0.0,
                "Stop a ratio drive when no command came for this long, in seconds (0 disables the watchdog)",
                Priority.INTERMEDIATE,
                0.0,
                60.0,
                2,
            ),
            lambda: ratio.timeout,
            setter(ratio, "timeout"),
        )
        for ahead, word in ((True, "Forward"), (False, "Backward")):
            self._add("Teleop", _clearance(word), *self._margin(ahead))
        self.comments["Robot config"] = "Limits of the simulated Pioneer 3-DX"
        self._add(
            "Robot config",
            ConfigParam(
                "TransVelMax",
                ParamType.INT,
                0,
                "Fastest a full-stick ratio drive goes forward, in mm/s (backwards: a quarter)",
                Priority.BASIC,
                0,
                int(p3dx.TRANS_VEL_MAX),
            ),
            lambda: round(ratio.trans_vel_max),
            setter(ratio, "trans_vel_max"),
        )
        self._add(
            "Robot config",
            ConfigParam(
                "RotVelMax",
                ParamType.INT,
                0,
                "Fastest a ratio drive turns, in deg/s",
                Priority.BASIC,
                0,
                int(p3dx.ABSOLUTE_MAX_ROT_VEL),
            ),
            lambda: round(ratio.rot_vel_max),
            setter(ratio, "rot_vel_max"),
        )
        for name, attr, what, top in (
            ("TransDecel", "trans_decel", "Braking on a stop or zero ratios, in mm/s²", 1000),
            ("RotDecel", "rot_decel", "Slowing of a turn on a stop or zero ratios, in deg/s²", 500),
        ):  # ARIA's ArRobotConfig lists these beside TransVelMax; its absolute maxima cap them
            self._add(
                "Robot config",
                ConfigParam(name, ParamType.INT, 0, what, Priority.BASIC, 10, top),
                lambda attr=attr: round(getattr(body, attr)),  # type: ignore[misc]
                setter(body, attr),
            )
        self._add("Robot config", ConfigParam("", ParamType.SEPARATOR), none, ignore)
        self._add(
            "Robot config",
            ConfigParam(
                "SerialNumber",
                ParamType.STRING,
                "",
                "The robot's serial number, set at the factory",
                Priority.FACTORY,
            ),
            lambda: "SIM-P3DX-0001",
            ignore,
        )
        self.comments["Camera"] = "The simulated camera"
        self._add(
            "Camera",
            ConfigParam(
                "FrameSize",
                ParamType.STRING,
                "",
                "Size of the frames sendVideo and getPicture send, in pixels",
                Priority.INTERMEDIATE,
                display_hint="Choices:" + ";;".join(CAMERA_SIZES),
            ),
            lambda: "{}x{}".format(*self.host.video_size),
            self._set_frame_size,
        )
        self.comments["Battery"] = "The simulated battery pack"
        self._add(
            "Battery",
            ConfigParam(
                "Drain", ParamType.BOOL, True, "Whether the pack runs down at all", Priority.ADVANCED
            ),
            lambda: body.drain_scale > 0.0,
            self._set_drain,
        )
        self._add(
            "Battery",
            ConfigParam(
                "DrainScale",
                ParamType.DOUBLE,
                1.0,
                "How many times a real P3-DX's drain the pack loses (1 = real, 100 = flat in minutes)",
                Priority.ADVANCED,
                0.0,
                1000.0,
                2,
            ),
            lambda: body.drain_scale,
            setter(body, "drain_scale"),
        )
        self.comments["Wi-Fi"] = "The radio model behind the Wi-Fi figures"
        self._add(
            "Wi-Fi",
            ConfigParam(
                "TxAt1m",
                ParamType.DOUBLE,
                0.0,
                "Signal 1 m from the access point, in dBm",
                Priority.EXPERT,
                -90.0,
                0.0,
                1,
            ),
            lambda: ap.tx_at_1m_dbm,
            setter(ap, "tx_at_1m_dbm"),
        )
        self._add(
            "Wi-Fi",
            ConfigParam(
                "PathLossExponent",
                ParamType.DOUBLE,
                0.0,
                "How fast the signal falls with distance (2 = free space)",
                Priority.EXPERT,
                1.0,
                6.0,
                2,
            ),
            lambda: ap.path_loss_exponent,
            setter(ap, "path_loss_exponent"),
        )
        self._add(
            "Wi-Fi",
            ConfigParam(
                "WallLoss",
                ParamType.DOUBLE,
                0.0,
                "Signal lost through each wall, in dB",
                Priority.EXPERT,
                0.0,
                30.0,
                1,
            ),
            lambda: ap.wall_loss_db,
            setter(ap, "wall_loss_db"),
        )
        self.comments[map_switch.SECTION] = map_switch.COMMENT  # ARNL's map file (rtmu.sim.map_switch)
        self._add(
            map_switch.SECTION,
            map_switch.TEMPLATE,
            lambda: map_switch.current(self.host),
            lambda v: map_switch.switch(self.host, str(v or "")),
            lambda v: map_switch.problem(self.host, str(v or "")),
        )

    def _margin(self, ahead: bool) -> tuple[Callable[[], Value], Callable[[Value], None]]:
        """Safe drive's margin, told as ARIA's limiter measures it: from half the robot's length (as
        physicalInfo gives it) ahead of and behind its centre; the simulated body is a circle."""
        margins = self.host.world.body.safe_margin
        beyond = p3dx.RADIUS_MM - p3dx.LENGTH_MM / 2

        def put(v: Value) -> None:
            margins[ahead] = max(float(v or 0) - beyond, 0.0)

        return (lambda: round(margins[ahead] + beyond)), put

    def _set_frame_size(self, v: Value) -> None:
        self.host.video_size = CAMERA_SIZES[str(v)]

    def _set_drain(self, v: Value) -> None:
        body = self.host.world.body
        if not v:
            body.drain_scale = 0.0
        elif body.drain_scale <= 0.0:
            body.drain_scale = 1.0

    def _fill(self, count: int) -> None:
        """Hostile extras: many sections of many parameters, markup and ampersands in every text."""
        store: dict[tuple[str, str], Value] = {}
        kinds = (ParamType.INT, ParamType.DOUBLE, ParamType.BOOL, ParamType.STRING)
        for i in range(count):
            section = f"<b>Extra</b> & {i // FILLER_PER_SECTION}"
            self.comments.setdefault(section, "<i>filler</i> & <span foreground='red'>markup</span>")
            self._filler_sections.add(section)
            kind = kinds[i % len(kinds)]
            name = f"P{i}<i>&amp;"
            start: Value = {ParamType.INT: i, ParamType.DOUBLE: i / 10, ParamType.BOOL: i % 2 == 0}.get(
                kind, f"<b>{i}</b>"
            )
            store[(section, name)] = start
            limits: tuple[int | float | None, int | float | None] = (None, None)
            if kind is ParamType.INT:
                limits = (-1_000_000, 1_000_000)
            elif kind is ParamType.DOUBLE:
                limits = (-math.inf, math.inf)
            template = ConfigParam(
                name,
                kind,
                None,
                f"<u>filler</u> {i} & <big>text</big>",
                i % 5,
                *limits,
                2 if kind is ParamType.DOUBLE else -1,
                display_hint=f"Choices:<b>{i}</b>;;<i>a</i> & b"
                if kind is ParamType.STRING and i % 8 == 7
                else "",
            )
            key = (section, name)
            self._add(section, template, lambda k=key: store[k], lambda v, k=key: store.__setitem__(k, v))  # type: ignore[misc]
        if count:  # control characters in names: a CR, a newline, an escape
            section, name = FILLER_CONTROL_SECTION, "Line\rbreak"
            store[(section, name)] = 1
            template = ConfigParam(name, ParamType.INT, None, "a CR in its name", 0, 0, 10, -1)
            self._add(
                section,
                template,
                lambda: store[(FILLER_CONTROL_SECTION, "Line\rbreak")],
                lambda v: store.__setitem__((FILLER_CONTROL_SECTION, "Line\rbreak"), v),
            )

    def values(self) -> list[tuple[str, str, str]]:
        """``(section, parameter, value text)`` of every parameter that has a value, in order."""
        return [
            (p.section, p.template.name, value_text(p.template.kind, p.get()))
            for p in self.params
            if p.template.kind not in (ParamType.SEPARATOR, ParamType.LIST)
        ]

    def sections(self) -> list[str]:
        seen: dict[str, None] = {}
        for p in self.params:
            seen.setdefault(p.section, None)
        return list(seen)

    # -- answers ---------------------------------------------------------------------------------
    def packets(self, version: int, request: ConfigRequest) -> list[bytes]:
        """The section packets (split into parts where too big, V3+), then the empty end packet."""
        cls = {1: V1, 2: V2, 3: V3}.get(version, ConfigSectionPacket)
        last = Priority.ADVANCED if request.last_priority is None else Priority.of(request.last_priority)
        read_only_too = request.last_editable is not None
        out: list[bytes] = []
        by_section: dict[str, list[SimParam]] = {}
        for p in self.params:
            by_section.setdefault(p.section, []).append(p)
        for section, params in by_section.items():
            key = (section, version, int(last), read_only_too)
            cached = self._filler_packets.get(key)
            if cached is not None:
                out += cached
                continue
            first = len(out)
            head = cls(section, self.comments.get(section, ""), (), "")
            head_size = len(head.encode())
            part: list[ConfigParam] = []
            index, size = 1, head_size
            for p in params:
                if not read_only_too and p.template.priority > LAST_EDITABLE:
                    continue
                param = p.current()
                if param.priority > last:
                    param = replace(param, priority=last)
                w = FieldWriter()
                param.write(w, cls.VERSION)
                one = len(w) + 1  # and its 'P'
                if part and size + one > MAX_PAYLOAD:
                    if version < 3:
                        break  # an older client gets what fits (ARIA sends nothing of it)
                    out.append(replace(head, params=tuple(part), index=index).encode())
                    part, index, size = [], index + 1, head_size
                part.append(param)
                size += one
            out.append(replace(head, params=tuple(part), index=index).encode())
            if section in self._filler_sections:  # only the filler's values never change behind our back
                self._filler_packets[key] = out[first:]
        out.append(b"")
        return out

    def apply(self, request: SetConfig) -> tuple[str, bool]:
        """Check every value, then change all or nothing: (first error or "", whether anything changed)."""
        planned: list[tuple[SimParam, Value]] = []
        for section, name, text in request.by_section():
            p = self._by_key.get((section.lower(), name.lower()))
            if p is None:
                where = f"{section}/{name}" if section else name
                return f"{where}: there is no such parameter", False
            value, error = parse_value(p, text)
            if (
                not error
                and p.template.name == "Timeout"
                and isinstance(value, float)
                and 0 < value < MIN_TIMEOUT
            ):
                error = (
                    f"{text.strip()} s is shorter than the 0.1 s between ratioDrive commands (0 disables it)"
                )
            if not error and p.check is not None:
                error = p.check(value)
            if error:
                return f"{p.section}/{p.template.name}: {error}", False
            planned.append((p, value))
        changed = False
        for p, value in planned:
            if p.get() != value:
                p.set(value)
                changed = True
                if p.section in self._filler_sections:
                    self._filler_packets = {
                        k: v for k, v in self._filler_packets.items() if k[0] != p.section
                    }
        if planned:
            self.sets += 1
        return "", changed


def parse_value(p: SimParam, text: str) -> tuple[Value, str]:
    """``text`` as the parameter's type within its limits, or an error that says why not."""
    t = p.template
    if t.priority > LAST_EDITABLE:
        return None, f"a {Priority(t.priority).name.lower()} parameter cannot be changed here"
    raw = text.strip()
    if t.kind is ParamType.BOOL:
        low = raw.lower()
        if low in ("true", "1", "yes", "on"):
            return True, ""
        if low in ("false", "0", "no", "off"):
            return False, ""
        return None, f"{text!r} is not true or false"
    if t.kind in (ParamType.INT, ParamType.DOUBLE):
        try:
            number: int | float = int(raw) if t.kind is ParamType.INT else float(raw)
        except ValueError:
            kind = "a whole number" if t.kind is ParamType.INT else "a number"
            return None, f"{text!r} is not {kind}"
        if isinstance(number, float) and math.isnan(number):
            return None, "NaN is not a number"
        if t.minimum is not None and number < t.minimum:
            return None, f"{raw} is below the minimum of {t.minimum:g}"
        if t.maximum is not None and number > t.maximum:
            return None, f"{raw} is above the maximum of {t.maximum:g}"
        return number, ""
    if t.kind is ParamType.STRING:
        if t.choices and raw not in t.choices:
            return None, f"{text!r} is not one of {', '.join(t.choices)}"
        return raw, ""
    return None, "this parameter has no value to set"


# -- the data module: handlers (see rtmu.sim.profiles; the rows are ARIA's, in rtmu.sim.catalogue.CONFIG) --


def _store(call: Call) -> ArConfigStore:
    return call.server.arconfig


def _request(call: Call) -> ConfigRequest:
    try:
        return ConfigRequest.decode(call.args)
    except (FieldUnderrun, PayloadError):
        return ConfigRequest(None, None)


def _clearance(word: str) -> ConfigParam:
    return ConfigParam(
        f"{word}Clearance",
        ParamType.INT,
        0,
        f"Safe drive stops this far short of anything {'ahead' if word == 'Forward' else 'behind'}, "
        "in mm from half the robot's length ahead of (behind) its centre",
        Priority.INTERMEDIATE,
        0,
        2000,
    )


def _get_by_sections(version: int) -> Handler:
    def handler(call: Call) -> Iterable[Reply]:
        return _store(call).packets(version, _request(call))

    return handler


def _set_config(call: Call) -> Iterable[Reply]:
    try:
        request = SetConfig.decode(call.args)
    except (FieldUnderrun, PayloadError) as exc:
        return (SetConfigReply(f"the request did not decode: {exc}").encode(),)
    error, changed = _store(call).apply(request)
    if changed:
        call.server.broadcast(ConfigUpdated.DATA_NAME, ConfigUpdated().encode(), exclude=call.session)
    return (SetConfigReply(error).encode(),)


def _section_flags(call: Call) -> Iterable[Reply]:
    return (ConfigSectionFlags(tuple((s, "") for s in _store(call).sections())).encode(),)


def _last_editable(call: Call) -> Iterable[Reply]:
    return (LastEditablePriority(LAST_EDITABLE).encode(),)


HANDLERS: dict[str, Handler] = {
    "getConfigBySectionsV4": _get_by_sections(4),
    "getConfigBySectionsV3": _get_by_sections(3),
    "getConfigBySectionsV2": _get_by_sections(2),
    "getConfigBySections": _get_by_sections(1),
    "setConfig": _set_config,
    "getConfigSectionFlags": _section_flags,
    "getLastEditablePriority": _last_editable,
}
