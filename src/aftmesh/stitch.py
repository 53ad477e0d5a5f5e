"""Stitch meshes of the parts of one domain into one mesh, and restore the CDT property.

The parts share their cut vertices exactly (each cut was discretized once and both
sides were given the same coordinates), so a vertex is identified across parts by the
bytes of its coordinates.  Only vertices on a part's segments can be shared: the
search runs over those, never over a part's interior.  Each part is the constrained
Delaunay triangulation of its own vertices and segments, a cut piece being a segment
there; once the cut pieces are ordinary edges, Lawson flips starting from them make
the whole mesh the CDT of its vertices and the input segments again.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _kernel
from .errors import KernelError

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["lawson_flips", "stitch_parts"]


def _void(xy: np.ndarray) -> np.ndarray:
    """Coordinate pairs as one opaque 16-byte key each (exact identity)."""
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    return xy.view(np.dtype((np.void, 16))).ravel()


def _pair_keys(a, b, n: int) -> np.ndarray:
    lo = np.minimum(a, b).astype(np.int64)
    hi = np.maximum(a, b).astype(np.int64)
    return lo * n + hi


def global_numbering(meshes: Sequence[Mesh]) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
    """(points, per-part old -> new vertex maps, shared keys sorted): shared vertices
    (segment ends) first, numbered by their coordinates, then each part's others."""
    ends = [np.unique(m.segments) for m in meshes]
    keys = np.concatenate([_void(m.points[e]) for m, e in zip(meshes, ends)])
    shared_keys, first = np.unique(keys, return_index=True)
    all_ends = np.concatenate([m.points[e] for m, e in zip(meshes, ends)])
    points = [all_ends[first]]
    maps = []
    next_id = len(shared_keys)
    for m, e in zip(meshes, ends):
        new = np.empty(len(m.points), dtype=np.int64)
        new[e] = np.searchsorted(shared_keys, _void(m.points[e]))
        rest = np.ones(len(m.points), dtype=bool)
        rest[e] = False
        n_rest = int(rest.sum())
        new[rest] = np.arange(next_id, next_id + n_rest)
        next_id += n_rest
        points.append(m.points[rest])
        maps.append(new)
    return np.concatenate(points), maps, shared_keys


def stitch_parts(
    meshes: Sequence[Mesh], input_xy: np.ndarray, input_markers: np.ndarray
) -> tuple[
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    set[Any],
]:
    """One mesh from the part meshes: (points, triangles, neighbors, regions,
    segments, segment_markers, cut_edges, cut_vertices, constrained) where the
    segments are the input pieces (given as coordinate pairs ``input_xy`` (s, 2, 2)),
    cut_edges are the (triangle, k) half-edges that were cut pieces, cut_vertices the
    vertices only on cuts, and constrained the segments' keys for
    :func:`lawson_flips`."""
    points, maps, shared_keys = global_numbering(meshes)
    n = len(points)
    total = sum(m.n_triangles for m in meshes)
    T = np.empty((total, 3), dtype=np.int32)
    N = np.empty((total, 3), dtype=np.int32)
    R = np.empty(total, dtype=np.int32)
    offset = 0
    for m, new in zip(meshes, maps):
        end = offset + m.n_triangles
        T[offset:end] = new.astype(np.int32)[m.triangles]
        N[offset:end] = m.neighbors
        part = N[offset:end]
        part[part >= 0] += offset
        R[offset:end] = m.regions
        offset = end
    # join the parts: a boundary half-edge (a, b) of one part meets (b, a) of another
    t, k = np.nonzero(N < 0)
    a = T[t, (k + 1) % 3].astype(np.int64)
    b = T[t, (k + 2) % 3].astype(np.int64)
    key, rev = a * n + b, b * n + a
    order = np.argsort(key)
    pos = np.minimum(np.searchsorted(key[order], rev), len(key) - 1)
    hit = key[order][pos] == rev
    other = order[pos[hit]]
    N[t[hit], k[hit]] = t[other]
    ends_key = _void(input_xy.reshape(-1, 2))
    seg_ends = np.minimum(np.searchsorted(shared_keys, ends_key), len(shared_keys) - 1)
    if not (shared_keys[seg_ends] == ends_key).all():
        raise KernelError("an input segment's end is in no part's mesh")
    seg_ends = seg_ends.reshape(-1, 2)
    segments = seg_ends.astype(np.int32)
    seg_key = np.sort(_pair_keys(segments[:, 0], segments[:, 1], n))
    joined = _pair_keys(a[hit], b[hit], n)
    sp = np.minimum(np.searchsorted(seg_key, joined), len(seg_key) - 1)
    is_input = seg_key[sp] == joined
    cut = np.c_[t[hit][~is_input], k[hit][~is_input]]
    cut_vertices = np.setdiff1d(np.unique(np.c_[a[hit], b[hit]][~is_input]), segments)
    return (points, T, N, R, segments, input_markers, cut, cut_vertices, set(seg_key.tolist()))


def lawson_flips(
    P: np.ndarray, T: np.ndarray, N: np.ndarray, constrained: set, start: np.ndarray
) -> int:
    """Flip non-Delaunay edges, starting from the half-edges ``start`` (t, k), until
    every edge reached is locally Delaunay or a constrained edge (``constrained``
    holds keys lo * n + hi).  T and N are changed in place; returns the flip count.
    The exact incircle predicate decides; an edge failing it is always flippable
    (its quadrilateral is convex), and each flip grows the smallest angle, so this
    stops."""
    n = len(P)
    stack = [(int(t), int(k)) for t, k in start]
    flips = 0
    incircle = _kernel.py_incircle
    while stack:
        t, k = stack.pop()
        u = int(N[t, k])
        if u < 0:
            continue
        c, a, b = int(T[t, k]), int(T[t, (k + 1) % 3]), int(T[t, (k + 2) % 3])
        if min(a, b) * n + max(a, b) in constrained:
            continue
        j = next(i for i in range(3) if int(T[u, i]) != a and int(T[u, i]) != b)
        d = int(T[u, j])
        if incircle(P[c, 0], P[c, 1], P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[d, 0], P[d, 1]) <= 0:
            continue
        n_bc, n_ca = int(N[t, (k + 1) % 3]), int(N[t, (k + 2) % 3])
        n_ad, n_db = int(N[u, (j + 1) % 3]), int(N[u, (j + 2) % 3])
        # where the two outer neighbours point back, found before anything changes
        # (one triangle may be both of them)
        back_ad = int(np.flatnonzero(N[n_ad] == u)[0]) if n_ad >= 0 else -1
        back_bc = int(np.flatnonzero(N[n_bc] == t)[0]) if n_bc >= 0 else -1
        T[t] = (c, a, d)
        N[t] = (n_ad, u, n_ca)
        T[u] = (c, d, b)
        N[u] = (n_db, n_bc, t)
        if n_ad >= 0:
            N[n_ad, back_ad] = t
        if n_bc >= 0:
            N[n_bc, back_bc] = u
        flips += 1
        stack.extend(((t, 0), (t, 2), (u, 0), (u, 1)))
    return flips
