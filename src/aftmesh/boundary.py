"""Discretize the input edges according to the size field.

The paper's Basic_aft takes the boundary as already discretized (its input edges stay
unmodified in the mesh); this module does that discretization: each input segment is
cut into n pieces, n being the rounded integral of 1/h along it, with the cut points
spaced so that every piece holds an equal share of that integral (shorter pieces where
the size is smaller).  Segments shorter than the local size are kept whole.
"""

from __future__ import annotations

import numpy as np

from ._kernel import discretize_boundary, discretize_segments
from .errors import InvalidSizeError
from .sizing import SizeField

# At most this many points per segment at which the size is read to integrate 1/h
# (cython_ext/discretize.pxi takes fewer on segments short against the size there):
# the field is graded, so 31 intervals follow it closely along any one input edge.
MAX_SAMPLES = 32


def discretize(
    vertices: np.ndarray,
    segments: np.ndarray,
    source: np.ndarray,
    field: SizeField,
    max_pieces: int | None = None,
    limit: str = "",
    clear: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return (vertices, segments, source) with long segments split by the size.

    Raises InvalidSizeError, before allocating anything, if the boundary alone would
    need more than `max_pieces` edges (each is a side of a triangle of the mesh).

    With `clear` > 0, split points are left out where rounding could change the
    PSLG's topology: a split point within that distance of another segment (it may
    land on that segment or beyond it: the sides of a needle, a line grazing an edge),
    and the ends of a piece that would put a vertex lying that near the segment on the
    other side of it, or on it.  Leaving points out only makes a piece longer than the
    size asks for."""
    if len(segments) == 0:
        return vertices, segments, source
    if not clear > 0:
        out = discretize_boundary(
            *field.kernel_args(),
            np.ascontiguousarray(vertices, dtype=np.float64),
            np.ascontiguousarray(segments, dtype=np.int32),
            np.ascontiguousarray(source, dtype=np.int32),
            MAX_SAMPLES,
            np.inf if max_pieces is None else float(max_pieces),
        )
        if out[1] is None:
            _refuse(out[0], limit)
        return out
    pieces, pts, row = discretize_segments(
        *field.kernel_args(),
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(segments, dtype=np.int32),
        MAX_SAMPLES,
        np.inf if max_pieces is None else float(max_pieces),
    )
    if pts is None:
        _refuse(pieces, limit)
    a = vertices[segments[:, 0]]
    b = vertices[segments[:, 1]]
    split = np.flatnonzero(pieces > 1)
    counts = pieces[split] - 1  # split points of each split segment
    if clear > 0 and len(split):
        points = np.split(pts, np.cumsum(counts)[:-1])
        points = _clear_of_others(points, split, a, b, clear)
        points = _keep_sides(points, split, vertices, segments, clear)
        counts = np.array([len(p) for p in points], dtype=np.int64)
        row = np.repeat(split, counts)
        pts = np.concatenate(points) if len(points) else pts
    return _chains(vertices, segments, source, pieces == 1, split, row, counts, pts, a, b)


def _refuse(total: float, limit: str):
    raise InvalidSizeError(
        f"{limit} is below what the boundary alone needs: about {total:.3g} edges at "
        "this size (each a side of a different triangle but for a few)"
    )


def _chains(vertices, segments, source, simple, split, row, counts, pts, a, b):
    """The new (vertices, segments, source): the unsplit segments first, then each
    split segment as the chain through its split points, in order."""
    # rounded points never coincide at the sizes make_size_field accepts, but a
    # piece of zero length would be fatal: drop any that do
    first = np.zeros(len(row), dtype=bool)
    starts = np.cumsum(counts) - counts
    first[starts[counts > 0]] = True
    prev = np.where(first[:, None], a[row], np.roll(pts, 1, axis=0))
    distinct = (pts != prev).any(axis=1) & (pts != b[row]).any(axis=1)
    if not distinct.all():
        pts, row = pts[distinct], row[distinct]
        counts = np.bincount(np.searchsorted(split, row), minlength=len(split))
    # each chain: the segment's start, its split points, its end
    size = counts + 2
    chain = np.empty(int(size.sum()), dtype=np.int64)
    begin = np.cumsum(size) - size
    chain[begin] = segments[split, 0]
    chain[begin + size - 1] = segments[split, 1]
    inner = np.ones(len(chain), dtype=bool)
    inner[begin] = False
    inner[begin + size - 1] = False
    chain[inner] = len(vertices) + np.arange(len(pts))
    link = np.ones(len(chain) - 1, dtype=bool) if len(chain) else np.zeros(0, dtype=bool)
    link[(begin + size - 1)[:-1]] = False  # no piece from one chain's end to the next
    body = np.flatnonzero(link)
    return (
        np.concatenate([vertices, pts]),
        np.concatenate([segments[simple], np.c_[chain[body], chain[body + 1]]]).astype(np.int32),
        np.concatenate([source[simple], np.repeat(source[split], counts + 1)]).astype(np.int32),
    )


def _clear_of_others(points, split, a, b, clear):
    """Drop from points[i] (the split points of segment split[i]) those within
    `clear` of any other segment."""
    import shapely

    lines = shapely.linestrings(np.stack([a, b], axis=1))
    allp = np.concatenate(points)
    parent = np.repeat(split, [len(p) for p in points])
    pi, si = shapely.STRtree(lines).query(shapely.points(allp), predicate="dwithin", distance=clear)
    keep = np.ones(len(allp), dtype=bool)
    keep[pi[si != parent[pi]]] = False
    out = []
    start = 0
    for p in points:
        out.append(p[keep[start : start + len(p)]])
        start += len(p)
    return out


def _keep_sides(points, split, vertices, segments, clear):
    """Leave out split points until every input vertex within `clear` of a split
    segment is on the same side of each nearby piece as of the segment (decided by
    the exact orientation predicate; the segment itself, unsplit, always qualifies)."""
    import shapely

    from ._kernel import py_orient2d

    a = vertices[segments[split, 0]]
    b = vertices[segments[split, 1]]
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    vi, li = shapely.STRtree(lines).query(
        shapely.points(vertices), predicate="dwithin", distance=clear
    )
    out = list(points)
    for v, i in zip(vi.tolist(), li.tolist()):
        k = int(split[i])
        if v in (segments[k, 0], segments[k, 1]):
            continue
        pv = vertices[v]
        side = py_orient2d(a[i, 0], a[i, 1], b[i, 0], b[i, 1], pv[0], pv[1])
        if side == 0:
            continue  # on the segment: the CDT splits it there, as it would unsplit
        pts = out[i]  # lines[i] is segment split[i], whose points are points[i]
        changed = True
        while changed and len(pts):
            changed = False
            chain = np.vstack([a[i], pts, b[i]])
            for j in range(len(chain) - 1):
                p, q = chain[j], chain[j + 1]
                if _distance(pv, p, q) > 2 * clear:
                    continue
                if py_orient2d(p[0], p[1], q[0], q[1], pv[0], pv[1]) != side:
                    # drop the piece's split-point ends (chain[0] and chain[-1] are the
                    # segment's own ends) and look again
                    drop = [m - 1 for m in (j, j + 1) if 0 < m < len(chain) - 1]
                    pts = np.delete(pts, drop, axis=0)
                    changed = True
                    break
        out[i] = pts
    return out


def _distance(p, a, b) -> float:
    """Distance from point p to segment a-b (floating point, for a proximity test)."""
    d = b - a
    L2 = float(np.dot(d, d))
    t = 0.0 if L2 == 0 else min(1.0, max(0.0, float(np.dot(p - a, d)) / L2))
    return float(np.hypot(*(a + t * d - p)))
