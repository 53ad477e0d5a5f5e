"""``aftmesh.cdt``: the constrained Delaunay triangulation of a PSLG, no points added."""
from __future__ import annotations

import numpy as np

from . import _kernel
from .mesh import Mesh
from .pslg import build_cdt

__all__ = ["cdt"]


# Points the minimum-angle pass puts on a segment are off its line by a few ulps
# (rounding, or moved into the domain past a sliver of exterior triangle): how far a
# piece's end may be from the line, in units in the last place of the coordinates.
PIECE_ULPS = 16


def _within_ulps(pa, pb, pw) -> bool:
    d = pb - pa
    scale = max(float(np.abs(pa).max()), float(np.abs(pb).max()), float(np.abs(pw).max()))
    cross = abs(float(d[0] * (pw[1] - pa[1]) - d[1] * (pw[0] - pa[0])))
    return cross <= PIECE_ULPS * np.finfo(float).eps * scale * float(np.hypot(*d))


def segment_markers(points: np.ndarray, out_segments: np.ndarray, in_points: np.ndarray,
                    in_segments: np.ndarray, to_out: np.ndarray) -> np.ndarray:
    """For each output segment, the index of the input segment it is (a piece of).

    ``to_out`` maps input vertex -> output vertex.  Pieces of a split input segment are
    found by walking from its first end along output segments collinear with it."""
    markers = np.full(len(out_segments), -1, dtype=np.int32)
    if len(out_segments) == 0 or len(in_segments) == 0:
        return markers
    # the common case, vectorized: an input segment that is an output segment as is
    n = max(int(len(points)), 1)
    out_key = np.sort(out_segments.astype(np.int64), axis=1)
    out_key = out_key[:, 0] * n + out_key[:, 1]
    ends = to_out[in_segments].astype(np.int64)
    whole = (ends >= 0).all(axis=1)
    in_key = np.sort(ends, axis=1)
    in_key = in_key[:, 0] * n + in_key[:, 1]
    order = np.argsort(out_key)
    pos = np.minimum(np.searchsorted(out_key[order], in_key), len(order) - 1)
    hit = whole & (out_key[order][pos] == in_key)
    # later input segments win on duplicates, as in the loop below
    markers[order[pos[hit]]] = np.flatnonzero(hit).astype(np.int32)
    rest = np.flatnonzero(~hit)
    if len(rest) == 0:
        return markers
    index = {}
    for k, (u, v) in enumerate(out_segments.tolist()):
        index[(u, v)] = k
        index[(v, u)] = k
    adjacency: dict[int, list[int]] = {}
    for u, v in out_segments:
        adjacency.setdefault(int(u), []).append(int(v))
        adjacency.setdefault(int(v), []).append(int(u))
    for j in rest.tolist():
        a, b = int(in_segments[j, 0]), int(in_segments[j, 1])
        u, v = int(to_out[a]), int(to_out[b])
        if u < 0:
            # walk from the end that is in the output (a segment can leave the domain
            # through a boundary vertex; its outside part is carved away)
            u, v, a, b = v, u, b, a
        if u < 0:
            continue
        # a split segment: follow collinear pieces from u towards b's input position
        pa, pb = in_points[a], in_points[b]
        cur, prev, guard = u, -1, 0
        while cur != v and guard <= len(points):
            guard += 1
            step = near = -1
            for w in adjacency.get(cur, ()):
                if w == prev:
                    continue
                pw = points[w]
                if not (np.dot(pw - points[cur], pb - pa) > 0 and np.dot(pb - pw, pb - pa) >= 0):
                    continue
                if _kernel.py_orient2d(pa[0], pa[1], pb[0], pb[1], pw[0], pw[1]) == 0:
                    step = w
                    break
                if near < 0 and _within_ulps(pa, pb, pw):
                    near = w
            step = step if step >= 0 else near
            if step < 0:
                break
            markers[index[(cur, step)]] = j
            prev, cur = cur, step
    return markers


def cdt(vertices, segments=None, *, holes=None, regions=None) -> Mesh:
    """Constrained Delaunay triangulation of a planar straight-line graph.

    No point is added.  A segment that runs exactly through an input vertex is split
    there; segments that cross raise :class:`aftmesh.CrossingSegmentsError`.

    Parameters
    ----------
    vertices : (n, 2) array_like
        Point coordinates.  Exact duplicates are merged (``info['merged_vertices']``).
    segments : (m, 2) array_like of int, optional
        Vertex index pairs that must be edges of the triangulation.
    holes : (h, 2) array_like, optional
        Points inside holes: the segment-bounded region around each is removed.
    regions : sequence of (x, y, marker), optional
        Each triangle of the segment-bounded region containing (x, y) gets ``marker``
        in ``Mesh.regions`` (0 elsewhere).

    Returns
    -------
    Mesh
        With segments given, the triangles inside closed rings of segments (minus
        holes); without, the whole convex hull.  ``info['vertex_map']`` maps each
        input vertex to its output index (-1: merged away or outside the domain).

    Examples
    --------
    >>> import aftmesh
    >>> m = aftmesh.cdt([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)])
    >>> m.n_triangles
    4
    >>> square = [(0, 0), (2, 0), (2, 2), (0, 2), (0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)]
    >>> ring = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    >>> m = aftmesh.cdt(square, ring, holes=[(1, 1)])
    >>> m.n_triangles, round(m.area(), 12)
    (8, 3.0)
    """
    built = build_cdt(vertices, segments, holes, regions)
    a = built.kernel.arrays()
    to_out = a["vertex_map"][built.merged]
    markers = segment_markers(a["points"], a["segments"], built.vertices, built.segments, to_out)
    info = {"merged_vertices": built.n_merged, "vertex_map": to_out}
    return Mesh._adopt(points=a["points"], triangles=a["triangles"], neighbors=a["neighbors"],
                segments=a["segments"], regions=a["regions"], segment_markers=markers, info=info)
