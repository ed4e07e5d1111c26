"""One process-wide thread pool that splits a C call across cores.

cffi releases the GIL for the duration of every C call, so calls on disjoint
ranges of one array run truly in parallel.
"""

from __future__ import annotations

import itertools
import operator
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from ._status import check

R = TypeVar("R")

_pool: ThreadPoolExecutor | None = None
_lock = threading.Lock()
_share: int | None = None  # the cores of a process that divides them with others (share_cores)


def cpu_count() -> int:
    """Cores this process may run on (its affinity mask, where the OS has one), or its share of them."""
    return min(_cores(), _share) if _share else _cores()


def share_cores(processes: int) -> None:
    """This process is one of ``processes`` that divide the cores between them (a batch's
    workers): a call that splits over every core takes this process's share, as threads
    beyond it would only contend with the other processes."""
    global _share
    _share = max(1, _cores() // max(1, processes))


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def _get_pool() -> ThreadPoolExecutor:
    global _pool
    with _lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(max(1, cpu_count() - 1), thread_name_prefix="mtcore")
        return _pool


def _forget_pool() -> None:
    # A forked child inherits the pool object but none of its threads.
    global _pool
    _pool = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def run_all(tasks: Sequence[Callable[[], R]]) -> list[R]:
    """Run the tasks, the first in the calling thread and the rest in the pool; their results in order."""
    if len(tasks) == 1:
        return [tasks[0]()]
    pool = _get_pool()
    futures = [pool.submit(task) for task in tasks[1:]]
    first = tasks[0]()
    return [first, *(f.result() for f in futures)]


def thread_count(workers: int | None, large: bool) -> int:
    """Threads a call may use: ``workers`` threads, every core for -1, and for
    None every core when the job is ``large`` enough to gain, else one."""
    if workers is None:
        return cpu_count() if large else 1
    try:
        wanted = operator.index(workers)
    except TypeError:
        raise TypeError(f"workers must be an integer or None, got {type(workers).__name__}") from None
    if wanted == -1:
        return cpu_count()
    if wanted < 1:
        raise ValueError(f"workers must be a positive integer, -1 (every core) or None, got {wanted}")
    return wanted


def even_bounds(count: int, threads: int) -> list[int]:
    """Bounds cutting range(count) into at most ``threads`` near-equal ranges."""
    threads = max(1, min(threads, count))
    return [count * i // threads for i in range(threads + 1)]


def run_ranges(call: Callable[[int, int], int], bounds: Sequence[int], name: str) -> None:
    """Run the C function ``call(begin, end)`` over each range between bounds, in parallel, and check its status."""
    parts = [lambda b=b, e=e: call(b, e) for b, e in itertools.pairwise(bounds)]
    for status in run_all(parts):
        check(status, name)
