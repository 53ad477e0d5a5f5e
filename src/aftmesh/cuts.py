"""Where ``generate(partitions=k)`` cuts a domain, and the part inputs the cuts make.

The boundary is discretized as a serial run would (the coupling to ``generate``'s
discretization is the first block below); the bounding box is bisected recursively by
straight lines placed by the integral of 1/h^2; each cut is discretized once by the
size field and ends on a boundary vertex; the faces of boundary + cuts are found on
their coarse CDT and handed to the part whose box holds most of their area.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._typing import DomainArg, SizeArg
from .mesh import Mesh

if TYPE_CHECKING:
    from .sizing import SizeField

    # a box (xmin, ymin, xmax, ymax)
    Box = tuple[float, float, float, float]

__all__ = ["Boundary", "coarse_cdt", "cut_pslg", "discretized_boundary", "part_inputs"]

SAMPLES = 256  # sampling grid per side for the expected-triangle integral
MARGIN = 0.02  # a cut stays this fraction of its box's side away from its ends


# ------------------------------------------------------------------------------------
# Coupling to aftmesh internals: the only place that knows how generate discretizes.
# After generate / boundary are restructured, adapt these two functions only.
# ------------------------------------------------------------------------------------
@dataclass
class Boundary:
    points: np.ndarray  # discretized boundary vertices (and fixed points)
    segments: np.ndarray  # pieces of the input edges
    markers: np.ndarray  # Mesh.segment_markers of each piece
    triangles: np.ndarray  # a triangulation of the domain on those vertices
    regions: np.ndarray  # its region labels (the serial mesh's numbering)
    field: Callable  # the graded size field, callable f(x, y)


def discretized_boundary(domain: DomainArg, size: SizeArg, options: dict) -> Boundary:
    """The boundary split by the size exactly as ``generate`` splits it, and the
    graded size field: a greedy run (no interior point) yields both."""
    from .generate import generate

    keep = {
        k: options[k]
        for k in ("split_boundary", "gradation", "repair", "tolerance")
        if k in options
    }
    m = generate(domain, size, greedy=True, smooth=0, **keep)
    return Boundary(
        m.points,
        m.segments,
        np.asarray(m.segment_markers),
        m.triangles,
        m.regions,
        m.info["size_field"],
    )


def split_by_size(p0: np.ndarray, p1: np.ndarray, field: SizeField) -> np.ndarray:
    """The points strictly between p0 and p1 that split the segment for the size,
    by the rule that splits the input edges."""
    from .boundary import discretize

    verts, _, _ = discretize(
        np.array([p0, p1], dtype=np.float64), np.array([[0, 1]]), np.zeros(1, dtype=np.int32), field
    )
    return verts[2:]


# ------------------------------------------------------------------------------------


class _Locator:
    """Which region (if any) holds each point: one prepared polygon per region, the
    union of the boundary triangulation's triangles of that region (a point tree over
    those triangles would be slow: a greedy triangulation is made of long slivers)."""

    def __init__(self, b: Boundary):
        tri = shapely.polygons(b.points[b.triangles])
        self.labels = np.unique(b.regions)
        self.polygons = [shapely.coverage_union_all(tri[b.regions == r]) for r in self.labels]
        for poly in self.polygons:
            shapely.prepare(poly)

    def __call__(self, xy: np.ndarray):
        inside = np.zeros(len(xy), dtype=bool)
        label = np.zeros(len(xy), dtype=np.int64)
        for r, poly in zip(self.labels, self.polygons):
            hit = shapely.intersects_xy(poly, xy[:, 0], xy[:, 1]) & ~inside
            inside |= hit
            label[hit] = r
        return inside, label


def _bisect(box, xs, ys, w, k: int, insert, leaves: list) -> None:
    """Recursive bisection of box (x0, y0, x1, y1) into k boxes of equal weight;
    ``insert(axis, c, box)`` lays each cut and returns where it actually lies."""
    if k == 1:
        leaves.append(box)
        return
    k1 = k // 2
    axis = 0 if box[2] - box[0] >= box[3] - box[1] else 1
    lo, hi = box[axis], box[axis + 2]
    coord = xs if axis == 0 else ys
    inside = (xs >= box[0]) & (xs < box[2]) & (ys >= box[1]) & (ys < box[3])
    order = np.argsort(coord[inside], kind="stable")
    cum = np.cumsum(w[inside][order])
    if len(cum) and cum[-1] > 0:
        c = float(coord[inside][order][np.searchsorted(cum, cum[-1] * k1 / k)])
    else:
        c = 0.5 * (lo + hi)
    c = min(max(c, lo + MARGIN * (hi - lo)), hi - MARGIN * (hi - lo))
    c = insert(axis, c, box)
    first = (box[0], box[1], c, box[3]) if axis == 0 else (box[0], box[1], box[2], c)
    second = (c, box[1], box[2], box[3]) if axis == 0 else (box[0], c, box[2], box[3])
    _bisect(first, xs, ys, w, k1, insert, leaves)
    _bisect(second, xs, ys, w, k - k1, insert, leaves)


def plan_cuts(
    b: Boundary, locate: _Locator, k: int, insert: Callable[[int, float, Box], float]
) -> list[Box]:
    """Bisect the domain's box into k leaf boxes, laying each cut by ``insert``."""
    lo, hi = b.points.min(axis=0), b.points.max(axis=0)
    g = (np.arange(SAMPLES) + 0.5) / SAMPLES
    X, Y = np.meshgrid(lo[0] + g * (hi[0] - lo[0]), lo[1] + g * (hi[1] - lo[1]))
    xy = np.c_[X.ravel(), Y.ravel()]
    inside, _ = locate(xy)
    h = np.asarray(b.field(xy[:, 0], xy[:, 1]), dtype=np.float64)
    w = np.where(inside, 1.0 / (h * h), 0.0)
    leaves: list = []
    _bisect((lo[0], lo[1], hi[0], hi[1]), xy[:, 0], xy[:, 1], w, k, insert, leaves)
    return leaves


def _insert_cut(P: list, S: list, axis: int, c: float, box, field, locate) -> float:
    """Add the pieces of the line {x_axis = c} inside box and inside the domain to
    the PSLG (P: list of point arrays, S: list of segment arrays), each crossing of
    an existing piece moved to that piece's nearer end.  Returns c, moved by an ulp
    or so if it ran through a vertex."""
    pts = np.concatenate(P)
    seg = np.concatenate(S)
    while (pts[:, axis] == c).any():  # the line through no vertex
        c = float(np.nextafter(c, np.inf))
    other = 1 - axis
    a, b = pts[seg[:, 0]], pts[seg[:, 1]]
    da, db = a[:, axis] - c, b[:, axis] - c
    cross = np.flatnonzero((da < 0) != (db < 0))
    t = da[cross] / (da[cross] - db[cross])
    ya, yb = a[cross, other], b[cross, other]
    y = np.where(ya == yb, ya, ya + t * (yb - ya))
    # the box's sides inside the domain are cuts already laid, which bend where
    # they end on a boundary vertex: look for crossings a size beyond the box
    ends = np.zeros((2, 2))
    ends[:, axis] = c
    ends[:, other] = box[other], box[other + 2]
    reach = float(np.max(field(ends[:, 0], ends[:, 1])))
    lo, hi = box[other], box[other + 2]
    keep = (y >= lo - reach) & (y <= hi + reach)
    snap = np.where(t <= 0.5, seg[cross, 0], seg[cross, 1])[keep]
    y = y[keep]
    order = np.argsort(y, kind="stable")
    y, snap = y[order], snap[order]
    if len(y) < 2:
        return c
    mid = np.zeros((len(y) - 1, 2))
    mid[:, axis] = c
    mid[:, other] = 0.5 * (y[1:] + y[:-1])
    inside, _ = locate(mid)
    inside &= (mid[:, other] >= lo) & (mid[:, other] <= hi) & (y[1:] > y[:-1])
    n_pts = len(pts)
    for i in np.flatnonzero(inside):
        p0, p1 = np.empty(2), np.empty(2)
        p0[axis] = p1[axis] = c
        p0[other], p1[other] = y[i], y[i + 1]
        inner = split_by_size(p0, p1, field)
        inner[:, axis] = c
        if len(inner) == 0 and snap[i] == snap[i + 1]:
            continue
        ids = np.arange(n_pts, n_pts + len(inner))
        n_pts += len(inner)
        chain = np.concatenate([[snap[i]], ids, [snap[i + 1]]])
        P.append(inner)
        S.append(np.c_[chain[:-1], chain[1:]])
    return c


def _faces(C: Mesh):
    """Face id of each triangle of the coarse CDT C (triangles joined across edges
    that are not segments), and whether each half-edge (t, k) is a segment."""
    T, N = C.triangles, C.neighbors
    n = max(len(C.points), 1)
    seg_key = np.sort(
        np.minimum(C.segments[:, 0], C.segments[:, 1]).astype(np.int64) * n
        + np.maximum(C.segments[:, 0], C.segments[:, 1])
    )
    a, b = T[:, [1, 2, 0]].astype(np.int64), T[:, [2, 0, 1]].astype(np.int64)
    key = np.minimum(a, b) * n + np.maximum(a, b)
    pos = np.minimum(np.searchsorted(seg_key, key), len(seg_key) - 1)
    is_seg = seg_key[pos] == key
    links = np.where(is_seg, -1, N).tolist()
    face = [-1] * len(T)
    n_faces = 0
    for start in range(len(T)):
        if face[start] >= 0:
            continue
        face[start] = n_faces
        stack = [start]
        while stack:
            for u in links[stack.pop()]:
                if u >= 0 and face[u] < 0:
                    face[u] = n_faces
                    stack.append(u)
        n_faces += 1
    return np.array(face, dtype=np.int64), n_faces, is_seg


def _face_owners(C: Mesh, face, n_faces, leaves, locate):
    """Per face: a probe point strictly inside, its part (the leaf box holding most
    of its area), whether it is inside the domain and its region label."""
    p = C.points[C.triangles]
    centroid = p.mean(axis=1)
    area = 0.5 * np.abs(
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )
    box = np.zeros(len(centroid), dtype=np.int64)
    for i, (x0, y0, x1, y1) in enumerate(leaves):
        box[
            (centroid[:, 0] >= x0)
            & (centroid[:, 1] >= y0)
            & (centroid[:, 0] <= x1)
            & (centroid[:, 1] <= y1)
        ] = i
    votes = np.zeros((n_faces, len(leaves)))
    np.add.at(votes, (face, box), area)
    owner = votes.argmax(axis=1)
    best = np.full(n_faces, -1)
    order = np.argsort(area, kind="stable")
    best[face[order]] = order  # the largest triangle wins
    probes = centroid[best]
    inside, label = locate(probes)
    return probes, owner, inside, label


def part_inputs(
    C: Mesh, leaves: list[Box], locate: _Locator
) -> tuple[list[dict], list[np.ndarray]]:
    """One Triangle-style dict per non-empty part: its vertices and segments, a
    region point per face it meshes, a hole point per other face it encloses; and
    the coarse ids of each part's vertices."""
    face, n_faces, is_seg = _faces(C)
    probes, owner, inside, label = _face_owners(C, face, n_faces, leaves, locate)
    T = C.triangles
    a, b = T[:, [1, 2, 0]], T[:, [2, 0, 1]]
    on_seg = np.zeros(len(C.points), dtype=bool)
    on_seg[C.segments.ravel()] = True
    out, ids = [], []
    for p in range(len(leaves)):
        mine = (owner == p) & inside
        tri_mine = mine[face]
        if not tri_mine.any():
            continue
        sel = is_seg & tri_mine[:, None]
        segs = np.unique(np.sort(np.c_[a[sel], b[sel]], axis=1), axis=0)
        lone = np.setdiff1d(np.unique(T[tri_mine]), np.flatnonzero(on_seg))
        used = np.union1d(segs.ravel(), lone)
        local = np.searchsorted(used, segs)
        pts = C.points[used]
        others = probes[~mine]
        if len(others):
            cover = coarse_cdt(pts, local)
            tree = shapely.STRtree(shapely.polygons(cover.points[cover.triangles]))
            hit = np.unique(tree.query(shapely.points(others), predicate="intersects")[0])
            others = others[hit]
        regions = np.c_[probes[mine], label[mine]]
        out.append(
            {"vertices": pts, "segments": local, "holes": others.reshape(-1, 2), "regions": regions}
        )
        ids.append(used)
    return out, ids


def coarse_cdt(points: np.ndarray, segments: np.ndarray) -> Mesh:
    """The CDT of boundary + cuts, whose faces become the parts."""
    from .cdt import cdt

    return cdt(points, segments)


def cut_pslg(b: Boundary, k: int) -> tuple[np.ndarray, np.ndarray, list, _Locator]:
    """Boundary + cuts as (points, segments, leaves, locator)."""
    locate = _Locator(b)
    P, S = [b.points], [b.segments.astype(np.int64)]
    leaves = plan_cuts(
        b, locate, k, lambda axis, c, box: _insert_cut(P, S, axis, c, box, b.field, locate)
    )
    pts = np.concatenate(P)
    seg = np.unique(np.sort(np.concatenate(S), axis=1), axis=0)
    return pts, seg, leaves, locate
