"""Random planar straight-line graphs (PSLGs) for the tests, from seeded numpy RNGs.

Every generator returns a dict with ``vertices`` (n, 2) float64, ``segments`` (m, 2)
int (possibly empty), ``holes`` (h, 2), ``regions`` (r, 3) rows (x, y, marker) and
``area``: the area of the domain the PSLG bounds (``None`` for bare point sets, whose
domain is the convex hull), computed with shapely, independently of aftmesh.

The inputs are in general position with probability one (random doubles): no four
points cocircular, no three collinear, and the segments do not cross (checked with a
margin, so no pair is anywhere near crossing or touching).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree
from shapely.geometry import LineString, Point, Polygon


def _orient(p, q, r):
    """Floating-point orientation of (p, q, r), broadcast over rows."""
    return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (
        r[..., 0] - p[..., 0]
    )


def add_noncrossing_segments(rng, pts, n_wanted, existing=(), k_near=12, margin=1e-9, allowed=None):
    """Pick up to ``n_wanted`` segments between points of ``pts`` (pairs of a point and
    one of its ``k_near`` nearest neighbours) that neither cross nor nearly touch each
    other or the ``existing`` ones.  ``allowed(i, j)`` may veto a pair."""
    pts = np.asarray(pts, dtype=np.float64)
    segs = [tuple(s) for s in existing]
    used = {frozenset(s) for s in segs}
    tree = cKDTree(pts)
    k = min(k_near + 1, len(pts))
    _, nbrs = tree.query(pts, k=k)
    tries = 0
    while len(segs) - len(existing) < n_wanted and tries < 20 * n_wanted + 50:
        tries += 1
        i = int(rng.integers(len(pts)))
        j = int(nbrs[i, rng.integers(1, k)])
        if i == j or frozenset((i, j)) in used:
            continue
        if allowed is not None and not allowed(i, j):
            continue
        if segs:
            S = np.asarray(segs)
            p, q = pts[i], pts[j]
            a, b = pts[S[:, 0]], pts[S[:, 1]]
            shared = (S == i).any(axis=1) | (S == j).any(axis=1)
            scale = max(np.ptp(pts[:, 0]), np.ptp(pts[:, 1])) ** 2
            o1, o2 = _orient(p, q, a), _orient(p, q, b)
            o3, o4 = _orient(a, b, p), _orient(a, b, q)
            near = np.minimum.reduce([abs(o1), abs(o2), abs(o3), abs(o4)]) < margin * scale
            cross = (o1 * o2 < 0) & (o3 * o4 < 0)
            if ((cross | near) & ~shared).any():
                continue
            # segments sharing an endpoint must not overlap (never with random points,
            # but be safe): the other ends must not be collinear with this one
            if (
                shared
                & (np.minimum(abs(o1), abs(o2)) < margin * scale)
                & (np.maximum(abs(o1), abs(o2)) < margin * scale)
            ).any():
                continue
        # no other point may lie (nearly) on the new segment
        p, q = pts[i], pts[j]
        d = q - p
        L2 = d @ d
        t = ((pts - p) @ d) / L2
        dist2 = (_orient(p, q, pts) ** 2) / L2
        on = (t > -1e-9) & (t < 1 + 1e-9) & (dist2 < (1e-9) ** 2 * L2)
        on[[i, j]] = False
        if on.any():
            continue
        segs.append((i, j))
        used.add(frozenset((i, j)))
    return np.asarray(segs, dtype=np.int64).reshape(-1, 2)


def random_points(rng, n, kind="uniform"):
    """A bare point set (domain: its convex hull)."""
    if kind == "uniform":
        pts = rng.random((n, 2))
    elif kind == "gauss":
        pts = rng.normal(size=(n, 2))
    elif kind == "clusters":
        centres = rng.random((max(2, n // 50), 2)) * 10
        pts = centres[rng.integers(len(centres), size=n)] + rng.normal(scale=0.05, size=(n, 2))
    elif kind == "anisotropic":
        pts = rng.random((n, 2)) * np.array([1000.0, 0.01])
    elif kind == "disk":
        r = np.sqrt(rng.random(n))
        a = rng.random(n) * 2 * np.pi
        pts = np.c_[r * np.cos(a), r * np.sin(a)]
    else:
        raise ValueError(kind)
    return dict(
        vertices=pts,
        segments=np.zeros((0, 2), np.int64),
        holes=np.zeros((0, 2)),
        regions=np.zeros((0, 3)),
        area=None,
    )


def box_with_segments(rng, n_points, n_segments, k_near=12):
    """The unit square (as a ring of 4 segments) holding random points and random
    non-crossing segments among them (dangling segments, open chains)."""
    inner = 0.02 + 0.96 * rng.random((n_points, 2))
    pts = np.vstack([[(0, 0), (1, 0), (1, 1), (0, 1)], inner])
    ring = [(0, 1), (1, 2), (2, 3), (3, 0)]
    segs = add_noncrossing_segments(
        rng, pts, n_segments, existing=ring, k_near=k_near, allowed=lambda i, j: i >= 4 and j >= 4
    )
    return dict(
        vertices=pts, segments=segs, holes=np.zeros((0, 2)), regions=np.zeros((0, 3)), area=1.0
    )


def star_ring(rng, centre, rmin, rmax, k):
    """k vertices of a random star-shaped polygon around ``centre``, counter-clockwise."""
    # jittered equal angles: every angular gap is within 0.7..1.3 of 2 pi / k, below pi
    # for k >= 3, so the polygon is star-shaped about ``centre`` (strictly inside it)
    step = 2 * np.pi / k
    ang = np.arange(k) * step + rng.random() * 2 * np.pi + (rng.random(k) - 0.5) * 0.3 * step
    r = rmin + (rmax - rmin) * rng.random(k)
    return np.c_[centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang)]


def _ring_segments(start, k):
    return [(start + i, start + (i + 1) % k) for i in range(k)]


def polygon_with_holes(rng, n_outer=None, n_inner_rings=None, n_points=None, n_extra_segments=0):
    """A random star-shaped outer ring around the origin with small star-shaped inner
    rings; some inner rings are holes (a hole point at their centre), the others are
    sub-regions with a region marker.  Random points fill the domain.

    ``regions`` also marks the part between the rings (marker 1)."""
    n_outer = n_outer or int(rng.integers(8, 40))
    n_inner_rings = int(rng.integers(0, 5)) if n_inner_rings is None else n_inner_rings
    n_points = int(rng.integers(0, 300)) if n_points is None else n_points
    outer = star_ring(rng, (0.0, 0.0), 0.7, 1.0, n_outer)
    verts = [outer]
    segs = _ring_segments(0, n_outer)
    holes, regions, inner_polys, hole_polys = [], [], [], []
    # inner ring centres spread on a circle of radius 0.38 (radius up to 0.16 each, so
    # they stay apart, and inside the outer ring: with n_outer >= 8 its edges stay
    # beyond 0.7 * cos(1.3 pi / 8) > 0.6 from the origin)
    base = rng.random() * 2 * np.pi
    for k in range(n_inner_rings):
        a = base + 2 * np.pi * k / max(n_inner_rings, 1)
        c = (0.38 * np.cos(a), 0.38 * np.sin(a)) if n_inner_rings > 1 else (0.0, 0.0)
        kk = int(rng.integers(3, 16))
        ring = star_ring(rng, c, 0.06, 0.16, kk)
        start = sum(len(v) for v in verts)
        verts.append(ring)
        segs += _ring_segments(start, kk)
        poly = Polygon(ring)
        inner_polys.append(poly)
        if rng.random() < 0.6:
            holes.append(c)
            hole_polys.append(poly)
        else:
            regions.append((c[0], c[1], 10 + k))
    domain = Polygon(outer, [np.asarray(p.exterior.coords) for p in hole_polys])
    # random points in the outer ring's bounding disk, kept if strictly inside the
    # domain and well away from every ring
    cand = rng.random((4 * n_points + 10, 2)) * 2 - 1
    rings_boundary = Polygon(outer).boundary
    for p in inner_polys:
        rings_boundary = rings_boundary.union(p.boundary)
    keep = []
    for xy in cand:
        if len(keep) >= n_points:
            break
        pt = Point(xy)
        if domain.contains(pt) and rings_boundary.distance(pt) > 1e-3:
            keep.append(xy)
    verts.append(np.asarray(keep).reshape(-1, 2))
    pts = np.vstack(verts)
    if n_extra_segments:
        # extra segments only among the free points, not touching any ring
        first_free = len(pts) - len(keep)
        ring_segs = np.asarray(segs)
        rings_geom = rings_boundary

        def allowed(i, j):
            if i < first_free or j < first_free:
                return False
            return rings_geom.distance(LineString([pts[i], pts[j]])) > 1e-6

        segs = [
            tuple(s)
            for s in add_noncrossing_segments(
                rng, pts, n_extra_segments, existing=ring_segs, allowed=allowed
            )
        ]
    # region marker 1 for the part between the rings: a point of the domain minus the
    # inner rings
    between = Polygon(outer, [np.asarray(p.exterior.coords) for p in inner_polys])
    rp = between.representative_point()
    if rings_boundary.distance(rp) > 1e-6:
        regions.append((rp.x, rp.y, 1))
    return dict(
        vertices=pts,
        segments=np.asarray(segs, dtype=np.int64).reshape(-1, 2),
        holes=np.asarray(holes, dtype=np.float64).reshape(-1, 2),
        regions=np.asarray(regions, dtype=np.float64).reshape(-1, 3),
        area=domain.area,
    )


def nested_rings(rng, depth=None, n_points=None):
    """Concentric star-shaped rings around the origin, the annuli alternately kept and
    removed by hole points; the innermost disk is kept.  Random points in the kept
    annuli."""
    depth = int(rng.integers(2, 7)) if depth is None else depth
    n_points = int(rng.integers(0, 200)) if n_points is None else n_points
    radii = np.linspace(1.0, 0.15, depth)
    gap = radii[0] - radii[1] if depth > 1 else 0.5
    verts, segs, rings = [], [], []
    start = 0
    for R in radii:
        k = int(rng.integers(12, 40))
        # keep each ring within [R - 0.3 min(gap, R), R]: rings cannot touch
        ring = star_ring(rng, (0.0, 0.0), R - 0.3 * min(gap, R), R, k)
        verts.append(ring)
        segs += _ring_segments(start, k)
        start += k
        rings.append(Polygon(ring))
    holes, regions = [], []
    kept = []
    for d in range(depth):
        inner = rings[d + 1] if d + 1 < depth else None
        annulus = Polygon(
            rings[d].exterior.coords, [inner.exterior.coords] if inner is not None else []
        )
        rp = annulus.representative_point()
        if d % 2 == 1 and inner is not None:
            holes.append((rp.x, rp.y))
        else:
            kept.append(annulus)
            regions.append((rp.x, rp.y, 100 + d))
    area = sum(a.area for a in kept)
    boundary = rings[0].boundary
    for r in rings[1:]:
        boundary = boundary.union(r.boundary)
    pts_extra = []
    cand = rng.random((6 * n_points + 10, 2)) * 2 - 1
    for xy in cand:
        if len(pts_extra) >= n_points:
            break
        p = Point(xy)
        if any(a.contains(p) for a in kept) and boundary.distance(p) > 1e-3:
            pts_extra.append(xy)
    pts = np.vstack(verts + [np.asarray(pts_extra).reshape(-1, 2)])
    return dict(
        vertices=pts,
        segments=np.asarray(segs, dtype=np.int64),
        holes=np.asarray(holes, dtype=np.float64).reshape(-1, 2),
        regions=np.asarray(regions, dtype=np.float64).reshape(-1, 3),
        area=area,
    )
