"""``aftmesh.cdt``: the constrained Delaunay triangulation of a PSLG, no points added
(unless crossing segments are to be split at their crossing points)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .domain import node_crossings
from .errors import InvalidOptionError
from .mesh import Mesh
from .pslg import as_points, as_segments, build_cdt

__all__ = ["cdt"]

CROSSINGS = ("raise", "split")


def cdt(
    vertices: npt.ArrayLike,
    segments: npt.ArrayLike | None = None,
    *,
    holes: npt.ArrayLike | None = None,
    regions: npt.ArrayLike | None = None,
    crossings: str = "raise",
) -> Mesh:
    """Constrained Delaunay triangulation of a planar straight-line graph.

    No point is added, unless ``crossings="split"``.  A segment that runs exactly
    through an input vertex is split there.

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
    crossings : {"raise", "split"}, keyword-only
        What to do with segments that cross at a point interior to both.  ``"raise"``
        (the default) raises :class:`aftmesh.CrossingSegmentsError` naming both, so
        the output's vertices are exactly the input's.  ``"split"`` inserts each
        crossing point (computed once, rounded to the nearest double, and shared by
        the segments through it) and splits the segments there, repeating until no
        crossing remains, as Triangle's ``p`` switch does.  The points are listed in
        ``info['crossings']``: ``points`` (k, 2), ``segments`` (the input segment
        indices crossing there, one tuple per point) and ``vertices`` (their indices
        in ``Mesh.points``).

    Returns
    -------
    Mesh
        With segments given, the triangles inside closed rings of segments (minus
        holes); without, the whole convex hull.  ``info['vertex_map']`` maps each
        input vertex to its output index (-1: merged away or outside the domain).
        ``segment_markers`` and ``segment_sources`` give, for each output segment, the
        input segment it is a piece of (the kernel carries it through every split and
        retriangulation).

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

    Two diagonals of a square cross at its centre; ``"split"`` inserts that point:

    >>> corners = [(0, 0), (2, 0), (2, 2), (0, 2)]
    >>> edges = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)]
    >>> m = aftmesh.cdt(corners, edges, crossings="split")
    >>> m.n_triangles, m.info["crossings"]["points"].tolist(), m.info["crossings"]["segments"]
    (4, [[1.0, 1.0]], [(4, 5)])
    >>> sorted(m.segment_markers.tolist())     # each diagonal is now two pieces
    [0, 1, 2, 3, 4, 4, 5, 5]
    """
    if not isinstance(crossings, str) or crossings not in CROSSINGS:
        raise InvalidOptionError(
            f"crossings={crossings!r} is not a valid option, must be one of {list(CROSSINGS)}"
        )
    noded = _split_crossings(vertices, segments) if crossings == "split" else None
    if noded is None:
        built = build_cdt(vertices, segments, holes, regions)
        a = built.kernel.arrays(release=True)
        to_out = a["vertex_map"][built.merged]
        markers = a["segment_ids"]  # the kernel's provenance of each output segment
        info = {"merged_vertices": built.n_merged, "vertex_map": to_out}
        if crossings == "split":
            info["crossings"] = _no_crossings()
    else:
        verts, segs, src, to_noded, n_merged = noded
        built = build_cdt(verts, segs, holes, regions)
        a = built.kernel.arrays(release=True)
        noded_out = a["vertex_map"][built.merged]
        ids = a["segment_ids"]
        markers = np.where(ids >= 0, src[np.maximum(ids, 0)], -1).astype(np.int32)
        info = {
            "merged_vertices": n_merged,
            "vertex_map": noded_out[to_noded],
            "crossings": _crossing_report(verts, segs, src, to_noded, noded_out),
        }
    return Mesh._adopt(
        points=a["points"],
        triangles=a["triangles"],
        neighbors=a["neighbors"],
        segments=a["segments"],
        regions=a["regions"],
        segment_markers=markers,
        segment_sources=markers,
        info=info,
    )


def _split_crossings(vertices, segments):
    """Node the crossing segments (domain.node_crossings: crossing points computed
    once, cut points ordered along a segment by exact coordinate comparison, repeated
    until nothing crosses; vertices are snapped only when exactly on a segment).
    Returns None when nothing crosses, else (vertices, segments, source segment of
    each piece, input vertex -> noded vertex, number of merged input vertices)."""
    pts = as_points(vertices, "vertices")
    seg = as_segments(segments, len(pts), pts)
    if len(seg) < 2:
        return None
    note: list[str] = []
    src = np.arange(len(seg), dtype=np.int64)
    verts, segs, src = node_crossings(pts, seg.astype(np.int64), src, note, tol=0.0)
    if not note:
        return None
    # node_crossings keeps every input coordinate exactly (np.unique): find them again
    index = {p: i for i, p in enumerate(map(tuple, verts.tolist()))}
    to_noded = np.array([index[p] for p in map(tuple, pts.tolist())], dtype=np.int64)
    n_merged = len(pts) - len(np.unique(to_noded))
    return (
        np.ascontiguousarray(verts),
        np.asarray(segs, dtype=np.int32),
        np.asarray(src, dtype=np.int32),
        to_noded,
        n_merged,
    )


def _no_crossings():
    return {"points": np.zeros((0, 2)), "segments": [], "vertices": np.zeros(0, np.int32)}


def _crossing_report(verts, segs, src, to_noded, noded_out):
    """The inserted points: coordinates, the input segments through each, and their
    index in the output."""
    is_new = np.ones(len(verts), dtype=bool)
    is_new[to_noded] = False
    through: dict[int, set[int]] = {}
    for (u, w), s in zip(segs.tolist(), src.tolist()):
        for v in (u, w):
            if is_new[v]:
                through.setdefault(v, set()).add(s)
    new = np.flatnonzero(is_new)
    return {
        "points": verts[new].copy(),
        "segments": [tuple(sorted(through.get(int(v), ()))) for v in new],
        "vertices": noded_out[new].astype(np.int32),
    }
