"""The one invariant checker, applied to every mesh the tests make.

:func:`check_mesh` verifies, with the exact predicates where geometry decides:

* arrays: shapes, dtypes, indices in range, every point used, no duplicate points;
* orientation: every triangle strictly counter-clockwise;
* topology: each edge in one or two triangles, ``neighbors`` symmetric and consistent
  with the shared edges, every boundary edge a segment, every segment an edge;
* area: the triangles' areas sum to the domain's area (when given);
* conformity: each input segment (given as coordinates) is covered by mesh segments;
* constrained Delaunay: on every edge that is not a segment, the far vertex of the
  neighbouring triangle is not strictly inside the circumcircle.

It raises :class:`MeshCheckError` listing every problem found.
"""

from __future__ import annotations

import numpy as np

from . import _kernel
from .mesh import Mesh

# re-exported: the one connected-components routine lives with the mesh topology
from .topology import triangle_components

__all__ = ["MeshCheckError", "check_mesh", "count_formula", "triangle_components"]


class MeshCheckError(AssertionError):
    """A mesh broke an invariant; the message lists each problem."""


def _edges(tri: np.ndarray):
    """Half-edges (t, k): edge opposite vertex k of triangle t, as vertex pairs."""
    a = tri[:, [1, 2, 0]]
    b = tri[:, [2, 0, 1]]
    return a, b


def check_mesh(
    mesh: Mesh,
    *,
    domain_area: float | None = None,
    input_segments: np.ndarray | None = None,
    delaunay: bool = True,
    boundary_is_segments: bool | None = None,
    area_rtol: float = 1e-9,
) -> None:
    """Check every invariant of ``mesh``; raise :class:`MeshCheckError` if any fails.

    Parameters
    ----------
    domain_area : float, optional
        Expected total area.
    input_segments : (m, 2, 2) array, optional
        Input edges as coordinate pairs; each must be covered exactly by mesh segments.
    delaunay : bool
        Also check the constrained Delaunay property.
    boundary_is_segments : bool, optional
        Require every boundary edge to be a segment (default: when the mesh has
        segments at all; a CDT of bare points is bounded by its convex hull instead).
    """
    problems: list[str] = []
    P = np.asarray(mesh.points)
    T = np.asarray(mesh.triangles)
    N = np.asarray(mesh.neighbors)
    S = np.asarray(mesh.segments)
    n, t = len(P), len(T)
    if P.dtype != np.float64 or P.ndim != 2 or P.shape[1] != 2:
        problems.append(f"points: dtype {P.dtype}, shape {P.shape}")
    if T.dtype != np.int32 or T.shape != (t, 3) or N.shape != (t, 3):
        problems.append(f"triangles {T.dtype} {T.shape} / neighbors {N.shape}")
    if len(mesh.regions) != t:
        problems.append(f"regions has {len(mesh.regions)} entries for {t} triangles")
    markers = mesh.segment_markers
    if markers is None or len(markers) != len(S):
        n_markers = "no" if markers is None else len(markers)
        problems.append(f"segment_markers has {n_markers} entries for {len(S)} segments")
    if problems:
        raise MeshCheckError("; ".join(problems))
    if t == 0:
        if domain_area:
            raise MeshCheckError(f"no triangles, but the domain area is {domain_area}")
        return
    if T.min() < 0 or T.max() >= n:
        raise MeshCheckError(f"triangle vertex index out of range 0..{n - 1}")
    if not np.isfinite(P).all():
        problems.append("non-finite coordinates")
    used = np.zeros(n, dtype=bool)
    used[T.ravel()] = True
    if not used.all():
        problems.append(f"{int((~used).sum())} unused points, e.g. {int(np.flatnonzero(~used)[0])}")
    if len(np.unique(P, axis=0)) != n:
        problems.append("duplicate points")
    if ((T[:, 0] == T[:, 1]) | (T[:, 1] == T[:, 2]) | (T[:, 2] == T[:, 0])).any():
        problems.append("a triangle repeats a vertex")
    orient = _kernel.orient2d_many(np.ascontiguousarray(P), np.ascontiguousarray(T))
    if (orient <= 0).any():
        i = int(np.flatnonzero(orient <= 0)[0])
        problems.append(
            f"{int((orient <= 0).sum())} triangles not counter-clockwise, e.g. {i}: "
            f"{P[T[i]].tolist()}"
        )
    # topology: match each half-edge with its reverse
    a, b = _edges(T)
    key = a.astype(np.int64) * n + b
    rev = b.astype(np.int64) * n + a
    flat_key = key.ravel()
    order = np.argsort(flat_key)
    sorted_keys = flat_key[order]
    if (sorted_keys[1:] == sorted_keys[:-1]).any():
        problems.append("a directed edge appears twice (overlapping or folded triangles)")
    pos = np.searchsorted(sorted_keys, rev.ravel())
    pos = np.minimum(pos, len(sorted_keys) - 1)
    found = sorted_keys[pos] == rev.ravel()
    other = np.where(found, order[pos] // 3, -1).reshape(t, 3)
    neighbors_ok = np.array_equal(other, N)
    if not neighbors_ok:
        bad = np.argwhere(other != N)[0]
        problems.append(
            f"neighbors[{bad[0]}, {bad[1]}] = {N[bad[0], bad[1]]}, "
            f"the shared edge says {other[bad[0], bad[1]]}"
        )
    seg_keys = set()
    for u, v in S:
        seg_keys.add((int(u), int(v)))
        seg_keys.add((int(v), int(u)))
    boundary = ~found.reshape(t, 3)
    if boundary_is_segments is None:
        boundary_is_segments = len(S) > 0
    for ti, k in np.argwhere(boundary) if boundary_is_segments else ():
        e = (int(a[ti, k]), int(b[ti, k]))
        if e not in seg_keys:
            problems.append(f"boundary edge {e} of triangle {ti} is not a segment")
            break
    edge_set = set(zip(a.ravel().tolist(), b.ravel().tolist()))
    for u, v in S:
        if (int(u), int(v)) not in edge_set and (int(v), int(u)) not in edge_set:
            problems.append(f"segment ({u}, {v}) is not an edge of the mesh")
            break
    # area
    p = P[T]
    area = 0.5 * (
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )
    if domain_area is not None:
        total = float(area.sum())
        if abs(total - domain_area) > area_rtol * max(abs(domain_area), 1e-300) + 1e-300:
            problems.append(
                f"triangle areas sum to {total!r}, the domain's area is {domain_area!r}"
            )
    # conformity: each input segment covered by collinear mesh segments of equal total length
    if input_segments is not None and len(input_segments):
        problems.extend(_check_cover(P, S, np.asarray(input_segments, dtype=np.float64)))
    # constrained Delaunay: the apex across every non-segment interior edge
    if delaunay:
        # the shared edges found above, not `neighbors`, which may be what is broken
        N = other
        interior = found.reshape(t, 3)
        ti, k = np.nonzero(interior)
        is_seg = np.fromiter(
            ((int(a[i, j]), int(b[i, j])) in seg_keys for i, j in zip(ti, k)),
            dtype=bool,
            count=len(ti),
        )
        ti, k = ti[~is_seg], k[~is_seg]
        nb = N[ti, k]
        # the vertex of the neighbour not on the shared edge
        nbt = T[nb]
        far = nbt[(nbt != a[ti, k][:, None]) & (nbt != b[ti, k][:, None])]
        quad = np.ascontiguousarray(np.c_[T[ti], far], dtype=np.int32)
        inc = _kernel.incircle_many(np.ascontiguousarray(P), quad)
        if (inc > 0).any():
            i = int(np.flatnonzero(inc > 0)[0])
            problems.append(
                f"{int((inc > 0).sum())} non-Delaunay edges, e.g. triangle "
                f"{int(ti[i])} vs its neighbour {int(nb[i])}"
            )
    if problems:
        raise MeshCheckError("; ".join(problems))


def _check_cover(P, S, segs):
    """Each input segment must be the union of mesh segments lying on it."""
    problems = []
    sa, sb = P[S[:, 0]], P[S[:, 1]]
    for j, (pa, pb) in enumerate(segs):
        d = pb - pa
        L = float(np.hypot(*d))
        # mesh segments whose both ends lie on the line and inside the input segment
        ca = _kernel_orient_points(pa, pb, sa)
        cb = _kernel_orient_points(pa, pb, sb)
        ta = (sa - pa) @ d / (d @ d)
        tb = (sb - pa) @ d / (d @ d)
        on = (
            (ca == 0)
            & (cb == 0)
            & (np.minimum(ta, tb) >= -1e-12)
            & (np.maximum(ta, tb) <= 1 + 1e-12)
        )
        covered = float(np.hypot(*(sb[on] - sa[on]).T).sum())
        if abs(covered - L) > 1e-9 * max(L, 1e-300):
            problems.append(
                f"input segment {j} ({pa.tolist()} -> {pb.tolist()}) is covered over "
                f"{covered!r} of its length {L!r}"
            )
            break
    return problems


def _kernel_orient_points(pa, pb, pts):
    allp = np.ascontiguousarray(np.vstack([pa, pb, pts]), dtype=np.float64)
    idx = np.c_[np.zeros(len(pts)), np.ones(len(pts)), np.arange(2, len(pts) + 2)].astype(np.int32)
    return _kernel.orient2d_many(allp, np.ascontiguousarray(idx))


def boundary_curves(points: np.ndarray, triangles: np.ndarray) -> int:
    """Number of closed boundary curves of a set of triangles, traced as in the paper's
    §2.1: boundary edges oriented with the triangles on their left, the successor of an
    edge being the outgoing boundary edge that turns most to the left (formula (1)),
    so a curve touching itself at a vertex stays one curve."""
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    fwd = set(map(tuple, e.tolist()))
    bnd = [(u, v) for u, v in fwd if (v, u) not in fwd]
    out: dict[int, list[int]] = {}
    for u, v in bnd:
        out.setdefault(u, []).append(v)
    succ = {}
    for u, v in bnd:
        d_in = points[v] - points[u]
        best, best_turn = None, -np.inf
        for w in out[v]:
            d_out = points[w] - points[v]
            turn = np.arctan2(d_in[0] * d_out[1] - d_in[1] * d_out[0], d_in @ d_out)
            if turn > best_turn:
                best, best_turn = w, turn
        succ[(u, v)] = (v, best)
    seen = set()
    curves = 0
    for edge in succ:
        if edge in seen:
            continue
        curves += 1
        while edge not in seen:
            seen.add(edge)
            edge = succ[edge]
    return curves


def count_formula(mesh: Mesh) -> list[tuple[int, int, int, int]]:
    """Per connected component of the mesh: (T, E_b, V_i, m), with m + 1 the number of
    its boundary curves (see :func:`boundary_curves`).  The appendix's formula (6)
    states T = E_b + 2 V_i + 2 (m - 1)."""
    P = np.asarray(mesh.points)
    T = np.asarray(mesh.triangles)
    comp = triangle_components(mesh)
    c = int(comp.max()) + 1 if len(comp) else 0
    out = []
    for k in range(c):
        tk = T[comp == k]
        e = np.sort(np.concatenate([tk[:, [0, 1]], tk[:, [1, 2]], tk[:, [2, 0]]]), axis=1)
        uniq, counts = np.unique(e, axis=0, return_counts=True)
        bnd = uniq[counts == 1]
        verts = np.unique(tk)
        vb = np.unique(bnd)
        m = boundary_curves(P, tk) - 1
        out.append((len(tk), len(bnd), len(verts) - len(vb), m))
    return out
