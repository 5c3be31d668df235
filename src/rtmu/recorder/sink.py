"""The file under a recording: counts its bytes (for the size cap) and keeps the first write error.

foxglove-sdk's MCAP writer writes through this object from the writer thread. A
failed write (a full disk, a yanked USB stick) raises as usual, so the MCAP writer
stops; the error is also kept here, so the recording can say why and stop cleanly.
"""

from __future__ import annotations

import os
from pathlib import Path


class CountingFile:
    """A binary file that remembers how much was written and the first ``OSError``."""

    def __init__(self, path: Path) -> None:
        self.path = path
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        self._file = os.fdopen(fd, "wb", buffering=0)  # foxglove-sdk buffers; a failure shows at once
        self.written = 0
        self.error: OSError | None = None

    def write(self, data: bytes | bytearray) -> int:
        try:
            n = self._file.write(data) or 0  # may be short (a disk filling up): the writer writes the rest
        except OSError as exc:
            self.error = self.error or exc
            raise
        self.written += n
        return n

    def seek(self, offset: int, whence: int = os.SEEK_SET) -> int:
        try:
            return self._file.seek(offset, whence)
        except OSError as exc:
            self.error = self.error or exc
            raise

    def tell(self) -> int:
        return self._file.tell()

    def flush(self) -> None:
        try:
            self._file.flush()
        except OSError as exc:
            self.error = self.error or exc
            raise

    def sync(self) -> None:
        """Flush and ``fsync``: what is written survives a power loss."""
        self.flush()
        try:
            os.fsync(self._file.fileno())
        except OSError as exc:
            self.error = self.error or exc
            raise

    def close(self) -> None:
        try:
            self._file.close()
        except OSError as exc:
            self.error = self.error or exc
