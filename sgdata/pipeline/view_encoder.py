"""A room's views encoded on a background thread while the next view renders.

PNG and JPEG encoding (zlib, libjpeg) and the renderer's draw both release the GIL, so one
encoding thread overlaps the two: a worker with a spare core hides the encode time. Each view
is encoded by itself, in order, with the same encoder as :func:`sgdata.dataset.rows.
observation_table`, so the bytes are those of encoding after the room. Only a view's encoded
bytes are kept once it is encoded, not its pixel arrays, so a room's memory does not grow with
its images. A worker hands every room the same one-thread pool (:func:`encoding_pool`), so its
threads do not grow with the rooms it renders.
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor, wait
from dataclasses import replace
from types import TracebackType

import pyarrow as pa

from sgdata.annotate.records import ViewRecord
from sgdata.dataset.rows import EncodedImages, encode_view, observation_table

__all__ = ["ViewEncoder", "encoding_pool"]


def encoding_pool() -> ThreadPoolExecutor:
    """A pool of the one thread views are encoded on (a worker keeps one for all its rooms)."""
    return ThreadPoolExecutor(max_workers=1, thread_name_prefix="sgdata-encode")


class ViewEncoder:
    """Collects a room's views, encoding each on one background thread as it is added.

    Use as a context manager: leaving it drops the views not yet encoded (when an error
    leaves it early) and waits for the one being encoded; it stops the thread too unless the
    ``pool`` was handed in (:func:`encoding_pool`, kept by its owner).
    """

    def __init__(
        self,
        image_format: str = "png",
        *,
        jpeg_quality: int = 92,
        pool: ThreadPoolExecutor | None = None,
    ) -> None:
        self.image_format, self.jpeg_quality = image_format, jpeg_quality
        self._owned = pool is None
        self._pool = encoding_pool() if pool is None else pool
        self._records: list[ViewRecord] = []
        self._encoded: list[Future[EncodedImages]] = []

    def __len__(self) -> int:
        return len(self._records)

    def __enter__(self) -> ViewEncoder:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        for future in self._encoded:
            future.cancel()
        wait(self._encoded)
        if self._owned:
            self._pool.shutdown(wait=True)

    def add(self, record: ViewRecord) -> None:
        """Queue ``record``'s images for encoding; keep the record without its pixels."""
        self._encoded.append(
            self._pool.submit(
                encode_view, record, self.image_format, jpeg_quality=self.jpeg_quality
            )
        )
        self._records.append(replace(record, rgb=None, depth=None, instances=None, structure=None))

    def table(
        self, *, room_type: str, split: str, scene_paths: list[str], class_ids: dict[str, int]
    ) -> pa.Table:
        """The rows of every view added, in order, once each is encoded (the arguments are
        :func:`~sgdata.dataset.rows.observation_table`'s).

        Raises:
            DatasetError: a view's encoding failed, or the rows are inconsistent.
        """
        return observation_table(
            self._records,
            room_type=room_type,
            split=split,
            scene_paths=scene_paths,
            class_ids=class_ids,
            image_format=self.image_format,
            jpeg_quality=self.jpeg_quality,
            encoded=[future.result() for future in self._encoded],
        )
