"""Steps applied to takes too large for memory: chunk by chunk, to the same bytes as whole.

A step is streamable when it registers a ``streamer`` (the smoothing filters
do: :class:`~motiontheater.filtering.Smoother`), and a pipeline is when it is
one such step over the whole take.  The AMC codec reads and writes the take a
piece at a time (:func:`~motiontheater.amc.open_amc`,
:func:`~motiontheater.amc.amc_writer`); this module only cuts the frames into
chunks with the halo of neighbours the step needs.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterator

import numpy as np

from .amc import READ_BYTES, AmcStream, amc_writer, open_amc
from .filtering import Smoother, TakeStats
from .pipeline import Pipeline
from .skeleton import Skeleton

CHUNK_FRAMES = 1 << 15  # frames per streamed chunk (a multiple of the filters' block length)


def streamable(pipeline: Pipeline) -> bool:
    """Whether the pipeline can be streamed: one streamable step over the whole take, no exporter."""
    if len(pipeline.entries) != 1:
        return False
    entry = pipeline.entries[0]
    return entry.step.streamer is not None and dict(entry.options).get("frames") is None


def stream(
    path: str | os.PathLike,
    target: str | os.PathLike,
    skeleton: Skeleton,
    pipeline: Pipeline,
    frame_rate: float | None = None,
    *,
    chunk_frames: int = CHUNK_FRAMES,
    read_bytes: int = READ_BYTES,
) -> int:
    """Apply a streamable pipeline to the AMC take at ``path``, writing ``target``; returns the frame count.

    Two passes over the file: the first gathers what the step needs of the
    whole take (channel ranges, first frame), the second unwraps, smooths and
    writes chunk by chunk, each with a halo of neighbouring frames and
    aligned to the filters' blocks, so that the bytes equal those of
    processing the take whole.
    """
    if not streamable(pipeline):
        raise ValueError("only a pipeline of one streamable step (median, mean, binomial) over all frames streams")
    entry = pipeline.entries[0]
    options = entry.step.bind(dict(entry.options))
    del options["frames"]
    options["workers"] = 1
    assert entry.step.streamer is not None
    smoother: Smoother = entry.step.streamer(skeleton, **options)
    take = open_amc(path, skeleton, frame_rate, read_bytes=read_bytes)
    stats, frames = None, 0
    for values in take.pieces():
        if stats is None:
            stats = TakeStats.of(values)
        else:
            stats.update(values)
        frames += len(values)
    block = smoother.block
    chunk = max(block, chunk_frames // block * block)
    lead = -(-smoother.halo // block) * block  # frames before a chunk: the halo, rounded up to a block
    with amc_writer(take.motion, target) as write:
        if stats is None:
            return 0
        unwrapped = _unwrapped_chunks(take, smoother, chunk)
        tail = np.zeros((0, len(skeleton.channels)))  # unwrapped frames before the current chunk
        current: np.ndarray | None = next(unwrapped)
        start = 0
        for following in itertools.chain(unwrapped, [None]):  # one chunk of lookahead, no more
            assert current is not None
            after = following[: smoother.halo] if following is not None else tail[:0]
            before = min(lead, start)
            buffer = np.concatenate([tail[len(tail) - before :], current, after])
            smoothed = smoother.smooth(buffer, stats)[before : before + len(current)]
            write(smoothed, take.motion.first_frame + start)
            tail = np.concatenate([tail, current])[-lead:] if lead else tail
            start += len(current)
            current = following
    return frames


def _unwrapped_chunks(take: AmcStream, smoother: Smoother, chunk: int) -> Iterator[np.ndarray]:
    """The take's frames, unwrapped, in chunks of exactly ``chunk`` frames (the last shorter)."""
    state, pending = None, []
    held = 0
    for values in take.pieces():
        unwrapped, state = smoother.unwrap(values, state)
        pending.append(unwrapped)
        held += len(unwrapped)
        while held >= chunk:
            joined = np.concatenate(pending)
            yield joined[:chunk]
            pending, held = [joined[chunk:]], held - chunk
    if held:
        yield np.concatenate(pending)
