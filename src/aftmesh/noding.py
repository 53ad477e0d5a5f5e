"""Noding and repair of a planar straight-line graph (PSLG).

The input adapters (:mod:`aftmesh.inputs`) hand over rings and lines as vertices and
segments; this module makes them a proper PSLG: coincident vertices merged, every
segment split at the vertices lying on it (exactly, or within rounding for a line's
free end, see :func:`snap_tolerance`), segments given twice dropped, and crossings
noded.  Each segment carries ``src``, the index of the input edge it is a piece of, so
every piece can be traced back to what the user drew.
"""

from __future__ import annotations

import numpy as np
import shapely

from ._kernel import (
    CollinearError,
    CrossingError,
    Triangulation,
    py_orient2d,
    rings_proper,
    segments_cross,
    unique_points,
    vertices_near_segments_pairs,
)
from ._order import brio_order
from .errors import CrossingSegmentsError

# shapely's type id of a Point
POINT_TYPE = 0

__all__ = [
    "snap_tolerance",
    "merge_and_node",
    "node_crossings",
    "vertices_first",
    "split_at_vertices",
    "refuse_crossings",
]

# The rounding of a + t (b - a) in ulps of the largest coordinate: b - a (up to twice
# that coordinate) rounds by 1, the product and the sum by 1/2 and 1 more per
# coordinate, and the two coordinates' errors add up across the line: about 3.5.
SNAP_ULPS = 4.0
# Segments still crossing after this many rounds of noding are left for the CDT to
# report: each round only bends pieces by an ulp, so one or two rounds suffice.
NODING_ROUNDS = 8
# Relative reach of the candidate search for vertices on segments: a floating-point
# distance may miss a point exactly on a segment but not representable on its line,
# so candidates are gathered this near and then decided exactly.
CANDIDATE_REACH = 1e-12
# Relative error bound of a floating-point orientation of double inputs: Shewchuk's
# (3 + 16 eps) eps for the first stage, taken four times over for margin.
ORIENT_ERROR = 4 * (3 + 16 * 2.0**-53) * 2.0**-53
# Below this the orientation's terms may have lost precision by underflow.
ORIENT_TINY = 1e-280
# Valid rings with at most this many (vertex, segment) pairs are checked for touching
# pairwise in the kernel (about 1.2 ns a pair), which costs less than the tree search
# of split_at_vertices up to there (measured: 0.3 ms against 1.2 ms at 500 vertices).
PROPER_CHECK_PAIRS = 250_000


def snap_tolerance(pts: np.ndarray) -> float:
    """How near a vertex must be to a segment to count as lying on it:
    SNAP_ULPS units in the last place (ulps) of the largest coordinate.  Points
    computed from the input (a line's end at a + t (b - a), a crossing point, the
    points that split an edge for the size) are off their segment's line by that much
    at most, so a vertex that near an edge may land on either side of it or of the
    pieces it is split into; splitting the edge at the vertex bends it by no more than
    that and removes the ambiguity.  Only free line ends and lone points are snapped:
    a ring's corner stays, so no gap a valid polygon has on purpose is closed."""
    if len(pts) == 0:
        return 0.0
    return SNAP_ULPS * float(np.spacing(np.abs(pts).max()))


def merge_and_node(
    verts: np.ndarray,
    segs: np.ndarray,
    src: np.ndarray,
    note: list[str],
    ring_source: np.ndarray | None,
    tolerance: float = 0.0,
    report: dict | None = None,
    valid_rings: int = 0,
    apart: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Make the input edges a proper PSLG: merge coincident vertices, split every
    segment at the input vertices lying on it or within rounding of it (a hole touching
    the outer ring, a T-junction between regions, a constraint line ending on a
    boundary), drop segments given twice (a boundary shared by two regions), and split
    segments that cross each other at their crossing points.

    With `tolerance` > 0, vertices closer than that are merged first (see
    :func:`merge_close`) and a line's free end or bend that near a segment splits it
    there; ``report`` then receives the counts ``merged`` and ``snapped``.

    `valid_rings` > 0 says the segments are exactly the rings of one polygon (or of
    the parts of one multipolygon) that shapely found valid, that many rings: then
    no two segments cross (validity forbids it, decided with exact predicates as the
    crossing search would), so the search is skipped; with one ring, no vertex lies
    on another segment either (the ring is simple, and a ring's vertex is never
    snapped), so the split is skipped, and so is the search for repeated segments;
    with several small rings, a pairwise look in the kernel says whether any of that
    is needed at all (rings touching at a point are rare).  `apart` says more: the
    valid rings meet nowhere but at common vertices, which the merge joins (the kernel
    proved it, inputs.proved_polygon), so nothing else is needed, however many rings
    there are."""
    n_merged = 0
    if tolerance > 0:
        verts, n_merged = merge_close(verts, tolerance)
        if n_merged:
            note.append(f"merged {n_merged} vertices within tolerance {tolerance:g} of another")
    uniq, inverse = unique_rows(verts)
    segs = inverse[segs]
    exact_valid = valid_rings and not tolerance > 0
    if exact_valid and (valid_rings == 1 or apart):
        # one simple ring of at least three distinct vertices, or rings apart but for
        # common vertices (now merged): no vertex on another segment, no segment
        # given twice or from a vertex to itself, no crossing
        return uniq, segs, src
    if exact_valid and len(uniq) * len(segs) <= PROPER_CHECK_PAIRS and rings_proper(uniq, segs):
        # the rings of a valid polygon that touch nowhere (the usual polygon with
        # holes): no split, no repeated segment, no crossing
        return uniq, segs, src
    tol = max(snap_tolerance(uniq), tolerance)
    counts = {"snapped": 0}
    segs, src = split_at_vertices(uniq, segs, src, note, tol, ring_source, counts)
    segs, src = _drop_repeats(segs, src)
    if exact_valid:
        out = uniq, segs, src
    else:
        out = node_crossings(uniq, segs, src, note, tol, ring_source=ring_source)
    if report is not None and tolerance > 0:
        report.update(merged=n_merged, snapped=counts["snapped"])
    return out


def _proved_uncrossed(verts: np.ndarray, segs: np.ndarray) -> bool:
    """The kernel's grid test (crossings.pxi) proves that no two segments cross at a
    point inside both, as a round of node_crossings would find (shapely's "crosses" on
    segments split at every vertex on them): the round would change nothing, so its
    tree search and relate tests are skipped."""
    if len(segs) < 2:
        return True
    xy = np.ascontiguousarray(verts, dtype=np.float64)
    return segments_cross(xy, np.ascontiguousarray(segs, dtype=np.int64)) == 0


def unique_rows(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(pts, axis=0, return_inverse=True)`` (the distinct points in
    lexicographic order, and each point's index among them) from one compiled stable
    sort, without np.unique's cost.  Finite points only; and where two copies of a
    point differ in their bits (0.0 and -0.0) np.unique itself decides which is kept."""
    pts = np.ascontiguousarray(pts, dtype=np.float64)
    found = unique_points(pts)
    if found is not None:
        first, inverse = found
        return pts[first], inverse.astype(np.intp, copy=False)
    uniq, inv = np.unique(pts, axis=0, return_inverse=True)
    return uniq, inv.reshape(-1)


def merge_close(verts: np.ndarray, tolerance: float) -> tuple[np.ndarray, int]:
    """Move every vertex within `tolerance` of another onto the first vertex (in
    input order: rings before lines before points) of its cluster; clusters are
    closed under that relation, so a chain of near vertices becomes one.  Returns the
    new coordinates and how many vertices moved."""
    if len(verts) < 2:
        return verts, 0
    pts = shapely.points(verts)
    i, j = shapely.STRtree(pts).query(pts, predicate="dwithin", distance=tolerance)
    pairs = i < j
    parent = np.arange(len(verts))

    def root(v):
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for a, b in zip(i[pairs].tolist(), j[pairs].tolist()):
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    rep = np.array([root(v) for v in range(len(verts))])
    out = verts[rep]
    return out, int((out != verts).any(axis=1).sum())


def merge_close_segments(
    pts: np.ndarray, segs: np.ndarray, src: np.ndarray, note: list[str], tolerance: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """A dict's vertices merged within `tolerance` (see :func:`merge_close`), the
    segments renumbered, those that became points or repeats dropped.  Returns
    (vertices, segments, src, how many vertices moved)."""
    moved, n_merged = merge_close(pts, tolerance)
    if not n_merged:
        return pts, segs, src, 0
    note.append(f"merged {n_merged} vertices within tolerance {tolerance:g} of another")
    uniq, inverse = unique_rows(moved)
    segs, src = _drop_repeats(inverse[segs], np.asarray(src))
    return uniq, segs, src, n_merged


def _crossing_pairs(verts, segs):
    """The pairs (i < j) of segments that cross, in the order of shapely's STRtree
    query with the "crosses" predicate.  That predicate is slow (a full relate per
    pair), so it is asked only of the box-overlapping pairs that might cross: not of
    pairs sharing a vertex (two segments from one point meet only there, or overlap
    along a line: neither is a crossing), nor of pairs where one segment's ends are
    certainly on the same side of the other's line (see _same_side)."""
    lines = shapely.linestrings(np.stack([verts[segs[:, 0]], verts[segs[:, 1]]], axis=1))
    pairs = shapely.STRtree(lines).query(lines)  # box overlaps, in the tree's order
    pairs = pairs[:, pairs[0] < pairs[1]]
    si, sj = segs[pairs[0]], segs[pairs[1]]
    shared = (si[:, :1] == sj).any(axis=1) | (si[:, 1:] == sj).any(axis=1)
    a, b, c, d = verts[si[:, 0]], verts[si[:, 1]], verts[sj[:, 0]], verts[sj[:, 1]]
    maybe = ~shared & ~_same_side(a, b, c, d) & ~_same_side(c, d, a, b)
    pairs = pairs[:, maybe]
    return lines, pairs[:, shapely.crosses(lines[pairs[0]], lines[pairs[1]])]


def _same_side(a, b, c, d) -> np.ndarray:
    """Whether c and d are certainly strictly on the same side of line a-b: both
    floating-point orientations are beyond a bound on their rounding error (a few
    times Shewchuk's first-stage bound), so any exact predicate agrees."""
    ab = b - a

    def orient(p):
        left = ab[:, 0] * (p[:, 1] - a[:, 1])
        right = ab[:, 1] * (p[:, 0] - a[:, 0])
        det = left - right
        sure = np.abs(det) > ORIENT_ERROR * (np.abs(left) + np.abs(right))
        # a bound relative to the terms means nothing once they underflow
        sure &= np.abs(left) + np.abs(right) > ORIENT_TINY
        return np.where(sure, np.sign(det), 0.0)

    with np.errstate(over="ignore", invalid="ignore"):
        oc, od = orient(c), orient(d)
    return oc * od > 0


def node_crossings(
    verts: np.ndarray,
    segs: np.ndarray,
    src: np.ndarray,
    note: list[str] | None,
    tol: float | None = None,
    rounds: int = NODING_ROUNDS,
    ring_source: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split the segments that cross each other at their crossing points, until none
    cross.  A crossing point is rounded, so it is not exactly on either segment, but
    within an ulp of both: the two pieces of each segment bend by that much at most,
    and a bent piece may, rarely, cross another segment that passes just as near; so
    this repeats (a few rounds at most in practice).  Returns (vertices, segments,
    source); segments still crossing after `rounds` rounds are left for the CDT to
    report."""
    if tol is None:
        tol = snap_tolerance(verts)
    n_cut = 0
    for _ in range(rounds):
        if _proved_uncrossed(verts, segs):
            break
        lines, pairs = _crossing_pairs(verts, segs)
        if pairs.shape[1] == 0:
            break
        extra, cuts = _crossing_points(lines, pairs, len(verts))
        if not len(extra):
            break
        n_cut += pairs.shape[1]
        verts = np.concatenate([verts, extra])
        segs, src = _cut(verts, segs, src, cuts)
        verts, inverse = unique_rows(verts)
        segs = inverse[segs]
        segs, src = split_at_vertices(verts, segs, src, None, tol, ring_source)
        segs, src = _drop_repeats(segs, src)
    if n_cut and note is not None:
        note.append(f"split segments at {n_cut} crossings")
    return verts, segs, src


def _crossing_points(lines, pairs, base: int) -> tuple[np.ndarray, dict[int, list[int]]]:
    """The points where the crossing pairs of lines meet (all intersections in one
    vectorized call, pair by pair in order, each pair's points in GEOS's order), and
    for each segment the numbers of the points on it, counted on from `base`."""
    meet = shapely.intersection(lines[pairs[0]], lines[pairs[1]])
    parts, pair = shapely.get_parts(meet, return_index=True)
    is_point = shapely.get_type_id(parts) == POINT_TYPE
    extra = shapely.get_coordinates(parts[is_point]).reshape(-1, 2)
    cuts: dict[int, list[int]] = {}
    for n, k in enumerate(pair[is_point].tolist()):
        cuts.setdefault(int(pairs[0, k]), []).append(base + n)
        cuts.setdefault(int(pairs[1, k]), []).append(base + n)
    return extra, cuts


def _cut(pts, segs, src, cuts):
    """Replace each segment k in `cuts` by the chain through the vertices cuts[k],
    ordered along it (the segments not cut are copied as they are, in bulk)."""
    chains = {k: _chain(pts, segs[k], cuts[k]) for k in sorted(cuts)}
    rows = np.ones(len(segs), dtype=np.int64)
    for k, chain in chains.items():
        rows[k] = len(chain) - 1
    out_s = np.repeat(np.asarray(segs, dtype=np.int64), rows, axis=0)
    out_src = np.repeat(np.asarray(src, dtype=np.int64), rows)
    start = np.cumsum(rows) - rows
    for k, chain in chains.items():
        out_s[start[k] : start[k] + rows[k]] = np.c_[chain[:-1], chain[1:]]
    return out_s, out_src


def _chain(pts, seg, on: list[int]) -> list[int]:
    """The segment's ends with the vertices `on` it between them, ordered along it."""
    a, b = int(seg[0]), int(seg[1])
    # order the cut points along the segment by the coordinate along which it runs
    # furthest, then the other: comparing coordinates is exact, whereas a dot
    # product would round away the order of points closer than its ulp
    d = pts[b] - pts[a]
    major = 0 if abs(d[0]) >= abs(d[1]) else 1
    sign = np.where(d >= 0, 1.0, -1.0)
    inner = sorted(
        set(on) - {a, b},
        key=lambda v: (sign[major] * pts[v][major], sign[1 - major] * pts[v][1 - major]),
    )
    return [a, *inner, b]


def _drop_repeats(segs, src):
    """The segments without those given twice (either way round; the first copy
    stays) and without those from a vertex to itself, in input order."""
    key = np.sort(segs, axis=1)
    keep = key[:, 0] != key[:, 1]
    # one integer per vertex pair, ordered as the pairs are (indices are below 2**31)
    pair = key[:, 0].astype(np.int64) * (int(key[:, 1].max(initial=0)) + 1) + key[:, 1]
    _, first = np.unique(pair, return_index=True)
    first = np.sort(first[keep[first]])
    return segs[first], src[first]


def split_at_vertices(
    pts: np.ndarray,
    segs: np.ndarray,
    src: np.ndarray,
    note: list[str] | None,
    tol: float = 0.0,
    ring_source: np.ndarray | None = None,
    counts: dict | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Split each segment at the vertices lying on its interior: exactly (decided with
    the exact orientation predicate), or, for a vertex on no polygon ring (a line's end
    or bend, a lone point), within `tol` of it (see snap_tolerance).  ring_source[s]
    says whether source s is a ring; without it, only vertices with at most one
    segment are snapped.  ``counts['snapped']``, if given, counts the near splits."""
    if len(segs) == 0:
        return segs, src
    segs = np.asarray(segs)
    reach = max(tol, CANDIDATE_REACH * float(np.abs(pts).max() + 1.0))
    # candidates from the kernel's grid search (nearby.pxi): every vertex within reach
    # of a segment other than its own ends, and a few a little farther
    vi, si = vertices_near_segments_pairs(
        np.ascontiguousarray(pts, dtype=np.float64),
        np.ascontiguousarray(segs, dtype=np.int64),
        reach,
    )
    cuts: dict[int, list[int]] = {}
    if ring_source is None:
        fixed = np.bincount(segs.ravel(), minlength=len(pts)) > 1
    else:
        fixed = np.zeros(len(pts), dtype=bool)
        fixed[segs[ring_source[np.asarray(src)]].ravel()] = True
    for v, k in zip(vi.tolist(), si.tolist()):
        a, b = segs[k]
        pa, pb, pv = pts[a], pts[b], pts[v]
        if not (np.dot(pv - pa, pb - pa) > 0 and np.dot(pv - pb, pa - pb) > 0):
            continue
        if py_orient2d(pa[0], pa[1], pb[0], pb[1], pv[0], pv[1]) != 0:
            d = pb - pa
            cross = d[0] * (pv[1] - pa[1]) - d[1] * (pv[0] - pa[0])
            if not abs(cross) <= tol * float(np.hypot(d[0], d[1])):
                continue
            # near, not on: a constraint line's vertex (or a lone point) is meant to
            # be on the segment, as in a crack ending on the boundary at a computed
            # point.  A ring's corner is not: a valid polygon may have a hole an ulp
            # from its outer ring or a needle an ulp wide, and snapping would close
            # the gap or fold the needle, so it stays (generate drops split points
            # that near it, see boundary.discretize).
            if fixed[v]:
                continue
            if counts is not None:
                counts["snapped"] += 1
        cuts.setdefault(k, []).append(v)
    if not cuts:
        return segs, src
    if note is not None:
        note.append(f"split {len(cuts)} segments at vertices lying on them")
    return _cut(pts, segs, src, cuts)


def refuse_crossings(pts: np.ndarray, seg: np.ndarray) -> None:
    """Dict / .poly input: segments crossing at a point inside both are refused (the
    policy of aftmesh.cdt), before any size-dependent splitting could hide them.

    The kernel finds them: a grid test of the pairs of nearby segments proves most
    inputs free of any (exact orientations), and otherwise the Delaunay triangulation
    of the points, then the segments inserted one by one as constrained edges (a
    segment running through a vertex is split there, which is no crossing), names the
    first."""
    if len(seg) < 2:
        return
    xy = np.ascontiguousarray(pts, dtype=np.float64)
    if segments_cross(xy, np.ascontiguousarray(seg, dtype=np.int64)) == 0:
        return  # proved free of crossings, without a CDT
    kernel = Triangulation(pts)
    try:
        merged = kernel.insert_points(brio_order(pts))
    except CollinearError:
        return  # all on one line: segments may overlap there, never cross
    try:
        kernel.insert_segments(np.ascontiguousarray(merged[seg], dtype=np.int32))
    except CrossingError as err:
        i, j = sorted((int(err.index), int(err.blocker_segment)))
        if i < 0:  # cannot happen: every constrained edge here is a piece of an input one
            raise CrossingSegmentsError(
                f"segments[{j}] = {seg[j].tolist()} crosses another segment", (j,)
            ) from None
        raise CrossingSegmentsError(
            f"segments[{i}] = {seg[i].tolist()} ({pts[seg[i, 0]].tolist()} -> "
            f"{pts[seg[i, 1]].tolist()}) crosses segments[{j}] = {seg[j].tolist()} "
            f"({pts[seg[j, 0]].tolist()} -> {pts[seg[j, 1]].tolist()})",
            (i, j),
        ) from None


def vertices_first(
    first: np.ndarray, verts: np.ndarray, segs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The same PSLG (verts, segs) numbered with the points `first` (each one of the
    vertices, as node_crossings keeps every input coordinate exactly) as vertices
    0..len(first)-1, in their order, and the others after them in theirs.  Callers
    number the input vertices first (the minimum-angle pass takes them for the ends
    of the segment chains), and node_crossings numbers all in lexicographic order."""
    index = {p: i for i, p in enumerate(map(tuple, verts.tolist()))}
    head = [index.get(p, -1) for p in map(tuple, np.asarray(first).tolist())]
    if -1 in head:  # not kept exactly after all: no numbering to restore
        return verts, segs
    taken = np.zeros(len(verts), dtype=bool)
    taken[head] = True
    order = np.concatenate([np.array(head, dtype=np.int64), np.flatnonzero(~taken)])
    renumber = np.empty(len(verts), dtype=np.int64)
    renumber[order] = np.arange(len(verts))
    return verts[order], renumber[segs].astype(segs.dtype)
