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
               field: SizeField, max_pieces: int | None = None, limit: str = ""):
    """Return (vertices, segments, source) with long segments split by the size.

    Raises InvalidSizeError, before allocating anything, if the boundary alone would
    need more than `max_pieces` edges (each is a side of a triangle of the mesh)."""
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
    new_vertices = [vertices]
    new_segments = []
    new_source = []
    next_index = len(vertices)
    simple = pieces == 1
    new_segments.append(segments[simple])
    new_source.append(source[simple])
    for k in np.flatnonzero(~simple):
        n = int(pieces[k])
        targets = cum[k, -1] * np.arange(1, n) / n
        t = np.interp(targets, cum[k], s)
        pts = a[k] + np.outer(t, b[k] - a[k])
        idx = np.arange(next_index, next_index + n - 1)
        next_index += n - 1
        chain = np.concatenate([[segments[k, 0]], idx, [segments[k, 1]]])
        new_vertices.append(pts)
        new_segments.append(np.c_[chain[:-1], chain[1:]])
        new_source.append(np.full(n, source[k]))
    return (np.concatenate(new_vertices), np.concatenate(new_segments).astype(np.int32),
            np.concatenate(new_source).astype(np.int32))
