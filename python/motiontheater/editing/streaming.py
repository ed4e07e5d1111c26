"""Steps applied to takes too large for memory: chunk by chunk, to the same bytes as whole.

A step is streamable when it registers a ``streamer`` that builds a
:class:`~motiontheater.model.registry.Streamer` (the protocol says what each part does; the
smoothing filters' is :class:`~motiontheater.editing.filtering.Smoother`), and a pipeline is
when it is one such step over the whole take.  The AMC codec reads and writes the take a
piece at a time (:func:`~motiontheater.formats.amc.open_amc`,
:func:`~motiontheater.formats.amc.amc_writer`); this module only drives the passes and cuts
the frames into chunks with the halo of neighbours the step needs.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterator

import numpy as np

from ..formats.amc import READ_BYTES, AmcStream, amc_writer, open_amc
from ..model.registry import Streamer
from ..model.skeleton import Skeleton
from .pipeline import Pipeline

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

    Two passes over the file: the first surveys the whole take (what the step
    needs of it), the second prepares, processes and writes chunk by chunk,
    each with a halo of neighbouring frames and aligned to the step's blocks,
    so that the bytes equal those of processing the take whole.
    """
    if not streamable(pipeline):
        raise ValueError("only a pipeline of one streamable step (median, mean, binomial, ...) over all frames streams")
    entry = pipeline.entries[0]
    options = entry.step.bind(dict(entry.options))
    del options["frames"]
    if "workers" in options:
        options["workers"] = 1  # the stream is one take of a batch, whose processes share the cores
    assert entry.step.streamer is not None
    streamer = entry.step.streamer(skeleton, **options)
    take = open_amc(path, skeleton, frame_rate, read_bytes=read_bytes)
    summary, frames = None, 0
    for values in take.pieces():
        summary = streamer.survey(values, summary)
        frames += len(values)
    block = streamer.block
    chunk = max(block, chunk_frames // block * block)
    lead = -(-streamer.halo // block) * block  # frames before a chunk: the halo, rounded up to a block
    with amc_writer(take.motion, target) as write:
        if not frames:
            return 0
        prepared = _prepared_chunks(take, streamer, chunk)
        tail = np.zeros((0, len(skeleton.channels)))  # prepared frames before the current chunk
        current: np.ndarray | None = next(prepared)
        start = 0
        for following in itertools.chain(prepared, [None]):  # one chunk of lookahead, no more
            assert current is not None
            after = following[: streamer.halo] if following is not None else tail[:0]
            before = min(lead, start)
            buffer = np.concatenate([tail[len(tail) - before :], current, after])
            result = streamer.process(buffer, summary)[before : before + len(current)]
            write(result, take.motion.first_frame + start)
            tail = np.concatenate([tail, current])[-lead:] if lead else tail
            start += len(current)
            current = following
    return frames


def _prepared_chunks(take: AmcStream, streamer: Streamer, chunk: int) -> Iterator[np.ndarray]:
    """The take's frames, prepared, in chunks of exactly ``chunk`` frames (the last shorter)."""
    state, pending = None, []
    held = 0
    for values in take.pieces():
        prepared, state = streamer.prepare(values, state)
        pending.append(prepared)
        held += len(prepared)
        while held >= chunk:
            joined = np.concatenate(pending)
            yield joined[:chunk]
            pending, held = [joined[chunk:]], held - chunk
    if held:
        yield np.concatenate(pending)
