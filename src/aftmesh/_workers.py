"""The threads backend of ``generate_many`` / ``imap_many``.

Worker threads take the next domain themselves and queue each result, so the calling
thread only collects results: it holds the GIL for a few microseconds per domain,
which the workers' Python glue around the GIL-free kernel needs.  (A
``concurrent.futures`` pool spends about a hundred and fifty microseconds of the
calling thread's GIL time per small domain on submitting and waiting.)  When nobody
watches the results one by one (``generate_many`` without a progress callback), the
calling thread is woken once per batch of results, not once per domain: each wake-up
is a GIL hand-off that a worker waits through.
"""

from __future__ import annotations

import collections
import itertools
import queue
import threading
from collections.abc import Callable, Iterator
from typing import Any


class _Source:
    """The shared iterable of ``(index, domain, size)``, read under a lock; with a
    window, at most that many domains taken but not yet handed to the caller."""

    def __init__(self, items, window: int | None):
        self._items = iter(items)
        self._lock = threading.Lock()
        self._slots = None if window is None else threading.Semaphore(window)
        self.stopped = False

    def take(self):
        """The next item; None when there is none or the run was stopped.  Blocks
        while `window` results wait for the caller."""
        if self._slots is not None:
            self._slots.acquire()
        with self._lock:
            if self.stopped:
                return None
            try:
                return next(self._items)
            except StopIteration:
                self.stopped = True
                return None
            except BaseException:
                self.stopped = True  # the caller re-raises it; no one reads on
                raise

    def handed_out(self) -> None:
        if self._slots is not None:
            self._slots.release()

    def stop(self, workers: int) -> None:
        with self._lock:
            self.stopped = True
        if self._slots is not None:
            for _ in range(workers):  # wake workers waiting for a slot
                self._slots.release()


class _Results:
    """Finished results (a deque: append and popleft need no lock) and the wake-ups
    of the caller: one per `batch` results, and one when a worker stops (with the
    error it stopped on, if reading the domains raised)."""

    def __init__(self, batch: int):
        self.done: collections.deque = collections.deque()
        self.wake: queue.SimpleQueue = queue.SimpleQueue()
        self._batch = batch
        self._count = itertools.count(1)

    def put(self, item) -> None:
        self.done.append(item)
        if next(self._count) % self._batch == 0:
            self.wake.put(None)

    def worker_stopped(self, error: BaseException | None) -> None:
        self.wake.put((error,))


def _work(source: _Source, results: _Results, mesh_one: Callable, options: dict):
    error = None
    try:
        while (item := source.take()) is not None:
            i, domain, size = item
            results.put((i, mesh_one(i, domain, size, options)))
    except BaseException as err:  # noqa: BLE001  (raised again by the caller)
        error = err
    finally:
        results.worker_stopped(error)


def run_threads(
    items, options: dict, workers: int, mesh_one: Callable, window: int | None, batch: int = 1
) -> Iterator[tuple[int, Any]]:
    """``(index, result)`` as the `workers` threads finish them (handed over in
    batches of `batch`); `mesh_one(i, domain, size, options)` makes a result.
    Closing the generator stops the workers after the domains they are meshing."""
    source = _Source(items, window)
    # a worker blocked on a full window must have woken the caller: batches only
    # without one
    results = _Results(batch if window is None else 1)
    # daemon threads: every way out of this generator joins them, but one left
    # suspended until the interpreter exits would otherwise keep it from exiting
    # (its workers wait for window slots that nobody frees)
    threads = [
        threading.Thread(
            target=_work,
            args=(source, results, mesh_one, options),
            name=f"aftmesh_{k}",
            daemon=True,
        )
        for k in range(workers)
    ]
    for t in threads:
        t.start()
    running = workers
    try:
        while running:
            token = results.wake.get()
            if token is not None:  # a worker stopped
                running -= 1
                if token[0] is not None:
                    raise token[0]
            while results.done:
                item = results.done.popleft()
                source.handed_out()
                yield item
    finally:
        source.stop(workers)
        for t in threads:
            t.join()
