"""Domain builders shared by the generate / domain tests, and the independent oracles
(Triangle, an exact incircle) the tests compare aftmesh's meshes against.

Every builder returns a :class:`Case`: the domain in one of the input forms that
``aftmesh.generate`` accepts plus what a test needs to judge a mesh of it without
asking aftmesh: the exact area, the input edges as coordinate pairs, the input
vertices, and a modest target size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import shapely
import shapely.affinity
import triangle
from hypothesis import assume
from hypothesis import strategies as st
from shapely.geometry import MultiPolygon, Point, Polygon, box


# --------------------------------------------------------------------------- cases
@dataclass(frozen=True)
class Case:
    name: str
    domain: object  # what is passed to aftmesh.generate
    area: float  # exact area of the domain
    edges: np.ndarray  # (k, 2, 2) input edges as coordinate pairs
    vertices: np.ndarray  # (n, 2) distinct input vertices (incl. isolated ones)
    size: float  # a modest target edge length
    holes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # a point per hole
    isolated: int = 0  # input vertices strictly inside the domain (fixed points)

    def __repr__(self):  # short ids in pytest output
        return self.name


def _ring_edges(coords) -> list:
    c = np.asarray(coords, dtype=float)[:, :2]
    if len(c) > 1 and (c[0] == c[-1]).all():
        c = c[:-1]
    return [(c[i], c[(i + 1) % len(c)]) for i in range(len(c))]


def _polys(geom) -> list[Polygon]:
    if isinstance(geom, Polygon):
        return [geom]
    if isinstance(geom, MultiPolygon):
        return list(geom.geoms)
    return [g for g in geom]


def shapely_case(name: str, geom, size: float) -> Case:
    """A Case from a shapely Polygon / MultiPolygon or a list of polygons."""
    edges, holes = [], []
    for poly in _polys(geom):
        for ring in [poly.exterior, *poly.interiors]:
            edges += _ring_edges(ring.coords)
        for hole in poly.interiors:
            holes.append(np.asarray(Polygon(hole).representative_point().coords)[0])
    E = np.array([[a, b] for a, b in edges], dtype=float)
    V = np.unique(E.reshape(-1, 2), axis=0)
    if isinstance(geom, (Polygon, MultiPolygon)):
        area = geom.area
    else:
        area = sum(p.area for p in geom)
    return Case(name, geom, float(area), E, V, size, np.array(holes).reshape(-1, 2))


def triangle_sample(name: str, size: float | None = None) -> Case:
    """One of Triangle's sample .poly files, as the dict Triangle's loader gives."""
    d = triangle.get_data(name)
    V = np.asarray(d["vertices"], dtype=float)
    S = np.asarray(d["segments"])
    E = np.stack([V[S[:, 0]], V[S[:, 1]]], axis=1)
    # area: Triangle's own constrained triangulation of the same PSLG
    ref = triangle.triangulate({k: d[k] for k in ("vertices", "segments", "holes") if k in d}, "p")
    p = ref["vertices"][ref["triangles"]]
    area = (
        0.5
        * np.abs(
            (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
            - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
        ).sum()
    )
    on_segment = np.zeros(len(V), dtype=bool)
    on_segment[S.ravel()] = True
    L = np.linalg.norm(E[:, 1] - E[:, 0], axis=1)
    return Case(
        f"poly:{name}",
        d,
        float(area),
        E,
        V,
        float(np.median(L)) if size is None else size,
        np.asarray(d.get("holes", np.zeros((0, 2)))).reshape(-1, 2),
        isolated=int((~on_segment).sum()),
    )


def square():
    return shapely_case("square", box(0, 0, 1, 1), 0.2)


def regular_polygon(n=13):
    t = 2 * np.pi * np.arange(n) / n
    return shapely_case(f"ngon{n}", Polygon(np.c_[np.cos(t), np.sin(t)]), 0.3)


def l_shape():
    return shapely_case("L", Polygon([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]), 0.25)


def comb(teeth=5):
    # spine along the bottom, teeth of width 1 separated by gaps of width 1
    ring = [(0.0, 0.0), (2.0 * teeth - 1, 0.0)]
    for k in reversed(range(teeth)):
        x0, x1 = 2.0 * k, 2.0 * k + 1
        ring += [(x1, 4.0), (x0, 4.0)]
        if k:
            ring += [(x0, 1.0), (x0 - 1, 1.0)]
    return shapely_case(f"comb{teeth}", Polygon(ring), 0.4)


def thin_channel():
    """A straight channel much narrower than the size."""
    return shapely_case("channel", box(0, 0, 10, 0.05), 0.5)


def serpentine():
    """A meandering orthogonal channel of width 0.1."""
    w = 0.1
    parts = [
        box(0, 0, 3, w),
        box(3 - w, 0, 3, 1),
        box(0, 1 - w, 3, 1),
        box(0, 1 - w, w, 2),
        box(0, 2 - w, 3, 2),
    ]
    return shapely_case("serpentine", shapely.union_all(parts), 0.15)


def many_holes(k=4, kind="square"):
    outer = box(0, 0, k, k)
    holes = []
    for i in range(k):
        for j in range(k):
            c = (i + 0.5, j + 0.5)
            if kind == "square":
                holes.append(box(c[0] - 0.2, c[1] - 0.2, c[0] + 0.2, c[1] + 0.2))
            else:
                holes.append(Point(c).buffer(0.25, quad_segs=3))
    poly = Polygon(outer.exterior.coords, [h.exterior.coords for h in holes])
    assert poly.is_valid
    return shapely_case(f"{k * k}holes-{kind}", poly, 0.2)


def hole_touching_boundary(on_vertex=True):
    """A triangular hole one of whose vertices lies on the exterior ring."""
    ext = (
        [(0, 0), (2, 0), (4, 0), (4, 4), (0, 4)] if on_vertex else [(0, 0), (4, 0), (4, 4), (0, 4)]
    )
    poly = Polygon(ext, [[(2, 0), (3, 2), (1, 2)]])
    assert poly.is_valid
    return shapely_case("hole-touch-" + ("vertex" if on_vertex else "edge"), poly, 0.5)


def holes_touching_each_other():
    poly = Polygon(
        [(0, 0), (6, 0), (6, 4), (0, 4)], [[(1, 1), (3, 2), (1, 3)], [(3, 2), (5, 1), (5, 3)]]
    )
    assert poly.is_valid
    return shapely_case("holes-touch", poly, 0.5)


def corner_touching_parts():
    geom = MultiPolygon([box(0, 0, 1, 1), box(1, 1, 2, 2)])
    assert geom.is_valid
    return shapely_case("touch-corner", geom, 0.25)


def vertex_on_edge_parts():
    geom = MultiPolygon([box(0, 0, 2, 1), Polygon([(1, 1), (1.5, 2), (0.5, 2)])])
    assert geom.is_valid
    return shapely_case("touch-vertex-edge", geom, 0.25)


def annulus():
    outer = Point(0, 0).buffer(1.0, quad_segs=8)
    inner = Point(0.1, 0.05).buffer(0.4, quad_segs=6)
    return shapely_case("annulus", outer.difference(inner), 0.2)


def far_from_origin(offset=1e6):
    """The L-shape translated far away: coordinates with few bits left for detail."""
    L = Polygon([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
    return shapely_case(f"L+{offset:g}", shapely.affinity.translate(L, offset, offset), 0.25)


def tiny_annulus(scale=1e-6):
    a = annulus()
    geom = shapely.affinity.scale(a.domain, scale, scale, origin=(0, 0))
    return shapely_case(f"annulus*{scale:g}", geom, a.size * scale)


def narrow_slot():
    """A slot much narrower than the size cut into a rectangle."""
    ring = [(0, 0), (3, 0), (3, 2), (1.55, 2), (1.55, 0.5), (1.45, 0.5), (1.45, 2), (0, 2)]
    return shapely_case("slot", Polygon(ring), 0.3)


def spiral():
    th = np.linspace(0, 4 * np.pi, 80)
    inner, outer = 1 + th, 1.5 + th
    ring = np.r_[
        np.c_[inner * np.cos(th), inner * np.sin(th)],
        np.c_[outer * np.cos(th), outer * np.sin(th)][::-1],
    ]
    poly = Polygon(ring)
    assert poly.is_valid
    return shapely_case("spiral", poly, 0.3)


def sliver():
    """A needle triangle, 1000 times longer than high."""
    return shapely_case("sliver", Polygon([(0, 0), (10, 0), (10, 0.01)]), 1.0)


def shapely_cases() -> list[Case]:
    return [
        square(),
        regular_polygon(),
        l_shape(),
        comb(),
        thin_channel(),
        serpentine(),
        many_holes(3, "square"),
        many_holes(4, "circle"),
        hole_touching_boundary(True),
        hole_touching_boundary(False),
        holes_touching_each_other(),
        corner_touching_parts(),
        vertex_on_edge_parts(),
        annulus(),
        far_from_origin(),
        tiny_annulus(),
        narrow_slot(),
        spiral(),
        sliver(),
    ]


# Triangle's sample files that describe closed domains (box.poly has an unclosed
# segment and only a hole-filled square: nothing for aftmesh to mesh, tested apart).
TRIANGLE_SAMPLES = [
    "A",
    "double_hex",
    "double_hex2",
    "double_hex3",
    "face",
    "la",
    "square_circle_hole",
]


# --------------------------------------------------------------- hypothesis domains
@st.composite
def star_polygons(draw, max_vertices=16):
    """Star-shaped polygons around the origin: sorted angles with every angular gap
    below pi, radii in [0.35, 1]."""
    n = draw(st.integers(4, max_vertices))
    w = np.array(draw(st.lists(st.floats(1.0, 2.0), min_size=n, max_size=n)))
    theta = np.cumsum(w) / w.sum() * 2 * np.pi + draw(st.floats(0, 2 * np.pi))
    r = np.array(draw(st.lists(st.floats(0.35, 1.0), min_size=n, max_size=n)))
    ring = np.c_[r * np.cos(theta), r * np.sin(theta)]
    poly = Polygon(ring)
    assume(poly.is_valid and poly.area > 0.05)
    return poly


@st.composite
def nested_multipolygons(draw, max_depth=4):
    """Multipolygons whose rings meet nowhere: a star polygon and copies of it scaled
    about its centre, alternately a part's exterior and a hole (islands in lakes in
    islands, the innermost island with or without a lake), and maybe a second such
    nest beside the first."""
    star = draw(star_polygons())
    parts = []
    for dx in (0.0, 2.5)[: draw(st.integers(1, 2))]:
        depth = draw(st.integers(1, max_depth))
        n = 2 * depth - 1 + draw(st.integers(0, 1))  # rings in this nest
        scales = sorted(draw(st.lists(st.floats(0.1, 1.0), min_size=n, max_size=n)))[::-1]
        assume(all(a - b > 0.05 for a, b in zip(scales, scales[1:])))
        rings = [shapely.affinity.scale(star, f, f, origin=(0, 0)).exterior.coords for f in scales]
        for k in range(0, n, 2):
            part = Polygon(rings[k], rings[k + 1 : k + 2])
            parts.append(shapely.affinity.translate(part, dx, 0.0))
    multi = MultiPolygon(parts)
    assume(multi.is_valid)
    return multi


@st.composite
def polygons_with_circular_holes(draw, max_holes=5):
    """The square [0, 2]^2 minus disjoint discs (as polygons) well inside it."""
    k = draw(st.integers(1, max_holes))
    discs = []
    for _ in range(k):
        r = draw(st.floats(0.08, 0.35))
        cx = draw(st.floats(r + 0.1, 2 - r - 0.1))
        cy = draw(st.floats(r + 0.1, 2 - r - 0.1))
        discs.append((cx, cy, r))
    for i in range(k):
        for j in range(i):
            (x1, y1, r1), (x2, y2, r2) = discs[i], discs[j]
            assume(math.hypot(x1 - x2, y1 - y2) > r1 + r2 + 0.08)
    nseg = draw(st.integers(2, 5))
    holes = [Point(x, y).buffer(r, quad_segs=nseg).exterior.coords for x, y, r in discs]
    poly = Polygon([(0, 0), (2, 0), (2, 2), (0, 2)], holes)
    assume(poly.is_valid)
    return poly


@st.composite
def curved_domains(draw):
    """Domains whose boundary curves round the inside, meshed at one constant size no
    longer than their edges (so that the size stays one constant and converging rows
    snap to one lattice, cython_ext/lattice.pxi): a disc, an ellipse, a slot with round
    ends, a box with rounded corners or a disc with an off-centre hole, turned and
    moved.  Returns (polygon, size)."""
    kind = draw(st.sampled_from(["disc", "ellipse", "slot", "rounded", "holed"]))
    r = draw(st.floats(0.3, 3.0))
    quad = draw(st.integers(4, 24))
    disc = shapely.Point(0.0, 0.0).buffer(r, quad_segs=quad)
    if kind == "ellipse":
        geom = shapely.affinity.scale(disc, draw(st.floats(1.0, 3.0)), 1.0)
    elif kind == "slot":
        geom = shapely.LineString([(0.0, 0.0), (draw(st.floats(0.5, 4.0)) * r, 0.0)])
        geom = geom.buffer(r, quad_segs=quad)
    elif kind == "rounded":
        geom = shapely.box(-r, -0.6 * r, r, 0.6 * r).buffer(draw(st.floats(0.1, 0.4)) * r, quad)
    elif kind == "holed":
        hx, hy = draw(st.floats(-0.3, 0.3)) * r, draw(st.floats(-0.3, 0.3)) * r
        geom = disc.difference(shapely.Point(hx, hy).buffer(0.4 * r, quad_segs=2 * quad))
    else:
        geom = disc
    geom = shapely.affinity.rotate(geom, draw(st.floats(0.0, 360.0)), origin=(0.0, 0.0))
    # moved by at least 1 each way: a turn leaves coordinates like 1e-80 where one was
    # 0, which generate refuses (below the exact predicates' range)
    dx, dy = (draw(st.floats(1.0, 1e3)) * draw(st.sampled_from([-1.0, 1.0])) for _ in "xy")
    geom = shapely.affinity.translate(geom, dx, dy)
    edges = np.diff(np.asarray(geom.exterior.coords), axis=0)
    shortest = float(np.hypot(edges[:, 0], edges[:, 1]).min())
    size = shortest * draw(st.floats(0.25, 1.0))
    # at most about 20,000 triangles: the suite stays fast
    size = max(size, math.sqrt(geom.area / (0.433 * 20000)))
    assume(geom.is_valid and geom.geom_type == "Polygon")
    return geom, size


# ------------------------------------------------------------------------- oracles
def triangle_keys(tris) -> set:
    return {tuple(sorted(t)) for t in np.asarray(tris).tolist()}


def _exact_incircle(a, b, c, d) -> int:
    a, b, c, d = ([Fraction(float(x)) for x in p] for p in (a, b, c, d))
    rows = [(p[0] - d[0], p[1] - d[1]) for p in (a, b, c)]
    rows = [(x, y, x * x + y * y) for x, y in rows]
    (ax, ay, al), (bx, by, bl), (cx, cy, cl) = rows
    det = al * (bx * cy - cx * by) + bl * (cx * ay - ax * cy) + cl * (ax * by - bx * ay)
    return (det > 0) - (det < 0)


def incircle_signs(P: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """Exact sign of incircle(a, b, c, d) for each row (a, b, c, d) of vertex indices:
    > 0 when d is strictly inside the circle through the CCW triangle a, b, c.  A float
    evaluation decides where it clearly can; the rest is done in rationals."""
    q = P[quads]
    d = q[:, 3:4, :]
    r = q[:, :3, :] - d
    lift = (r**2).sum(axis=2)
    x, y = r[..., 0], r[..., 1]
    m0 = x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1]
    m1 = x[:, 2] * y[:, 0] - x[:, 0] * y[:, 2]
    m2 = x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]
    det = lift[:, 0] * m0 + lift[:, 1] * m1 + lift[:, 2] * m2
    perm = (
        lift[:, 0] * (np.abs(x[:, 1] * y[:, 2]) + np.abs(x[:, 2] * y[:, 1]))
        + lift[:, 1] * (np.abs(x[:, 2] * y[:, 0]) + np.abs(x[:, 0] * y[:, 2]))
        + lift[:, 2] * (np.abs(x[:, 0] * y[:, 1]) + np.abs(x[:, 1] * y[:, 0]))
    )
    sign = np.sign(det).astype(int)
    unsure = np.abs(det) <= 1e-9 * perm
    for i in np.flatnonzero(unsure):
        sign[i] = _exact_incircle(*P[quads[i]])
    return sign


def _exact_orient(a, b, c) -> int:
    a, b, c = ([Fraction(float(x)) for x in p] for p in (a, b, c))
    det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (det > 0) - (det < 0)


def orient_signs(P: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Exact sign of the orientation of each triangle (> 0: counter-clockwise)."""
    p = P[np.asarray(tris)]
    l = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
    r = (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    det = l - r
    sign = np.sign(det).astype(int)
    for i in np.flatnonzero(np.abs(det) <= 1e-12 * (np.abs(l) + np.abs(r))):
        sign[i] = _exact_orient(*p[i])
    return sign


def non_delaunay_edges(mesh) -> list:
    """Interior edges that are not segments and whose opposite apex lies strictly
    inside the circumcircle (exact arithmetic).  Empty for a CDT."""
    P = np.asarray(mesh.points, dtype=float)
    T = np.asarray(mesh.triangles)
    N = np.asarray(mesh.neighbors)
    seg = {tuple(sorted(s)) for s in np.asarray(mesh.segments).tolist()}
    quads, where = [], []
    for t, k in zip(*np.nonzero(N >= 0)):
        u, v = int(T[t, (k + 1) % 3]), int(T[t, (k + 2) % 3])
        if (min(u, v), max(u, v)) in seg:
            continue
        nb = T[N[t, k]]
        far = int(nb[(nb != u) & (nb != v)][0])
        quads.append([*T[t], far])
        where.append((int(t), (u, v)))
    if not quads:
        return []
    s = incircle_signs(P, np.array(quads))
    return [where[i] for i in np.flatnonzero(s > 0)]


def assert_cdt(mesh) -> None:
    """The mesh is the constrained Delaunay triangulation of its points and segments:
    every triangle is one of Triangle's CDT of the same PSLG (Triangle also fills the
    holes; the area check of check_mesh rules those out).  Where the points are
    cocircular the CDT is not unique: then the exact empty-circle test decides."""
    P = np.array(mesh.points, dtype=float)
    S = np.array(mesh.segments, dtype=np.int32)
    ref = triangle.triangulate({"vertices": P, "segments": S}, "p")
    assert len(ref["vertices"]) == len(P), "Triangle had to add points: segments cross?"
    ours, theirs = triangle_keys(mesh.triangles), triangle_keys(ref["triangles"])
    if ours <= theirs:
        return
    bad = non_delaunay_edges(mesh)
    assert not bad, (
        f"{len(ours - theirs)} triangles are not in Triangle's CDT and "
        f"{len(bad)} edges fail the exact empty-circle test, e.g. {bad[:3]}"
    )


def coordinate_keys(points) -> set:
    return {(float(x), float(y)) for x, y in np.asarray(points)}


def edge_keys(points, segments) -> set:
    P = np.asarray(points)
    out = set()
    for u, v in np.asarray(segments):
        a, b = tuple(map(float, P[u])), tuple(map(float, P[v]))
        out.add((min(a, b), max(a, b)))
    return out


def input_edge_keys(edges) -> set:
    out = set()
    for a, b in np.asarray(edges):
        a, b = tuple(map(float, a)), tuple(map(float, b))
        out.add((min(a, b), max(a, b)))
    return out


def points_on_edges(points, edges, tol=1e-12) -> np.ndarray:
    """For each point, whether it lies on one of the (k, 2, 2) edges (within tol of
    the edge's length)."""
    P = np.asarray(points, dtype=float)
    E = np.asarray(edges, dtype=float)
    a, b = E[:, 0], E[:, 1]
    d = b - a
    L2 = (d**2).sum(axis=1)
    rel = P[:, None, :] - a[None]
    t = (rel * d[None]).sum(axis=2) / L2[None]
    cross = rel[..., 0] * d[None, :, 1] - rel[..., 1] * d[None, :, 0]
    dist = np.abs(cross) / np.sqrt(L2)[None]
    scale = np.sqrt(L2)[None]
    on = (dist <= tol * scale) & (t >= -tol) & (t <= 1 + tol)
    return on.any(axis=1)


def split_at_vertices(edges, vertices, tol=1e-14) -> set:
    """The input edges cut at every input vertex lying on them (as edge_keys): the
    segments a mesh that keeps the input edges unmodified must have."""
    E = np.asarray(edges, dtype=float)
    V = np.asarray(vertices, dtype=float)
    out = set()
    for a, b in E:
        on = points_on_edges(V, np.array([[a, b]]), tol=tol)
        on &= ~(V == a).all(axis=1) & ~(V == b).all(axis=1)
        d = b - a
        inner = sorted(V[on].tolist(), key=lambda p: float((np.array(p) - a) @ d))
        chain = [tuple(map(float, p)) for p in [a, *inner, b]]
        for p, q in zip(chain[:-1], chain[1:]):
            out.add((min(p, q), max(p, q)))
    return out
