"""The threads backend of ``generate_many`` / ``imap_many``.

Worker threads take the next domain themselves and put each result on a queue, so
the calling thread only collects results: it holds the GIL for a few microseconds per
domain, which the workers' Python glue around the GIL-free kernel needs.  (A
``concurrent.futures`` pool spends about a hundred and fifty microseconds of the
calling thread's GIL time per small domain on submitting and waiting.)
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Iterator
from typing import Any


class _Source:
    """The shared iterable of ``(index, domain, size)``, read under a lock, with a
    bounded number of domains taken but not yet handed to the caller."""

    def __init__(self, items, window: int):
        self._items = iter(items)
        self._lock = threading.Lock()
        self._slots = threading.Semaphore(window)
        self.stopped = False

    def take(self):
        """The next item; None when there is none or the run was stopped.  Blocks
        while `window` results wait for the caller."""
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
        self._slots.release()

    def stop(self, workers: int) -> None:
        with self._lock:
            self.stopped = True
        for _ in range(workers):  # wake workers waiting for a slot
            self._slots.release()


# what a worker puts on the queue when it stops: (_DONE, None), or (_DONE, error)
# when reading the domains raised
_DONE = -1


def _work(source: _Source, results: queue.SimpleQueue, mesh_one: Callable, options: dict):
    error = None
    try:
        while (item := source.take()) is not None:
            i, domain, size = item
            results.put((i, mesh_one(i, domain, size, options)))
    except BaseException as err:  # noqa: BLE001  (raised again by the caller)
        error = err
    finally:
        results.put((_DONE, error))


def run_threads(
    items, options: dict, workers: int, window: int, mesh_one: Callable
) -> Iterator[tuple[int, Any]]:
    """``(index, result)`` as the `workers` threads finish them; `mesh_one(i, domain,
    size, options)` makes a result.  Closing the generator stops the workers after
    the domains they are meshing."""
    source = _Source(items, window)
    results: queue.SimpleQueue = queue.SimpleQueue()
    threads = [
        threading.Thread(
            target=_work, args=(source, results, mesh_one, options), name=f"aftmesh_{k}"
        )
        for k in range(workers)
    ]
    for t in threads:
        t.start()
    running = workers
    try:
        while running:
            index, result = results.get()
            if index == _DONE:
                running -= 1
                if result is not None:
                    raise result
                continue
            source.handed_out()
            yield index, result
    finally:
        source.stop(workers)
        for t in threads:
            t.join()
