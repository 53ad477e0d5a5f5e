"""Domain input -> a validated planar straight-line graph with regions.

Accepted forms (see :func:`aftmesh.generate`):

* a shapely ``Polygon`` or ``MultiPolygon`` (holes, parts touching at a point);
* a shapely ``GeometryCollection``: its polygons are the domain, its ``LineString`` /
  ``Point`` members inside them are internal constraints (cracks, interfaces, fixed
  nodes);
* a sequence of shapely polygons with disjoint interiors: a multi-region domain whose
  shared boundaries are discretized once; ``Mesh.regions`` is the index in the sequence;
* an (n, 2) array of coordinates: one polygon ring;
* a Triangle-style dict (``vertices``, ``segments``, ``holes``, ``regions``) or the
  path of a Triangle ``.poly`` file.

Clean-up done and reported in ``Mesh.info['cleanup']``: repeated vertices, a repeated
closing vertex, collinear runs, rings in either orientation, segments split at the
vertices lying on them (or within rounding of them, see :func:`snap_tolerance`) and at
their crossings.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from os import PathLike

import numpy as np
import shapely
from shapely.geometry import (GeometryCollection, LineString, MultiLineString, MultiPoint,
                              MultiPolygon, Point, Polygon)

from .errors import InvalidDomainError, InvalidInputError
from .pslg import as_points, as_segments, check_range

__all__ = ["Domain", "to_domain"]


@dataclass
class Domain:
    """A PSLG plus what is needed to mesh it.

    ``segment_source[k]`` numbers the input ring / constraint line segment k came from
    (``source_names`` says which; ``source_markers``, if the input had them, maps that
    number to the user's own segment marker); ``polygons`` classify the pieces cut out by the
    segments into regions (index in the list; outside all: not meshed).  Dict and
    ``.poly`` inputs instead carry Triangle's ``holes`` and ``region_points``."""

    vertices: np.ndarray
    segments: np.ndarray
    segment_source: np.ndarray
    source_names: list[str]
    polygons: list | None = None
    holes: np.ndarray | None = None
    region_points: np.ndarray | None = None
    area: float | None = None
    cleanup: list[str] = field(default_factory=list)
    source_markers: np.ndarray | None = None    # the user's marker of each source
    ring_source: np.ndarray | None = None       # whether each source is a polygon ring


def _is_coordinate_array(obj) -> bool:
    if isinstance(obj, (str, bytes, dict)) or isinstance(obj, shapely.Geometry):
        return False
    try:
        arr = np.asarray(obj, dtype=np.float64)
    except (TypeError, ValueError):
        return False
    return arr.ndim == 2 and arr.shape[1] == 2


def _polygon_parts(geom, where: str) -> list[Polygon]:
    if isinstance(geom, Polygon):
        return [geom]
    if isinstance(geom, MultiPolygon):
        return list(geom.geoms)
    raise InvalidDomainError(f"{where} is a {geom.geom_type}, expected a Polygon")


def _check_polygon(poly: Polygon, where: str) -> None:
    coords = np.asarray(poly.exterior.coords) if not poly.is_empty else np.zeros((0, 2))
    if poly.is_empty:
        raise InvalidDomainError(f"{where} is empty")
    for k, ring in enumerate([poly.exterior, *poly.interiors]):
        c = np.asarray(ring.coords)
        bad = ~np.isfinite(c).all(axis=1)
        if bad.any():
            name = "exterior ring" if k == 0 else f"hole {k - 1}"
            i = int(np.flatnonzero(bad)[0])
            raise InvalidDomainError(f"{where}, {name}: vertex {i} = {c[i].tolist()} is not finite")
    if not poly.is_valid:
        reason = shapely.is_valid_reason(poly)
        ring = "its rings"
        # name the ring that is invalid on its own, if one is
        if not Polygon(poly.exterior).is_valid:
            ring = "the exterior ring"
        else:
            for k, hole in enumerate(poly.interiors):
                if not Polygon(hole).is_valid:
                    ring = f"hole {k}"
                    break
                if not Polygon(poly.exterior).contains(Polygon(hole)):
                    ring = f"hole {k} (not inside the exterior ring)"
                    break
        raise InvalidDomainError(f"{where} is not a valid polygon ({ring}): {reason}")
    if not poly.area > 0:
        raise InvalidDomainError(f"{where} has zero area (vertices {coords[:4].tolist()}...)")


def _clean_ring(coords: np.ndarray, note: list[str], name: str, keep_collinear: bool):
    """Drop the closing duplicate, repeated vertices and (optionally) collinear runs."""
    c = np.asarray(coords, dtype=np.float64)
    n0 = len(c)
    keep = np.ones(len(c), dtype=bool)
    keep[1:] = (c[1:] != c[:-1]).any(axis=1)
    c = c[keep]
    while len(c) > 1 and (c[-1] == c[0]).all():     # the closing vertex, given or not
        c = c[:-1]
    removed = n0 - len(c) - (1 if n0 > 1 and (np.asarray(coords)[0] == np.asarray(coords)[-1]).all() else 0)
    if removed > 0:
        note.append(f"{name}: removed {removed} repeated vertices")
    if not keep_collinear and len(c) > 3:
        from ._kernel import py_orient2d
        changed = True
        removed = 0
        while changed and len(c) > 3:
            changed = False
            n = len(c)
            mask = np.ones(n, dtype=bool)
            for i in range(n):
                a, b, d = c[i - 1], c[i], c[(i + 1) % n]
                if mask[i - 1] and py_orient2d(a[0], a[1], b[0], b[1], d[0], d[1]) == 0 \
                        and np.dot(b - a, d - b) > 0:
                    mask[i] = False
                    removed += 1
                    changed = True
            c = c[mask]
        if removed:
            note.append(f"{name}: merged {removed} vertices of collinear runs")
    return c


def _from_shapely(polygons: list[Polygon], lines: list, points: list, names: list[str],
                  keep_vertices: bool) -> Domain:
    note: list[str] = []
    vertices: list[np.ndarray] = []
    segments: list[np.ndarray] = []
    sources: list[np.ndarray] = []
    source_names: list[str] = []
    ring_source: list[bool] = []
    offset = 0

    def add_chain(c: np.ndarray, closed: bool, name: str):
        nonlocal offset
        n = len(c)
        if n < 2:
            return
        idx = np.arange(n)
        seg = np.c_[idx, (idx + 1) % n] if closed else np.c_[idx[:-1], idx[1:]]
        vertices.append(c)
        segments.append(seg + offset)
        sources.append(np.full(len(seg), len(source_names)))
        source_names.append(name)
        ring_source.append(closed)
        offset += n

    for k, poly in enumerate(polygons):
        where = names[k]
        rings = [("exterior ring", poly.exterior)] + [
            (f"hole {i}", h) for i, h in enumerate(poly.interiors)]
        for rname, ring in rings:
            c = _clean_ring(np.asarray(ring.coords)[:, :2], note, f"{where}, {rname}",
                            keep_collinear=keep_vertices)
            add_chain(c, True, f"{where}, {rname}")
    for k, line in enumerate(lines):
        c = np.asarray(line.coords)[:, :2]
        keep = np.ones(len(c), dtype=bool)
        keep[1:] = (c[1:] != c[:-1]).any(axis=1)
        add_chain(c[keep], False, f"constraint line {k}")
    isolated = [np.asarray(p.coords)[:, :2] for p in points]
    if isolated:
        iso = np.concatenate(isolated)
        vertices.append(iso)
        offset += len(iso)
    verts = np.concatenate(vertices) if vertices else np.zeros((0, 2))
    segs = np.concatenate(segments) if segments else np.zeros((0, 2), dtype=np.int64)
    src = np.concatenate(sources) if sources else np.zeros(0, dtype=np.int64)
    rings = np.array(ring_source, dtype=bool)
    verts, segs, src = _merge_and_node(verts, segs, src, note, rings)
    union_area = float(shapely.union_all(polygons).area)
    return Domain(verts, segs.astype(np.int32), src.astype(np.int32), source_names,
                  polygons=polygons, area=union_area, cleanup=note, ring_source=rings)


def snap_tolerance(pts: np.ndarray) -> float:
    """How near a vertex must be to a segment to count as lying on it: two units in
    the last place (ulps) of the largest coordinate.  Points computed from the input (a
    line's end at a + t (b - a), a crossing point, the points that split an edge for
    the size) are off by up to about one such unit, so a vertex that near an edge may
    land on either side of it or of the pieces it is split into; splitting the edge at
    the vertex bends it by no more than that and removes the ambiguity.  (Larger, it
    would close gaps a valid polygon has on purpose; what it leaves, generate repairs
    after the discretization.)"""
    if len(pts) == 0:
        return 0.0
    return 2.0 * float(np.spacing(np.abs(pts).max()))


def _merge_and_node(verts, segs, src, note, ring_source):
    """Make the input edges a proper PSLG: merge coincident vertices, split every
    segment at the input vertices lying on it or within rounding of it (a hole touching
    the outer ring, a T-junction between regions, a constraint line ending on a
    boundary), drop segments given twice (a boundary shared by two regions), and split
    segments that cross each other at their crossing points."""
    uniq, inverse = np.unique(verts, axis=0, return_inverse=True)
    segs = inverse.reshape(-1)[segs]
    tol = snap_tolerance(uniq)
    segs, src = _split_at_vertices(uniq, segs, src, note, tol, ring_source)
    segs, src = _drop_repeats(segs, src)
    return node_crossings(uniq, segs, src, note, tol, ring_source=ring_source)


def _crossing_pairs(verts, segs):
    lines = shapely.linestrings(np.stack([verts[segs[:, 0]], verts[segs[:, 1]]], axis=1))
    pairs = shapely.STRtree(lines).query(lines, predicate="crosses")
    return lines, pairs[:, pairs[0] < pairs[1]]


def node_crossings(verts, segs, src, note, tol=None, rounds: int = 8, ring_source=None):
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
        if len(segs) < 2:
            break
        lines, pairs = _crossing_pairs(verts, segs)
        if pairs.shape[1] == 0:
            break
        base = len(verts)
        extra = []
        cuts: dict[int, list[int]] = {}
        for i, j in pairs.T:
            for p in shapely.get_parts(shapely.intersection(lines[i], lines[j])):
                if isinstance(p, Point):
                    extra.append(np.asarray(p.coords)[0, :2])
                    cuts.setdefault(int(i), []).append(base + len(extra) - 1)
                    cuts.setdefault(int(j), []).append(base + len(extra) - 1)
        if not extra:
            break
        n_cut += pairs.shape[1]
        verts = np.concatenate([verts, np.array(extra).reshape(-1, 2)])
        segs, src = _cut(verts, segs, src, cuts)
        verts, inverse = np.unique(verts, axis=0, return_inverse=True)
        segs = inverse.reshape(-1)[segs]
        segs, src = _split_at_vertices(verts, segs, src, None, tol, ring_source)
        segs, src = _drop_repeats(segs, src)
    if n_cut and note is not None:
        note.append(f"split segments at {n_cut} crossings")
    return verts, segs, src


def _cut(pts, segs, src, cuts):
    """Replace each segment k in `cuts` by the chain through the vertices cuts[k],
    ordered along it."""
    out_s, out_src = [], []
    for k in range(len(segs)):
        if k not in cuts:
            out_s.append(segs[k][None, :])
            out_src.append([src[k]])
            continue
        a, b = segs[k]
        # order the cut points along the segment by the coordinate along which it runs
        # furthest, then the other: comparing coordinates is exact, whereas a dot
        # product would round away the order of points closer than its ulp
        d = pts[b] - pts[a]
        major = 0 if abs(d[0]) >= abs(d[1]) else 1
        sign = np.where(d >= 0, 1.0, -1.0)
        inner = sorted(set(cuts[k]) - {a, b},
                       key=lambda v: (sign[major] * pts[v][major], sign[1 - major] * pts[v][1 - major]))
        chain = [a, *inner, b]
        out_s.append(np.c_[chain[:-1], chain[1:]])
        out_src.append([src[k]] * (len(chain) - 1))
    return (np.concatenate(out_s).astype(np.int64),
            np.concatenate([np.asarray(x) for x in out_src]).astype(np.int64))


def _drop_repeats(segs, src):
    key = np.sort(segs, axis=1)
    keep = key[:, 0] != key[:, 1]
    _, first = np.unique(key, axis=0, return_index=True)
    first = np.sort(first[keep[first]])
    return segs[first], src[first]


def _split_at_vertices(pts, segs, src, note, tol: float = 0.0, ring_source=None):
    """Split each segment at the vertices lying on its interior: exactly (decided with
    the exact orientation predicate), or, for a vertex on no polygon ring (a line's end
    or bend, a lone point), within `tol` of it (see snap_tolerance).  ring_source[s]
    says whether source s is a ring; without it, only vertices with at most one
    segment are snapped."""
    from ._kernel import py_orient2d
    if len(segs) == 0:
        return segs, src
    segs = np.asarray(segs)
    lines = shapely.linestrings(np.stack([pts[segs[:, 0]], pts[segs[:, 1]]], axis=1))
    # candidates: vertices within a tiny distance of a segment (shapely's own test may
    # miss a point that is exactly on the segment but not representable on its line)
    reach = max(tol, 1e-12 * float(np.abs(pts).max() + 1.0))
    vi, si = shapely.STRtree(lines).query(shapely.points(pts), predicate="dwithin", distance=reach)
    other = (vi != segs[si, 0]) & (vi != segs[si, 1])     # each segment finds its own ends
    vi, si = vi[other], si[other]
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
        cuts.setdefault(k, []).append(v)
    if not cuts:
        return segs, src
    if note is not None:
        note.append(f"split {len(cuts)} segments at vertices lying on them")
    return _cut(pts, segs, src, cuts)


def _from_dict(d: dict, presplit: bool = True) -> Domain:
    if "vertices" not in d:
        raise InvalidInputError("a domain dict needs 'vertices' (and usually 'segments')")
    pts = as_points(d["vertices"], "vertices")
    seg = as_segments(d.get("segments"), len(pts), pts)
    holes = as_points(d.get("holes", np.zeros((0, 2))), "holes")
    regions = d.get("regions")
    reg = None
    if regions is not None:
        try:
            reg = np.asarray(regions, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(f"regions must be rows of (x, y, marker[, max_area]): {exc}") from None
        if reg.size == 0:
            reg = None
        elif reg.ndim != 2 or reg.shape[1] < 3:
            raise InvalidInputError(f"regions must have shape (r, 3) or (r, 4), got {reg.shape}")
        else:
            reg = reg[:, :3]
    markers = d.get("segment_markers")
    src = np.arange(len(seg), dtype=np.int32)
    if markers is not None:
        try:
            markers = np.asarray(markers).reshape(-1)
        except (ValueError, TypeError) as exc:
            raise InvalidInputError(f"segment_markers must be a list of integers: {exc}") from None
        if len(markers) != len(seg):
            raise InvalidInputError(
                f"segment_markers has {len(markers)} entries for {len(seg)} segments")
        if not np.issubdtype(markers.dtype, np.integer):
            raise InvalidInputError("segment_markers must be integers")
        big = np.abs(markers.astype(np.int64)) > 2**31 - 1
        if big.any():
            i = int(np.flatnonzero(big)[0])
            raise InvalidInputError(
                f"segment_markers[{i}] = {int(markers[i])} is out of the int32 range")
        markers = markers.astype(np.int32)
    _refuse_crossings(pts, seg)
    names = [f"segments[{i}]" for i in range(len(seg))]
    # a segment running exactly through another vertex is split there now, before the
    # size splits it into pieces whose rounded ends would miss that vertex (kept whole,
    # the CDT splits it there exactly, at no cost here)
    note: list[str] = []
    if presplit:
        seg, src = _split_at_vertices(pts, seg, src, note)
    return Domain(pts, np.asarray(seg, dtype=np.int32), np.asarray(src, dtype=np.int32), names,
                  holes=holes, region_points=reg, source_markers=markers, cleanup=note)


def _refuse_crossings(pts, seg):
    """Dict / .poly input: segments crossing at a point inside both are refused (the
    policy of aftmesh.cdt), before any size-dependent splitting could hide them."""
    if len(seg) < 2:
        return
    lines = shapely.linestrings(np.stack([pts[seg[:, 0]], pts[seg[:, 1]]], axis=1))
    pairs = shapely.STRtree(lines).query(lines, predicate="crosses")
    pairs = pairs[:, pairs[0] < pairs[1]]
    if pairs.shape[1]:
        from .errors import CrossingSegmentsError
        i, j = (int(x) for x in pairs[:, 0])
        raise CrossingSegmentsError(
            f"segments[{i}] = {seg[i].tolist()} ({pts[seg[i, 0]].tolist()} -> "
            f"{pts[seg[i, 1]].tolist()}) crosses segments[{j}] = {seg[j].tolist()} "
            f"({pts[seg[j, 0]].tolist()} -> {pts[seg[j, 1]].tolist()})", (i, j))


def classify_pieces(polygons, probes: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """The index of the polygon each piece of the CDT lies in (-1: none), from a point
    inside one of its triangles (see Triangulation.components).  The probe is that
    triangle's rounded centroid; for a triangle an ulp or two wide it may fall on an
    edge or outside, and no double may lie inside it at all, so such a piece is
    classified by its exact rational centroid instead (see _exact_inside)."""
    from ._kernel import py_orient2d
    region_of = np.full(len(probes), -1, dtype=np.int32)
    for k, poly in enumerate(polygons):
        inside = shapely.contains_xy(poly, probes[:, 0], probes[:, 1])
        region_of[inside & (region_of < 0)] = k
    for c in range(len(probes)):
        (ax, ay), (bx, by), (cx, cy) = corners[c]
        x, y = probes[c]
        side = py_orient2d(ax, ay, bx, by, cx, cy)
        if side != 0 and py_orient2d(ax, ay, bx, by, x, y) == side \
                and py_orient2d(bx, by, cx, cy, x, y) == side \
                and py_orient2d(cx, cy, ax, ay, x, y) == side:
            continue            # the probe is strictly inside its triangle
        region_of[c] = -1
        for k, poly in enumerate(polygons):
            if _exact_inside(poly, corners[c]):
                region_of[c] = k
                break
    return region_of


def _exact_inside(poly, corners: np.ndarray) -> bool:
    """Whether the exact centroid of the triangle `corners` is inside `poly` (even-odd
    rule over all its rings, in rational arithmetic).  The centroid is strictly inside
    a triangle of the CDT, so it is on no ring."""
    from fractions import Fraction
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    x0, y0, x1, y1 = poly.bounds
    if lo[0] < x0 or lo[1] < y0 or hi[0] > x1 or hi[1] > y1:
        return False
    px = sum(Fraction(float(v)) for v in corners[:, 0]) / 3
    py = sum(Fraction(float(v)) for v in corners[:, 1]) / 3
    inside = False
    for part in shapely.get_parts(poly):
        for ring in [part.exterior, *part.interiors]:
            c = np.asarray(ring.coords)[:, :2]
            for (xa, ya), (xb, yb) in zip(c[:-1].tolist(), c[1:].tolist()):
                if (ya > py) != (yb > py):
                    x = Fraction(xa) + (py - Fraction(ya)) * (Fraction(xb) - Fraction(xa)) \
                        / (Fraction(yb) - Fraction(ya))
                    if px < x:
                        inside = not inside
    return inside


def _outside_by_rounding(outside, union, tol: float) -> bool:
    """Whether the parts of a constraint line outside the domain are there only by
    rounding (a line ending on the boundary at a computed point, which the noding
    then puts on the boundary): each part's ends and middle lie within `tol` of the
    domain.  (A straight part whose ends and middle are that near a polygon is that
    near it all along, unless the polygon has a feature right there, which the line
    would then cross, splitting the part.)"""
    parts = [p for p in shapely.get_parts(outside) if not p.is_empty]
    probes = []
    for p in parts:
        c = shapely.get_coordinates(p)
        probes.extend([c[0], c[-1], 0.5 * (c[0] + c[-1])])
    if not probes:
        return True
    return bool((shapely.distance(union, shapely.points(np.array(probes))) <= tol).all())


def to_domain(domain, *, keep_vertices: bool = False) -> Domain:
    """Convert any accepted domain form into a :class:`Domain` (see module doc)."""
    dom = _to_domain(domain, keep_vertices)
    if len(dom.vertices):
        check_range(dom.vertices, "vertices")
    return dom


def _to_domain(domain, keep_vertices: bool) -> Domain:
    if isinstance(domain, (str, PathLike)):
        from .io import read_poly
        try:
            return _from_dict(read_poly(domain), presplit=not keep_vertices)
        except OSError as exc:
            # a wrong path is the caller's input error like any other
            raise InvalidInputError(f"cannot read the domain file {str(domain)!r}: {exc}") from None
    if isinstance(domain, dict):
        return _from_dict(domain, presplit=not keep_vertices)
    if isinstance(domain, shapely.Geometry):
        polygons, lines, points = [], [], []
        parts = shapely.get_parts(domain) if isinstance(domain, GeometryCollection) else [domain]
        for part in parts:
            if isinstance(part, (Polygon, MultiPolygon)):
                polygons.extend(_polygon_parts(part, "the domain"))
            elif isinstance(part, (LineString, MultiLineString)):
                lines.extend(shapely.get_parts(part))
            elif isinstance(part, (Point, MultiPoint)):
                points.extend(shapely.get_parts(part))
            else:
                raise InvalidDomainError(f"cannot mesh a {part.geom_type}")
        if not polygons:
            raise InvalidDomainError("the domain has no polygon to mesh")
        names = [f"polygon {k}" if len(polygons) > 1 else "the polygon"
                 for k in range(len(polygons))]
        for k, p in enumerate(polygons):
            _check_polygon(p, names[k])
        union = shapely.union_all(polygons)
        tol = None
        for k, line in enumerate(lines):
            if union.covers(line):
                continue
            if tol is None:
                tol = snap_tolerance(np.concatenate(
                    [shapely.get_coordinates(g) for g in (*polygons, *lines)]))
            if not _outside_by_rounding(line.difference(union), union, tol):
                raise InvalidDomainError(f"constraint line {k} is not inside the domain")
        for k, p in enumerate(points):
            if not union.covers(p):
                raise InvalidDomainError(
                    f"fixed point {k} = {list(p.coords)[0]} is not inside the domain")
        single = shapely.union_all(polygons)
        return _from_shapely([single] if isinstance(single, Polygon) else polygons,
                             lines, points,
                             ["the polygon"] if isinstance(single, Polygon) else names,
                             keep_vertices)
    if _is_coordinate_array(domain):
        arr = np.asarray(domain, dtype=np.float64)
        bad = ~np.isfinite(arr).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InvalidDomainError(f"vertex {i} = {arr[i].tolist()} is not finite")
        if len(arr) < 3:
            raise InvalidDomainError(f"a polygon ring needs at least 3 vertices, got {len(arr)}")
        try:
            poly = Polygon(arr)
        except (ValueError, TypeError) as exc:
            raise InvalidDomainError(f"the ring is not a polygon: {exc}") from None
        _check_polygon(poly, "the polygon")
        return _from_shapely([poly], [], [], ["the polygon"], keep_vertices)
    try:
        items = list(domain)
    except TypeError:
        raise InvalidDomainError(
            f"cannot mesh a {type(domain).__name__}: give a shapely geometry, a sequence of "
            "polygons, an (n, 2) array, a dict or a .poly path") from None
    if not items:
        raise InvalidDomainError("the domain is an empty sequence")
    polygons = []
    for k, item in enumerate(items):
        if isinstance(item, shapely.Geometry):
            poly = item
        elif _is_coordinate_array(item):
            try:
                poly = Polygon(np.asarray(item, dtype=np.float64))
            except (ValueError, TypeError) as exc:
                raise InvalidDomainError(f"region {k} is not a polygon ring: {exc}") from None
        else:
            raise InvalidDomainError(f"region {k} is a {type(item).__name__}, expected a polygon")
        for part in _polygon_parts(poly, f"region {k}"):
            _check_polygon(part, f"region {k}")
        polygons.append(poly)
    for i in range(len(polygons)):
        for j in range(i + 1, len(polygons)):
            overlap = polygons[i].intersection(polygons[j]).area
            if overlap > 1e-12 * min(polygons[i].area, polygons[j].area):
                raise InvalidDomainError(
                    f"regions {i} and {j} overlap (common area {overlap:.6g}): regions must "
                    "have disjoint interiors")
    flat: list[Polygon] = []
    names: list[str] = []
    for k, p in enumerate(polygons):
        for part in _polygon_parts(p, f"region {k}"):
            flat.append(part)
            names.append(f"region {k}")
    dom = _from_shapely(flat, [], [], names, keep_vertices)
    dom.polygons = polygons
    dom.area = float(sum(p.area for p in polygons))
    return dom
