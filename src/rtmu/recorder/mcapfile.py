"""One MCAP file written with foxglove-sdk: a context of its own, channels made on first use.

Each recording gets its own :class:`foxglove.Context`, so two robots recorded at once
never share a channel or a file. Chunks are zstd-compressed and closed by every
:meth:`McapFile.flush`, so a process killed mid-session leaves a file whose complete
chunks read back (``mcap``'s non-seeking reader) up to the last flush.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import foxglove
from foxglove import Channel, Context, Schema
from foxglove.channels import (
    CompressedImageChannel,
    FrameTransformChannel,
    PointCloudChannel,
    PoseInFrameChannel,
    SceneUpdateChannel,
)
from foxglove.mcap import MCAPCompression, MCAPWriteOptions

from ..capture.recorded import RAW_ENCODING, RAW_SCHEMA, RAW_TOPICS
from . import schemas, topics
from .sink import CountingFile

CHUNK_SIZE = 512 * 1024
"""Target uncompressed chunk size; a flush (every second) usually ends a chunk sooner."""
PROFILE = "rtmu"
TYPED: dict[str, Any] = {
    topics.POSE: PoseInFrameChannel,
    topics.TF: FrameTransformChannel,
    topics.SONAR: PointCloudChannel,
    topics.LASER: PointCloudChannel,
    topics.CAMERA: CompressedImageChannel,
    topics.MAP: SceneUpdateChannel,
    topics.MAP_POINTS: PointCloudChannel,
}
"""Topic → the Foxglove channel class of its schema; every other decoded topic is JSON."""


def json_channel(topic: str, context: Context) -> Channel:
    """A JSON channel with its named schema (:mod:`.schemas`: ``rtmu.Status`` …)."""
    name, data = schemas.schema_name(topic), schemas.schema_data(topic)
    schema = Schema(name=name, encoding=schemas.ENCODING, data=data)
    return Channel(topic, schema=schema, message_encoding="json", context=context)


class McapFile:
    """Writer-thread only. ``log`` raises ``RuntimeError`` once the file has failed."""

    def __init__(self, path: Path, metadata: dict[str, str]) -> None:
        self.path = path
        self.file = CountingFile(path)
        self.context = Context()
        options = MCAPWriteOptions(
            compression=MCAPCompression.Zstd, chunk_size=CHUNK_SIZE, profile=PROFILE, compression_threads=0
        )
        self.writer = foxglove.open_mcap(self.file, context=self.context, writer_options=options)
        self.writer.write_metadata("rtmu", metadata)
        self._channels: dict[str, Any] = {}
        schema = Schema(name=RAW_SCHEMA, encoding="", data=b"")
        for direction, topic in RAW_TOPICS.items():
            self._channels[topic] = Channel(
                topic,
                message_encoding=RAW_ENCODING,
                schema=schema,
                context=self.context,
                metadata={"direction": direction},
            )

    @property
    def written(self) -> int:
        return self.file.written

    def log(self, topic: str, message: Any, at_ns: int) -> None:
        channel = self._channels.get(topic)
        if channel is None:
            kind = TYPED.get(topic)
            channel = kind(topic, context=self.context) if kind else json_channel(topic, self.context)
            self._channels[topic] = channel
        channel.log(message, log_time=at_ns)

    def flush(self, sync: bool = False) -> None:
        """End the current chunk and hand it to the OS (``sync``: and to the disk)."""
        self.writer.flush()
        if sync:
            self.file.sync()

    def close(self) -> None:
        """Write the summary and close; a failed file is closed as far as it goes."""
        try:
            self.writer.close()
        finally:
            self.file.close()
