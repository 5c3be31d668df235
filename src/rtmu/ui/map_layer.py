"""The map under the robot — background, tiles and cairns — painted once per view and re-used.

Why: following a drive, the view stays put while only the robot and what moves with it change
(10 status frames a second), yet every frame blitted each tile again and laid out and stroked every
cairn and name (issue 28: the window's Python while following was mostly this). :class:`MapLayer`
keeps one picture of that static part for one view — the viewport, the tile cache's map, the cairns
shown — and a frame paints it with one call, then draws the robot and its overlays on top.

It draws exactly what the direct path would (``frame.draw_base`` both ways) and steps aside — the
caller draws directly — while a visible tile is still missing (the picture would freeze the
overview's blur). A name moves out from under the robot: while the robot stands on one (at Home, at
a dock), the picture is made for that pose, and made again only when the robot moves on such a name.
GTK-free, like ``frame``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import cairo

from . import overlays
from .overlays import Box
from .tiles import TileCache
from .viewport import Viewport

XY = tuple[float, float]
DrawBase = Callable[[cairo.Context, Viewport, XY | None, list[Box]], bool]
"""Draws the static part at a viewport, names moved from under a robot there (None: no robot);
fills the list with every name's box; True when complete."""


class MapLayer:
    """One stored picture of the static map for the last view; ``scale`` is the widget's device scale."""

    def __init__(self) -> None:
        self.scale = 1
        """Pixels per logical pixel (the widget's scale factor): the picture stays sharp on HiDPI."""
        self.builds = 0
        """Pictures made so far (tests and the benchmark read it)."""
        self.uses = 0
        """Frames painted from a stored picture."""
        self._key: tuple[object, ...] | None = None
        self._surface: cairo.ImageSurface | None = None
        self._names: list[Box] = []
        self._avoided: XY | None = None
        """The robot's place the stored names were moved from (None: no name was under it)."""

    def forget(self) -> None:
        """Drop the picture (a new map, or the stage closed): its memory goes at once."""
        self._key, self._surface, self._names, self._avoided = None, None, [], None

    def paint(
        self,
        ctx: cairo.Context,
        vp: Viewport,
        tiles: TileCache,
        objects: Sequence[object],
        robot: XY | None,
        draw_base: DrawBase,
    ) -> bool:
        """Paint the stored picture of this view (made now if needed); False: draw directly instead."""
        surface = self.picture(vp, tiles, objects, robot, draw_base)
        if surface is None:
            return False
        ctx.save()
        ctx.new_path()
        ctx.set_source_surface(surface, 0, 0)
        ctx.rectangle(0, 0, vp.width, vp.height)
        ctx.fill()
        ctx.restore()
        return True

    def picture(
        self,
        vp: Viewport,
        tiles: TileCache,
        objects: Sequence[object],
        robot: XY | None,
        draw_base: DrawBase,
    ) -> cairo.ImageSurface | None:
        """The stored picture of this view, made now if needed — the same object for as long as it
        stays right, so a caller may keep what it made of it; None: draw directly instead."""
        key = (vp, tiles.generation, id(objects), len(objects), self.scale)
        if key != self._key:
            self.forget()
            spots = tiles.visible(vp.scale, vp.origin, vp.width, vp.height)
            if any(spot.surface is None for spot in spots):
                return None  # tiles still coming: the direct path shows the overview meanwhile
            self._surface, self._names = self._build(vp, None, draw_base)
            self._key = key
        avoided = None
        if robot is not None and self._names:
            box = overlays.robot_box(vp, *robot)
            avoided = robot if any(overlays.overlap(name, box) for name in self._names) else None
        if avoided != self._avoided:  # the robot came onto a name, moved on it, or left it
            self._surface, self._names = self._build(vp, avoided, draw_base)
            self._avoided = avoided
        self.uses += 1
        return self._surface

    def _build(
        self, vp: Viewport, avoided: XY | None, draw_base: DrawBase
    ) -> tuple[cairo.ImageSurface, list[Box]]:
        scale = max(1, int(self.scale))
        surface = cairo.ImageSurface(cairo.FORMAT_RGB24, vp.width * scale, vp.height * scale)
        surface.set_device_scale(scale, scale)
        names: list[Box] = []
        draw_base(cairo.Context(surface), vp, avoided, names)
        surface.flush()
        self.builds += 1
        return surface, names
