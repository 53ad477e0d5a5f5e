"""Topology of a finished mesh: connected pieces, holes, and a seed point per region.

One connected-components routine (:func:`components`, numpy only) serves every
question here and in :mod:`aftmesh.checks`.  (The kernel's ``Triangulation.components``
is a different job: it labels the pieces of the CDT before meshing.)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["components", "hole_points", "region_points", "triangle_components"]


def components(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Label of each of ``n`` items joined by the pairs ``(a[i], b[i])``.

    The label of an item is the smallest item of its connected component.
    Vectorized union-find: every root is hooked onto the smaller root across every
    pair that joins two components, then the parent pointers are shortcut until each
    points at its root; repeated until no pair joins two components.  Hooking only
    ever lowers a parent, so no cycle can form, and the smallest item of a component
    is never hooked anywhere: it ends as the root.

    Examples
    --------
    >>> components(5, [3, 1], [4, 3]).tolist()
    [0, 1, 2, 1, 1]
    """
    a = np.asarray(a, dtype=np.int64).reshape(-1)
    b = np.asarray(b, dtype=np.int64).reshape(-1)
    parent = np.arange(n)
    while True:
        ra, rb = parent[a], parent[b]
        differ = ra != rb
        if not differ.any():
            return parent
        lo = np.minimum(ra[differ], rb[differ])
        hi = np.maximum(ra[differ], rb[differ])
        np.minimum.at(parent, hi, lo)
        while True:
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand


def _interior_edges(mesh):
    """Each interior edge once: triangles (ti, tj) sharing it and its vertices (u, w)."""
    T, N = np.asarray(mesh.triangles), np.asarray(mesh.neighbors)
    ti, k = np.nonzero(N > np.arange(len(T))[:, None])
    return ti, N[ti, k], T[ti, (k + 1) % 3], T[ti, (k + 2) % 3]


def _is_segment(mesh, u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Whether each edge (u[i], w[i]) is one of the mesh's segments."""
    n = max(len(mesh.points), 1)
    u, w = u.astype(np.int64), w.astype(np.int64)
    S = np.asarray(mesh.segments, dtype=np.int64).reshape(-1, 2)
    seg_key = S.min(axis=1) * n + S.max(axis=1)
    return np.isin(np.minimum(u, w) * n + np.maximum(u, w), seg_key)


def triangle_components(mesh: Mesh, *, cut_at_segments: bool = False) -> np.ndarray:
    """The connected component of each triangle, through shared edges.

    Parameters
    ----------
    mesh : aftmesh.Mesh
    cut_at_segments : bool
        Do not join triangles across a segment: the pieces enclosed by segments.

    Returns
    -------
    (t,) int64
        Components numbered from 0 in the order of their first triangles.

    Examples
    --------
    >>> import aftmesh
    >>> from shapely.geometry import LineString, GeometryCollection, box
    >>> cut = GeometryCollection([box(0, 0, 2, 1), LineString([(1, 0), (1, 1)])])
    >>> m = aftmesh.generate(cut, size=0.5)
    >>> int(triangle_components(m).max()), int(triangle_components(m, cut_at_segments=True).max())
    (0, 1)
    """
    ti, tj, u, w = _interior_edges(mesh)
    if cut_at_segments:
        free = ~_is_segment(mesh, u, w)
        ti, tj = ti[free], tj[free]
    labels = components(len(mesh.triangles), ti, tj)
    return np.unique(labels, return_inverse=True)[1].reshape(-1)


def hole_points(mesh: Mesh) -> np.ndarray:
    """(h, 2): a point inside each hole of the mesh.

    The boundary edges are polygonized; each face they enclose is either covered by
    triangles or a hole, which a point of the face tells.

    Examples
    --------
    >>> import aftmesh
    >>> from shapely.geometry import box
    >>> m = aftmesh.generate(box(0, 0, 3, 3).difference(box(1, 1, 2, 2)), size=0.5)
    >>> p = hole_points(m)
    >>> p.shape, bool(((p > 1) & (p < 2)).all())
    ((1, 2), True)
    """
    import shapely

    P, T, N = mesh.points, mesh.triangles, mesh.neighbors
    if len(T) == 0:
        return np.zeros((0, 2))
    ti, k = np.nonzero(N < 0)
    a = T[ti, (k + 1) % 3]
    b = T[ti, (k + 2) % 3]
    loops = shapely.linestrings(np.stack([P[a], P[b]], axis=1))
    holes = []
    for face in shapely.get_parts(shapely.polygonize(loops)):
        p = np.asarray(face.representative_point().coords)[0]
        v = P[T] - p
        cross = v[:, [0, 1, 2], 0] * v[:, [1, 2, 0], 1] - v[:, [0, 1, 2], 1] * v[:, [1, 2, 0], 0]
        if not (cross >= 0).all(axis=1).any():
            holes.append(p)
    return np.array(holes).reshape(-1, 2)


def region_points(mesh: Mesh) -> np.ndarray:
    """(r, 3) rows of (x, y, region): a point in each piece of the mesh enclosed by
    segments, with that piece's region (the centroid of its first triangle).

    Meshing the mesh's segments with these as regional attribute points gives back
    the same region for every triangle.
    """
    if len(mesh.triangles) == 0:
        return np.zeros((0, 3))
    piece = triangle_components(mesh, cut_at_segments=True)
    _, first = np.unique(piece, return_index=True)
    centroids = mesh.points[mesh.triangles[first]].mean(axis=1)
    return np.c_[centroids, mesh.regions[first]]
