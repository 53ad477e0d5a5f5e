"""``aftmesh.generate_many``: many domains meshed in parallel, on threads or on Dask.

The compiled kernel releases the GIL while it meshes, so a thread pool in this process
meshes ``workers`` domains at once without copying them anywhere.  With a
``dask.distributed`` client, each domain (or a batch of them) is a task: the domain and
its size travel to a worker, the finished :class:`~aftmesh.Mesh` travels back.

One domain's failure never hides which one it was: with ``errors="raise"`` the first
failure is raised again as the same exception type with ``domain i:`` in front of its
message (and ``index`` set on it); with ``errors="collect"`` it is returned in its slot
as a :class:`MeshingFailure` while the other domains still mesh.
"""

from __future__ import annotations

import copy
import itertools
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ._typing import SizeArg
from ._workers import run_threads
from .errors import InvalidOptionError
from .mesh import Mesh

if TYPE_CHECKING:
    from distributed import Client

__all__ = ["MeshingFailure", "generate_many", "imap_many"]

# the Mesh arrays a pickled Mesh brings back writable (Mesh's own are read-only)
_ARRAYS = (
    "points",
    "triangles",
    "neighbors",
    "segments",
    "regions",
    "segment_markers",
    "segment_sources",
    "segment_tags",
)

_SCHEDULERS = ("threads", "dask", "serial")
_ERRORS = ("raise", "collect")
# Domains taken per worker but not yet handed to the caller (threads), or tasks kept in
# flight per worker (Dask): enough that no worker waits for the driver, few enough
# that a lazy iterable of domains is not read far ahead.
IN_FLIGHT_PER_WORKER = 4
# Without chunksize=, the domains are cut into this many Dask tasks per worker thread
# when their number is known: enough for the workers to even out domains of unequal
# cost, few enough that scheduling is small against meshing (measured on 2 workers:
# 1,000 domains of ~1.5 ms took 11 s one per task, 8 ms of the caller's CPU per task
# with the scheduler of a LocalCluster in its process, and 1.3-1.6 s in batches of
# 32-125).
AUTO_TASKS_PER_WORKER = 8
# ... and at most this many domains per task (the results of one task travel back as
# one message; a million small domains still make several thousand tasks) ...
AUTO_MAX_CHUNK = 256
# ... and this many when the domains come from an iterable without a length.
AUTO_UNKNOWN_CHUNK = 8
# generate_many without a progress callback wakes the calling thread once per this
# many finished domains (each wake-up takes the GIL from a worker); a failing domain
# is then raised at most this many domains late.
RESULTS_PER_WAKE = 32


@dataclass(frozen=True)
class MeshingFailure:
    """The slot of a domain that could not be meshed (``errors="collect"``).

    Attributes
    ----------
    index : int
        Position of the domain in the input (0-based, in iteration order).
    error : BaseException
        The exception ``aftmesh.generate`` raised for it.
    """

    index: int
    error: BaseException

    def __bool__(self) -> bool:  # `if result:` skips failures
        return False

    def __repr__(self) -> str:
        return (
            f"MeshingFailure(index={self.index}, error={type(self.error).__name__}: {self.error})"
        )


# ---------------------------------------------------------------- the per-domain task
def _mesh_one(index: int, domain, size, options: dict):
    """Mesh one domain; a failure comes back as a value, so that it travels from a
    Dask worker like a result and the driver decides whether to raise it."""
    from .generate import generate

    try:
        return generate(domain, size, **options)
    except Exception as err:  # noqa: BLE001  (every failure is reported)
        return MeshingFailure(index, err)


def _mesh_batch(items: list, options: dict) -> list:
    """One Dask task: several (index, domain, size) at once (less scheduler traffic)."""
    return [(i, _mesh_one(i, d, s, options)) for i, d, s in items]


def _with_index(failure: MeshingFailure) -> BaseException:
    """The failure's exception, same type, its message prefixed with the domain index."""
    err = failure.error
    try:
        new = copy.copy(err)
        new.args = (f"domain {failure.index}: {err.args[0] if err.args else err}", *err.args[1:])
    except Exception:  # noqa: BLE001  (an exotic exception type)
        new = err
        if hasattr(new, "add_note"):  # Python >= 3.11
            new.add_note(f"raised by domain {failure.index}")
    setattr(new, "index", failure.index)  # noqa: B010  (not a declared attribute)
    return new


# ---------------------------------------------------------------- inputs
def _domain_sequence(domains):
    """The geometries of a GeoDataFrame (its active geometry column), a GeoSeries, or
    any iterable, duck-typed so that geopandas is never imported here."""
    if hasattr(domains, "geometry") and hasattr(domains, "columns"):
        domains = domains.geometry
    return domains


def _is_scalar_size(size) -> bool:
    if size is None or callable(size) or isinstance(size, (int, float, np.number)):
        return True
    return isinstance(size, np.ndarray) and size.ndim == 0


def _pairs(domains, size) -> Iterator[tuple[int, Any, Any]]:
    """(index, domain, size) for each domain; a sequence of sizes must match."""
    if isinstance(size, str) and hasattr(domains, "columns"):
        if size not in domains.columns:
            raise InvalidOptionError(f"size={size!r} is not a column of the domains")
        size = domains[size]
    domains = _domain_sequence(domains)
    if _is_scalar_size(size):
        return ((i, d, size) for i, d in enumerate(domains))
    if isinstance(size, (str, bytes)):
        raise InvalidOptionError(f"size={size!r} is not a size or a column of the domains")
    domains = list(domains)
    sizes = list(size)
    if len(sizes) != len(domains):
        raise InvalidOptionError(
            f"size has {len(sizes)} entries for {len(domains)} domains: give one size for "
            "all or one per domain"
        )
    return ((i, d, s) for i, (d, s) in enumerate(zip(domains, sizes)))


def _check(scheduler, errors, workers, chunksize, client):
    if scheduler not in _SCHEDULERS:
        raise InvalidOptionError(
            f"scheduler={scheduler!r} is not a valid option, must be one of {list(_SCHEDULERS)}"
        )
    if errors not in _ERRORS:
        raise InvalidOptionError(
            f"errors={errors!r} is not a valid option, must be one of {list(_ERRORS)}"
        )
    for name, value in (("workers", workers), ("chunksize", chunksize)):
        if value is not None and (
            isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1
        ):
            raise InvalidOptionError(f"{name} must be a positive integer, got {value!r}")
    if client is not None and scheduler == "serial":
        raise InvalidOptionError("client= needs scheduler='dask' (or the default)")


def dask_client(client: Client | None = None) -> Client:
    """The given client, or the active ``dask.distributed`` client, or a clear error."""
    if client is not None:
        return client
    try:
        from distributed import get_client
    except ImportError:
        raise InvalidOptionError(
            "scheduler='dask' needs dask.distributed: pip install aftmesh[dask]"
        ) from None
    try:
        return get_client()
    except ValueError:
        raise InvalidOptionError(
            "scheduler='dask' found no active dask.distributed Client: start one "
            "(distributed.Client(...)) or pass client="
        ) from None


# ---------------------------------------------------------------- backends
def _serial(items, options, chunksize) -> Iterator[tuple[int, Any]]:
    for i, d, s in items:
        yield i, _mesh_one(i, d, s, options)


def _threads(items, options, workers, batched) -> Iterator[tuple[int, Any]]:
    """Worker threads that take the domains themselves: a bounded window ahead, or,
    `batched` (all results wanted at once), unbounded with results handed over in
    batches."""
    if batched:
        return run_threads(items, options, workers, _mesh_one, None, RESULTS_PER_WAKE)
    return run_threads(items, options, workers, _mesh_one, workers * IN_FLIGHT_PER_WORKER)


def auto_chunksize(total: int | None, n_threads: int) -> int:
    """Domains per Dask task when chunksize= is not given: `total` domains (None: not
    known) spread over about AUTO_TASKS_PER_WORKER tasks per worker thread.

    >>> auto_chunksize(1000, 2), auto_chunksize(10, 2), auto_chunksize(None, 2)
    (62, 1, 8)
    """
    if total is None:
        return AUTO_UNKNOWN_CHUNK
    return max(1, min(AUTO_MAX_CHUNK, total // (max(1, n_threads) * AUTO_TASKS_PER_WORKER)))


def _batches(items, chunksize):
    batch = []
    for item in items:
        batch.append(item)
        if len(batch) == chunksize:
            yield batch
            batch = []
    if batch:
        yield batch


def _dask(items, options, client, chunksize, total) -> Iterator[tuple[int, Any]]:
    """Batches of domains as Dask tasks, a bounded window of them in flight; without
    a chunksize, batches of auto_chunksize's size."""
    from distributed import as_completed

    workers = client.scheduler_info().get("workers", {})
    n_workers = max(1, len(workers))
    if not chunksize:
        chunksize = auto_chunksize(total, sum(w.get("nthreads", 1) for w in workers.values()))
    batches = _batches(items, chunksize)
    pending = {
        client.submit(_mesh_batch, b, options, pure=False)
        for b in itertools.islice(batches, n_workers * IN_FLIGHT_PER_WORKER)
    }
    queue = as_completed(list(pending), loop=client.loop)
    try:
        for fut in queue:
            pending.discard(fut)
            results = fut.result()
            for b in batches:
                nxt = client.submit(_mesh_batch, b, options, pure=False)
                pending.add(nxt)
                queue.add(nxt)
                break
            yield from results
    finally:
        for fut in pending:
            fut.cancel()


def _refreeze(result):
    """A Mesh unpickled from a worker has writeable arrays: freeze them again."""
    if isinstance(result, Mesh):
        for name in _ARRAYS:
            arr = getattr(result, name)
            if arr is not None and arr.flags.writeable:
                arr.setflags(write=False)
    return result


# ---------------------------------------------------------------- public API
def imap_many(
    domains: Iterable,
    size: SizeArg = None,
    *,
    workers: int | None = None,
    scheduler: str = "threads",
    client: Client | None = None,
    errors: str = "raise",
    progress: Callable[[int, int | None], None] | None = None,
    chunksize: int | None = None,
    **options,
) -> Iterator[tuple[int, Mesh | MeshingFailure]]:
    """Mesh many domains in parallel, yielding ``(index, mesh)`` as each one finishes.

    The lazy form of :func:`generate_many` (same parameters): results come in the
    order they complete, not the input order, and the domains are read from the
    iterable only a few per worker ahead, so a long generator of domains is never held
    in memory at once.  Closing the iterator early cancels the domains not started.

    Examples
    --------
    >>> import aftmesh
    >>> from shapely.geometry import box
    >>> squares = (box(i, 0, i + 1, 1) for i in range(3))
    >>> sorted(i for i, mesh in aftmesh.imap_many(squares, size=0.5, workers=2))
    [0, 1, 2]
    """
    run = (scheduler, workers, client, chunksize, options)
    return _imap(domains, size, run, errors, progress, batched=False)


def _imap(domains, size, run, errors, progress, batched):
    """imap_many's stream; `batched`: the caller wants all results at once (see
    _threads)."""
    scheduler, workers, client, chunksize, options = run
    if client is not None and scheduler == "threads":
        scheduler = "dask"
    _check(scheduler, errors, workers, chunksize, client)
    total = _length(domains)
    items = _pairs(domains, size)
    if scheduler == "dask":
        client = dask_client(client)
    run = (scheduler, workers, client, chunksize, options)
    return _results(items, total, run, errors, progress, batched)


def _results(items, total, run, errors, progress, batched):
    scheduler, workers, client, chunksize, options = run
    if scheduler == "serial":
        stream = _serial(items, options, chunksize)
    elif scheduler == "threads":
        stream = _threads(items, options, workers or os.cpu_count() or 1, batched)
    else:
        stream = _dask(items, options, client, chunksize, total)
    for done, (index, result) in enumerate(stream, start=1):
        if isinstance(result, MeshingFailure) and errors == "raise":
            stream.close()
            raise _with_index(result) from result.error
        if progress is not None:
            progress(done, total)
        # only a Mesh unpickled from a Dask worker has writeable arrays
        yield index, _refreeze(result) if scheduler == "dask" else result


def _length(domains) -> int | None:
    domains = _domain_sequence(domains)
    try:
        return len(domains)
    except TypeError:
        return None


def generate_many(
    domains: Iterable,
    size: SizeArg = None,
    *,
    workers: int | None = None,
    scheduler: str = "threads",
    client: Client | None = None,
    errors: str = "raise",
    progress: Callable[[int, int | None], None] | None = None,
    chunksize: int | None = None,
    **options,
) -> list:
    """Mesh many domains in parallel: ``[aftmesh.generate(d, s, **options), ...]``.

    Parameters
    ----------
    domains : iterable, GeoSeries or GeoDataFrame
        Domains in any form :func:`aftmesh.generate` accepts; a GeoDataFrame
        contributes its geometry column.
    size : float, callable, None, sequence or column
        One size for every domain, or one per domain (a sequence, array or Series of
        the same length as ``domains``; with a GeoDataFrame, also a column name).  A
        per-region size list for each domain is a sequence of such lists.
    workers : int, optional
        Threads (default: the number of cores).  Ignored by the other schedulers.
    scheduler : {'threads', 'dask', 'serial'}
        Threads in this process (the kernel releases the GIL), Dask tasks on a
        ``dask.distributed`` cluster, or one after the other.
    client : distributed.Client, optional
        The Dask client to use; giving one selects ``scheduler='dask'``.  Without it,
        ``scheduler='dask'`` uses the active client.
    errors : {'raise', 'collect'}
        On a domain that cannot be meshed: raise its exception again, same type, with
        ``domain i:`` in its message and ``.index = i`` (the other domains are
        cancelled); or put a :class:`MeshingFailure` in its slot and go on.
    progress : callable, optional
        ``progress(done, total)`` after each finished domain (``total`` is None for an
        iterable without a length).  Called in the calling thread.
    chunksize : int, optional
        Domains per Dask task.  By default about eight tasks per worker thread
        when the number of domains is known (at most 256 domains a task), 8 domains
        a task for an iterable without a length: batches of small domains save
        scheduler round trips, and enough tasks remain to share the work evenly.
    **options
        Keyword options of :func:`aftmesh.generate`, the same for every domain.

    Returns
    -------
    list
        One :class:`~aftmesh.Mesh` (or :class:`MeshingFailure`) per domain, in input
        order.  For results as they finish, see :func:`imap_many`.

    Raises
    ------
    InvalidOptionError
        A bad option, sizes not matching the domains, no Dask client.
    ValueError subclass
        The first domain that fails, with ``errors='raise'``.

    Examples
    --------
    >>> import aftmesh
    >>> from shapely.geometry import Point, box
    >>> domains = [box(0, 0, 1, 1), Point(0, 0).buffer(1.0), box(0, 0, 2, 1)]
    >>> meshes = aftmesh.generate_many(domains, size=[0.2, 0.3, 0.25], workers=2)
    >>> [round(m.area(), 6) for m in meshes][::2]
    [1.0, 2.0]
    >>> bad = [box(0, 0, 1, 1), [(0, 0), (1, 1), (1, 0), (0, 1)]]
    >>> out = aftmesh.generate_many(bad, size=0.5, errors="collect")
    >>> out[1].index, isinstance(out[1].error, aftmesh.InvalidDomainError)
    (1, True)
    """
    run = (scheduler, workers, client, chunksize, options)
    out: dict[int, Any] = dict(_imap(domains, size, run, errors, progress, progress is None))
    return [out[i] for i in range(len(out))]
