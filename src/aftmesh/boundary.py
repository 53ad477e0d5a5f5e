"""Discretize the input edges according to the size field.

The paper's Basic_aft takes the boundary as already discretized (its input edges stay
unmodified in the mesh); this module does that discretization: each input segment is
cut into n pieces, n being the rounded integral of 1/h along it, with the cut points
spaced so that every piece holds an equal share of that integral (shorter pieces where
the size is smaller).  Segments shorter than the local size are kept whole.
"""
from __future__ import annotations

import numpy as np

from .sizing import SizeField

_SAMPLES = 32  # points per segment at which the size is read to integrate 1/h


def discretize(vertices: np.ndarray, segments: np.ndarray, source: np.ndarray,
               field: SizeField, max_pieces: int | None = None, limit: str = "",
               clear: float = 0.0):
    """Return (vertices, segments, source) with long segments split by the size.

    Raises InvalidSizeError, before allocating anything, if the boundary alone would
    need more than `max_pieces` edges (each is a side of a triangle of the mesh).

    With `clear` > 0, a split point within that distance of another segment is left
    out.  A split point is rounded, so where two segments are within an ulp or two of
    each other (the sides of a needle, a line grazing an edge) it may land on the
    other segment or beyond it, which would change the PSLG's topology; leaving it out
    only makes a piece longer than the size asks for."""
    if len(segments) == 0:
        return vertices, segments, source
    a = vertices[segments[:, 0]]
    b = vertices[segments[:, 1]]
    length = np.linalg.norm(b - a, axis=1)
    s = np.linspace(0.0, 1.0, _SAMPLES)
    xs = a[:, None, 0] + (b - a)[:, None, 0] * s
    ys = a[:, None, 1] + (b - a)[:, None, 1] * s
    h = field(xs, ys)
    # cumulative integral of 1/h along each segment, h taken linear between samples:
    # the exact integral of 1/h on such a piece is ds * ln(h1/h0) / (h1 - h0) (the
    # trapezoid rule overcounts enormously next to a tiny size, where h varies by
    # orders of magnitude within one sample interval)
    ds = length[:, None] / (_SAMPLES - 1)
    h0 = h[:, :-1]
    h1 = h[:, 1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        log_mean = np.where(np.abs(h1 - h0) > 1e-9 * h0, (np.log(h1) - np.log(h0)) / (h1 - h0),
                            2.0 / (h0 + h1))
    steps = ds * log_mean
    cum = np.concatenate([np.zeros((len(segments), 1)), np.cumsum(steps, axis=1)], axis=1)
    total = float(np.rint(cum[:, -1]).clip(min=1).sum())
    if max_pieces is not None and not total <= max_pieces:
        from .errors import InvalidSizeError
        raise InvalidSizeError(
            f"{limit} is below what the boundary alone needs: about {total:.3g} edges at "
            "this size (each a side of a different triangle but for a few)")
    pieces = np.maximum(1, np.rint(cum[:, -1]).astype(np.int64))
    split = np.flatnonzero(pieces > 1)
    points = []
    for k in split:
        n = int(pieces[k])
        targets = cum[k, -1] * np.arange(1, n) / n
        t = np.interp(targets, cum[k], s)
        points.append(a[k] + np.outer(t, b[k] - a[k]))
    if clear > 0 and points:
        points = _clear_of_others(points, split, a, b, clear)
    new_vertices = [vertices]
    new_segments = []
    new_source = []
    next_index = len(vertices)
    simple = pieces == 1
    new_segments.append(segments[simple])
    new_source.append(source[simple])
    for k, pts in zip(split, points):
        # rounded points never coincide at the sizes make_size_field accepts, but a
        # piece of zero length would be fatal: drop any that do
        prev = np.vstack([a[k], pts[:-1]])
        distinct = (pts != prev).any(axis=1) & (pts != b[k]).any(axis=1)
        if not distinct.all():
            pts = pts[distinct]
        m = len(pts)
        idx = np.arange(next_index, next_index + m)
        next_index += m
        chain = np.concatenate([[segments[k, 0]], idx, [segments[k, 1]]])
        new_vertices.append(pts)
        new_segments.append(np.c_[chain[:-1], chain[1:]])
        new_source.append(np.full(m + 1, source[k]))
    return (np.concatenate(new_vertices), np.concatenate(new_segments).astype(np.int32),
            np.concatenate(new_source).astype(np.int32))


def _clear_of_others(points, split, a, b, clear):
    """Drop from points[i] (the split points of segment split[i]) those within
    `clear` of any other segment."""
    import shapely
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    allp = np.concatenate(points)
    parent = np.repeat(split, [len(p) for p in points])
    pi, si = shapely.STRtree(lines).query(shapely.points(allp), predicate="dwithin",
                                          distance=clear)
    keep = np.ones(len(allp), dtype=bool)
    keep[pi[si != parent[pi]]] = False
    out = []
    start = 0
    for p in points:
        out.append(p[keep[start:start + len(p)]])
        start += len(p)
    return out
