"""Files on the robot for the window: list, download, upload, delete — each an intent, with progress.

The work is :mod:`.remote_files`, :mod:`.download` and :mod:`.upload` (the functions ``rtmu files`` uses):
names from the robot are checked, a download streams to a hidden file beside its destination and takes
its name only when complete, an upload stops at the robot's first refusal. This feed adds what a window
needs on top: each transfer under way is published (:class:`~rtmu.values.state.TransfersChanged`) as it
progresses, at most every :data:`PROGRESS_EVERY` s however fast packets come, so a 200 MB download costs
the UI thread a few dozen updates, not thousands.
"""

from __future__ import annotations

from collections.abc import Callable, Coroutine
from pathlib import Path
from typing import Any, ClassVar

from ..values.commission import Direction, Transfer, TransfersState
from ..values.intents import DeleteFile, DownloadFile, Intent, ListFiles, UploadFile
from ..values.state import TransfersChanged
from .download import Transfer as Done
from .download import download_file
from .feed import Feed, FeedContext
from .remote_files import Listing, delete_file, list_folder
from .upload import upload_file

PROGRESS_EVERY = 0.1
"""Seconds between two published progress updates of one transfer."""


class FilesFeed(Feed):
    """Carries out :class:`ListFiles`, :class:`DownloadFile`, :class:`UploadFile`, :class:`DeleteFile`."""

    handles: ClassVar[tuple[type[Intent], ...]] = (ListFiles, DownloadFile, UploadFile, DeleteFile)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._active: dict[int, Transfer] = {}
        self._next = 0

    def disconnected(self) -> None:
        self._active.clear()
        self._publish()

    def handle(self, intent: Intent) -> Coroutine[Any, Any, Listing | Done | None]:
        client = self.require()
        timeout = self.ctx.config.reply_timeout
        if isinstance(intent, ListFiles):
            return list_folder(client, intent.folder, timeout=timeout)
        if isinstance(intent, DeleteFile):
            return delete_file(client, intent.remote, timeout=timeout)
        if isinstance(intent, DownloadFile):
            local = Path(intent.local)
            return self._tracked(
                Transfer(Direction.DOWNLOAD, intent.remote, intent.local, total=intent.size),
                lambda progress: download_file(
                    client, intent.remote, local, overwrite=intent.overwrite, progress=progress,
                    timeout=timeout, size=intent.size,
                ),
            )  # fmt: skip
        assert isinstance(intent, UploadFile)
        size = _size_of(intent.local)
        return self._tracked(
            Transfer(Direction.UPLOAD, intent.remote, intent.local, total=size),
            lambda progress: upload_file(
                client, Path(intent.local), intent.remote, progress=progress, timeout=timeout
            ),
        )

    async def _tracked(
        self, start: Transfer, run: Callable[[Callable[[int, int | None], None]], Coroutine[Any, Any, Done]]
    ) -> Done:
        """Run one transfer, published while it lasts (at most every :data:`PROGRESS_EVERY` s)."""
        key = self._next
        self._next += 1
        self._active[key] = start
        self._publish()
        shown = [self.ctx.clock()]

        def progress(done: int, total: int | None) -> None:
            current = self._active.get(key)
            if current is None:
                return
            self._active[key] = Transfer(current.direction, current.remote, current.local, done, total)
            now = self.ctx.clock()
            if now - shown[0] >= PROGRESS_EVERY:
                shown[0] = now
                self._publish()

        try:
            return await run(progress)
        finally:
            self._active.pop(key, None)
            self._publish()

    def _publish(self) -> None:
        self.ctx.publish(TransfersChanged(TransfersState(tuple(self._active.values()))))


def _size_of(local: str) -> int | None:
    try:
        return Path(local).stat().st_size
    except OSError:
        return None  # upload_file says why, in its own words
