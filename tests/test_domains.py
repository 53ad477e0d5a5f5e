"""Input forms of ``aftmesh.generate`` (issue "Domains, sizes and the user-facing API"):
every accepted form gives a valid mesh of the right domain; every bad input raises the
``ValueError`` subclass that names the problem, never an IndexError or a crash."""

from __future__ import annotations

import pickle
import re

import domain_cases as dc
import numpy as np
import pytest
import shapely
import triangle
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import GeometryCollection, LineString, MultiPolygon, Point, Polygon, box

import aftmesh
from aftmesh.checks import check_mesh, count_formula
from aftmesh.sizing import RESOLVE_ROUNDS


def valid(mesh, area, *, edges=None, delaunay=True):
    """check_mesh plus exact orientation, formula (6), and the CDT property against
    Triangle."""
    check_mesh(mesh, domain_area=area, input_segments=edges, delaunay=delaunay)
    assert (dc.orient_signs(np.asarray(mesh.points), np.asarray(mesh.triangles)) > 0).all()
    for T, Eb, Vi, m in count_formula(mesh):
        assert T == Eb + 2 * Vi + 2 * (m - 1)
    if delaunay:
        dc.assert_cdt(mesh)
    return mesh


def centroids(mesh):
    return np.asarray(mesh.points)[np.asarray(mesh.triangles)].mean(axis=1)


def region_areas(mesh) -> dict:
    p = np.asarray(mesh.points)[np.asarray(mesh.triangles)]
    a = 0.5 * (
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )
    return {int(r): float(a[np.asarray(mesh.regions) == r].sum()) for r in np.unique(mesh.regions)}


def covered_by_segments(mesh, a, b, tol=1e-9) -> bool:
    """Whether segment a-b is exactly the union of mesh segments lying on it."""
    P = np.asarray(mesh.points)
    S = np.asarray(mesh.segments)
    E = np.array([[a, b]], dtype=float)
    on = dc.points_on_edges(P[S[:, 0]], E, tol) & dc.points_on_edges(P[S[:, 1]], E, tol)
    total = np.linalg.norm(P[S[on, 1]] - P[S[on, 0]], axis=1).sum()
    return abs(total - np.hypot(*(np.subtract(b, a)))) <= tol * np.hypot(*np.subtract(b, a))


# ------------------------------------------------------------------ accepted forms
def test_polygon_with_holes():
    holes = [box(1, 1, 2, 2), Point(4, 2.5).buffer(0.6, quad_segs=4)]
    poly = Polygon(box(0, 0, 6, 4).exterior.coords, [h.exterior.coords for h in holes])
    mesh = valid(aftmesh.generate(poly, 0.3), poly.area)
    c = centroids(mesh)
    for h in holes:
        assert not shapely.contains_xy(h, c[:, 0], c[:, 1]).any()
    assert sorted(r[3] for r in count_formula(mesh)) == [2]
    assert (np.asarray(mesh.regions) == 0).all()
    # the hole's corners are mesh vertices
    assert dc.coordinate_keys([(1, 1), (2, 1), (2, 2), (1, 2)]) <= dc.coordinate_keys(mesh.points)


def test_multipolygon_disjoint_and_touching():
    disjoint = MultiPolygon([box(0, 0, 1, 1), box(2, 0, 3, 2)])
    mesh = valid(aftmesh.generate(disjoint, 0.25), disjoint.area)
    assert len(count_formula(mesh)) == 2
    touching = MultiPolygon([box(0, 0, 1, 1), box(1, 1, 2, 2)])
    mesh = valid(aftmesh.generate(touching, 0.25), touching.area)
    # one shared vertex, no shared edge: two components through edges
    assert len(count_formula(mesh)) == 2
    assert (1.0, 1.0) in dc.coordinate_keys(mesh.points)


def test_geometry_collection_constraints():
    """A LineString inside is a constraint: its pieces are mesh segments; a Point is a
    fixed mesh vertex."""
    line = [(0.3, 0.2), (1.0, 0.5), (1.7, 0.5)]
    fixed = (0.55, 0.75)
    gc = GeometryCollection([box(0, 0, 2, 1), LineString(line), Point(fixed)])
    mesh = valid(aftmesh.generate(gc, 0.15), 2.0)
    pts = dc.coordinate_keys(mesh.points)
    assert fixed in pts
    assert {(0.3, 0.2), (1.0, 0.5), (1.7, 0.5)} <= pts
    for a, b in zip(line[:-1], line[1:]):
        assert covered_by_segments(mesh, a, b)
    # the constraint line's segments are marked as coming from it
    names = mesh.info["sources"]
    k = [i for i, n in enumerate(names) if "constraint line" in n]
    assert len(k) == 1
    marked = np.asarray(mesh.segments)[np.asarray(mesh.segment_markers) == k[0]]
    P = np.asarray(mesh.points)
    L = np.linalg.norm(P[marked[:, 1]] - P[marked[:, 0]], axis=1).sum()
    assert L == pytest.approx(np.hypot(0.7, 0.3) + 0.7, rel=1e-9)
    # the line is interior: triangles on both of its sides
    assert len(count_formula(mesh)) == 1


def test_geometry_collection_line_splits_domain():
    """An interface crossing the whole domain: still one conforming mesh."""
    gc = GeometryCollection([box(0, 0, 2, 1), LineString([(1, 0), (1, 1)])])
    mesh = valid(aftmesh.generate(gc, 0.2), 2.0)
    assert covered_by_segments(mesh, (1, 0), (1, 1))
    # no triangle crosses x = 1
    x = np.asarray(mesh.points)[np.asarray(mesh.triangles)][..., 0]
    assert ((x.max(axis=1) <= 1) | (x.min(axis=1) >= 1)).all()


@pytest.mark.parametrize(
    "line",
    [[(1.0, 0.0), (1.0, 0.6)], [(0.5, 0.5), (1.5, 0.5)], [(0.3, 0.2), (1.6, 0.7)]],
    ids=["from-boundary", "interior", "slanted"],
)
def test_geometry_collection_crack(line):
    """A constraint line with a free end (a crack): a segment with triangles on both
    sides, its free end a vertex."""
    gc = GeometryCollection([box(0, 0, 2, 1), LineString(line)])
    mesh = valid(aftmesh.generate(gc, 0.1), 2.0)
    assert covered_by_segments(mesh, *line)
    assert tuple(map(float, line[1])) in dc.coordinate_keys(mesh.points)
    rows = count_formula(mesh)
    assert len(rows) == 1 and rows[0][3] == 0
    # every piece of the crack is an interior edge: two triangles on it
    P = np.asarray(mesh.points)
    S = np.asarray(mesh.segments)
    on = dc.points_on_edges(P[S[:, 0]], np.array([line]), 1e-9) & dc.points_on_edges(
        P[S[:, 1]], np.array([line]), 1e-9
    )
    T = np.asarray(mesh.triangles)
    e = np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(e, axis=0, return_counts=True)
    twice = {tuple(x) for x in uniq[counts == 2].tolist()}
    assert on.sum() >= 2
    assert all(tuple(sorted(x)) in twice for x in S[on].tolist())


def test_inclusion_regions():
    """The paper's Figure 2: an annular region around a core region."""
    outer, core = box(0, 0, 4, 3), box(1, 1, 3, 2)
    ring = outer.difference(core)
    mesh = valid(aftmesh.generate([ring, core], 0.25), 12.0)
    assert region_areas(mesh) == pytest.approx({0: 10.0, 1: 2.0}, rel=1e-12)
    shared = _shared_edge_vertices(
        mesh,
        lambda p: (
            (p[0] in (1.0, 3.0) and 1 <= p[1] <= 2) or (p[1] in (1.0, 2.0) and 1 <= p[0] <= 3)
        ),
    )
    assert shared[0] == shared[1] and len(shared[0]) >= 12
    assert len(count_formula(mesh)) == 1


def _shared_edge_vertices(mesh, on_edge):
    """The vertices on the shared edge used by the triangles of each region."""
    P = np.asarray(mesh.points)
    out = {}
    for r in (0, 1):
        v = np.unique(np.asarray(mesh.triangles)[np.asarray(mesh.regions) == r])
        out[r] = {tuple(map(float, P[i])) for i in v if on_edge(P[i])}
    return out


def test_two_regions_sharing_an_edge():
    a = box(0, 0, 1, 1)
    b = Polygon([(1, 0), (2.5, 0), (2.5, 1), (1, 1)])
    mesh = valid(aftmesh.generate([a, b], 0.15), a.area + b.area)
    areas = region_areas(mesh)
    assert sorted(areas) == [0, 1]
    assert areas[0] == pytest.approx(a.area, rel=1e-12)
    assert areas[1] == pytest.approx(b.area, rel=1e-12)
    shared = _shared_edge_vertices(mesh, lambda p: p[0] == 1.0)
    assert shared[0] == shared[1] and len(shared[0]) >= 3
    assert covered_by_segments(mesh, (1, 0), (1, 1))
    c = centroids(mesh)
    assert (shapely.contains_xy(a, c[:, 0], c[:, 1]) == (np.asarray(mesh.regions) == 0)).all()


def test_two_regions_partial_shared_edge():
    """A T-junction: region 1's corner (1, 1) lies on region 0's edge."""
    a = box(0, 0, 1, 2)
    b = box(1, 0, 2, 1)
    mesh = valid(aftmesh.generate([a, b], 0.25), 3.0)
    assert region_areas(mesh) == pytest.approx({0: 2.0, 1: 1.0}, rel=1e-12)
    assert (1.0, 1.0) in dc.coordinate_keys(mesh.points)
    shared = _shared_edge_vertices(mesh, lambda p: p[0] == 1.0 and p[1] <= 1.0)
    assert shared[0] == shared[1]


def test_regions_with_multipolygon_item():
    parts = MultiPolygon([box(0, 0, 1, 1), box(2, 0, 3, 1)])
    middle = box(1, 0, 2, 1)
    mesh = valid(aftmesh.generate([parts, middle], 0.3), 3.0)
    assert region_areas(mesh) == pytest.approx({0: 2.0, 1: 1.0}, rel=1e-12)


def test_coordinate_ring_clockwise_and_closed():
    ccw = np.array([(0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (0, 2)], dtype=float)
    cw_closed = np.r_[ccw[::-1], ccw[-1:]]
    assert (cw_closed[0] == cw_closed[-1]).all()
    meshes = [aftmesh.generate(r, 0.3) for r in (ccw, cw_closed, ccw.tolist())]
    for mesh in meshes:
        valid(mesh, 4.0)
        assert dc.coordinate_keys(ccw) <= dc.coordinate_keys(mesh.points)
        assert sorted(r[3] for r in count_formula(mesh)) == [0]
    # the boundary is discretized alike whatever the ring's orientation or closure
    # (up to rounding: a piece's ends are computed from either end of the edge);
    # the split points not slid, as smoothing would in each mesh's own order
    unsmoothed = [
        aftmesh.generate(r, 0.3, slide_boundary=False) for r in (ccw, cw_closed, ccw.tolist())
    ]
    for mesh in unsmoothed:
        valid(mesh, 4.0)
    bnd = [np.asarray(m.points)[np.unique(m.segments)] for m in unsmoothed]
    assert len(bnd[0]) == len(bnd[1]) == len(bnd[2])
    for other in bnd[1:]:
        dist = np.linalg.norm(bnd[0][:, None, :] - other[None, :, :], axis=2)
        assert dist.min(axis=1).max() < 1e-12


def test_repeated_vertices_are_cleaned_up():
    ring = [(0, 0), (1, 0), (1, 0), (2, 0), (2, 1), (2, 1), (2, 1), (0, 1), (0, 0)]
    for split in (True, False):
        mesh = aftmesh.generate(ring, 0.3, split_boundary=split)
        valid(mesh, 2.0)
        notes = " ".join(mesh.info["cleanup"])
        assert "repeated" in notes and "3" in notes, mesh.info["cleanup"]
        assert len(np.unique(mesh.points, axis=0)) == len(mesh.points)


def shortest_edge(mesh) -> float:
    P = np.asarray(mesh.points)
    e = mesh.edges
    return float(np.linalg.norm(P[e[:, 1]] - P[e[:, 0]], axis=1).min())


# A vertex of one ring lying inside an edge of another ring (not at one of its
# vertices) does not cut that edge before it is discretized: a piece end lands next to
# the vertex (1e-16 away when the size divides the edge evenly, a small fraction of the
# size otherwise), and the CDT then splits the piece there: a needle triangle.
def test_regression_hole_vertex_inside_exterior_edge():
    poly = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(2, 0), (3, 2), (1, 2)]])
    mesh = valid(aftmesh.generate(poly, 0.5), poly.area)
    assert shortest_edge(mesh) > 0.1  # 4.4e-16: (1.9999999999999996, 0) and (2, 0)
    assert mesh.quality()["min_angle"] > 5  # 0.0


def test_regression_multipolygon_vertex_inside_edge():
    geom = MultiPolygon([box(0, 0, 2, 1), Polygon([(1, 1), (1.5, 2), (0.5, 2)])])
    mesh = valid(aftmesh.generate(geom, 0.25), geom.area)
    assert shortest_edge(mesh) > 0.05


def test_regression_constraint_end_on_boundary_edge():
    gc = GeometryCollection([box(0, 0, 2, 1), LineString([(1, 0), (1, 0.6)])])
    mesh = valid(aftmesh.generate(gc, 0.1), 2.0)
    assert shortest_edge(mesh) > 0.02  # 3.3e-16
    gc = GeometryCollection([box(0, 0, 2, 1), Point(1.0, 0.0)])
    mesh = valid(aftmesh.generate(gc, 0.1), 2.0)
    assert shortest_edge(mesh) > 0.02


def test_regression_t_junction_shared_edge_discretized_twice():
    """Regions box(0,0,1,2) and box(1,0,2,1) share the edge x = 1, 0 <= y <= 1; it is
    discretized once per region (13 pieces per 2 and 7 per 1, interleaved), not once:
    vertices 0.011 apart for a size of 0.15, angles of 2.8 degrees."""
    mesh = valid(aftmesh.generate([box(0, 0, 1, 2), box(1, 0, 2, 1)], 0.15), 3.0)
    P = np.asarray(mesh.points)
    y = np.sort(P[(P[:, 0] == 1.0) & (P[:, 1] <= 1.0), 1])
    assert np.diff(y).min() > 0.05, np.round(y, 4)
    assert mesh.quality()["min_angle"] > 15


def test_regression_repeated_closing_vertex_zero_division():
    """A ring whose closing vertex is repeated three times: ZeroDivisionError in
    generate (a zero-length edge survives the clean-up, the size becomes 0)."""
    ring = [(0, 0), (1, 0), (0, 1), (0, 0), (0, 0), (0, 0)]
    for domain in (np.array(ring, dtype=float), Polygon(ring)):
        mesh = valid(aftmesh.generate(domain, 0.3), 0.5)
        assert len(mesh.points) == len(np.unique(mesh.points, axis=0))


def test_triangle_style_dict_with_holes_and_regions():
    d = dict(
        vertices=[
            (0, 0),
            (2.5, 0),
            (4, 0),
            (4, 4),
            (2.5, 4),
            (0, 4),
            (1, 1),
            (2, 1),
            (2, 2),
            (1, 2),
        ],
        segments=[
            (0, 1),
            (1, 2),
            (2, 3),
            (3, 4),
            (4, 5),
            (5, 0),
            (1, 4),
            (6, 7),
            (7, 8),
            (8, 9),
            (9, 6),
        ],
        holes=[(1.5, 1.5)],
        regions=[(0.5, 3, 10, 0), (3, 3, 20, 0)],
    )
    for kw in ({"size": 0.4}, {"size": None, "split_boundary": False}):
        mesh = valid(aftmesh.generate(d, **kw), 15.0)
        assert region_areas(mesh) == pytest.approx({10: 9.0, 20: 6.0}, rel=1e-12)
        c = centroids(mesh)
        assert not shapely.contains_xy(box(1, 1, 2, 2), c[:, 0], c[:, 1]).any()
        assert covered_by_segments(mesh, (2.5, 0), (2.5, 4))
    # without splitting, the input segments are the mesh's (the interface included)
    mesh = aftmesh.generate(d, split_boundary=False)
    V = np.asarray(d["vertices"], dtype=float)
    S = np.asarray(d["segments"])
    assert dc.edge_keys(mesh.points, mesh.segments) == dc.edge_keys(V, S)
    # segment markers: the index of the input segment each piece comes from
    mesh = aftmesh.generate(d, 0.3)
    P = np.asarray(mesh.points)
    for (u, v), k in zip(np.asarray(mesh.segments), np.asarray(mesh.segment_markers)):
        assert 0 <= k < len(S)
        assert dc.points_on_edges(P[[u, v]], np.array([V[S[k]]]), tol=1e-9).all()


def test_dict_nested_regions_match_triangle():
    """Nested square rings with region points and a hole in the middle: the area of
    each region marker is the one Triangle's regional attributes ('A') give."""
    rings = [box(-k, -k, k, k).exterior.coords[:-1] for k in (4, 3, 2, 1)]
    V = np.concatenate([np.asarray(r, dtype=float) for r in rings])
    S = np.concatenate([np.c_[np.arange(4), (np.arange(4) + 1) % 4] + 4 * i for i in range(4)])
    d = dict(
        vertices=V,
        segments=S,
        holes=np.array([[0.0, 0.0]]),
        regions=np.array([[3.5, 0, 7, 0], [2.5, 0, 8, 0], [0, 1.5, 9, 0]]),
    )
    ref = triangle.triangulate(d, "pA")
    p = ref["vertices"][ref["triangles"]]
    a = 0.5 * np.abs(
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )
    att = ref["triangle_attributes"][:, 0]
    expected = {int(k): float(a[att == k].sum()) for k in np.unique(att)}
    assert expected == pytest.approx({7: 28.0, 8: 20.0, 9: 12.0})
    for kw in ({"size": 0.5}, {"split_boundary": False}):
        mesh = valid(aftmesh.generate(d, **kw), 60.0)
        assert region_areas(mesh) == pytest.approx(expected, rel=1e-12)
        assert sorted(r[3] for r in count_formula(mesh)) == [1]


def test_poly_file_path(tmp_path):
    path = tmp_path / "sq.poly"
    path.write_text("4 2 0 0\n1 0 0\n2 2 0\n3 2 1\n4 0 1\n4 0\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n0\n")
    mesh = valid(aftmesh.generate(str(path), 0.25), 2.0)
    assert {(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)} <= dc.coordinate_keys(mesh.points)


# -------------------------------------------------------------------------- sizes
def test_size_number_int_and_numpy_scalar():
    poly = box(0, 0, 2, 1)
    meshes = [aftmesh.generate(poly, s) for s in (0.25, np.float64(0.25), np.float32(0.25))]
    for m in meshes:
        valid(m, 2.0)
    assert np.array_equal(meshes[0].points, meshes[1].points)
    valid(aftmesh.generate(box(0, 0, 20, 10), 3), 200.0)


def test_size_callable_called_on_arrays_a_few_times():
    calls = []

    def size(x, y):
        calls.append(np.size(x))
        assert isinstance(x, np.ndarray) and isinstance(y, np.ndarray)
        assert np.shape(x) == np.shape(y)
        return 0.06 + 0.1 * x

    poly = box(0, 0, 2, 1)
    mesh = valid(aftmesh.generate(poly, size), 2.0)
    assert len(mesh.points) > 100
    assert 1 <= len(calls) <= RESOLVE_ROUNDS + 1, calls
    assert min(calls) > 1
    # graded: smaller edges near x = 0 than near x = 2
    P = np.asarray(mesh.points)
    e = mesh.edges
    mid = 0.5 * (P[e[:, 0]] + P[e[:, 1]])
    L = np.linalg.norm(P[e[:, 1]] - P[e[:, 0]], axis=1)
    assert L[mid[:, 0] < 0.4].mean() < L[mid[:, 0] > 1.6].mean()


def test_size_callable_returning_scalar():
    mesh = aftmesh.generate(box(0, 0, 1, 1), lambda x, y: 0.2)
    valid(mesh, 1.0)
    same = aftmesh.generate(box(0, 0, 1, 1), 0.2)
    assert len(mesh.triangles) == pytest.approx(len(same.triangles), rel=0.3)


def test_size_none_from_edge_lengths():
    """size=None: the target is the input edges' own length, so equal edges are not
    split (here a regular 24-gon of edge length ~0.26)."""
    t = 2 * np.pi * np.arange(24) / 24
    ring = np.c_[np.cos(t), np.sin(t)]
    mesh = valid(aftmesh.generate(ring), Polygon(ring).area)
    E = np.stack([ring, np.roll(ring, -1, axis=0)], axis=1)
    assert dc.edge_keys(mesh.points, mesh.segments) == dc.input_edge_keys(E)
    assert len(mesh.points) > 24  # but the interior is meshed with new points


def test_size_none_follows_local_edge_length():
    """A rectangle whose bottom edge is finely divided, top edge not: smaller
    triangles at the bottom."""
    bottom = [(x, 0.0) for x in np.linspace(0, 4, 41)]
    ring = bottom + [(4.0, 2.0), (0.0, 2.0)]
    mesh = valid(aftmesh.generate(ring, split_boundary=False), 8.0)
    p = np.asarray(mesh.points)[np.asarray(mesh.triangles)]
    cy = p[..., 1].mean(axis=1)
    area = 0.5 * np.abs(
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )
    assert area[cy < 0.3].mean() < area[cy > 1.5].mean()


# ---------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "ring", [[(0, 0), (1, 1), (1, 0), (0, 1)], [(0, 0), (2, 0), (2, 2), (1, -1), (0, 2)]]
)
def test_self_intersecting_exterior_ring(ring):
    with pytest.raises(aftmesh.InvalidDomainError, match="exterior ring"):
        aftmesh.generate(ring, 0.3)
    with pytest.raises(aftmesh.InvalidDomainError, match="exterior ring"):
        aftmesh.generate(Polygon(ring), 0.3)


def test_self_intersecting_hole_named():
    poly = Polygon(
        box(0, 0, 4, 4).exterior.coords,
        [box(0.2, 0.2, 0.5, 0.5).exterior.coords, [(1, 1), (2, 2), (2, 1), (1, 2)]],
    )
    with pytest.raises(aftmesh.InvalidDomainError, match="hole 1"):
        aftmesh.generate(poly, 0.3)


def test_hole_outside_named():
    poly = Polygon(box(0, 0, 4, 4).exterior.coords, [[(5, 5), (6, 5), (6, 6)]])
    with pytest.raises(aftmesh.InvalidDomainError, match="hole 0"):
        aftmesh.generate(poly, 0.3)


def test_invalid_region_named():
    with pytest.raises(aftmesh.InvalidDomainError, match="region 1"):
        aftmesh.generate([box(0, 0, 1, 1), Polygon([(1, 0), (2, 1), (2, 0), (1, 1)])], 0.3)


@pytest.mark.parametrize(
    "regions, names",
    [
        ([box(0, 0, 2, 2), box(1, 1, 3, 3)], ("0", "1")),
        ([box(0, 0, 1, 1), box(2, 0, 3, 1), box(2.5, 0.5, 4, 2)], ("1", "2")),
        ([box(0, 0, 4, 4), box(1, 1, 2, 2)], ("0", "1")),
    ],
)
def test_overlapping_regions_named(regions, names):
    with pytest.raises(aftmesh.InvalidDomainError) as err:
        aftmesh.generate(regions, 0.3)
    msg = str(err.value)
    assert "overlap" in msg
    assert re.search(rf"\b{names[0]}\b.*\b{names[1]}\b", msg), msg


@pytest.mark.parametrize(
    "size", [0, -1, -0.5, float("nan"), float("inf"), -float("inf"), "big", [0.1, 0.2], object()]
)
def test_bad_size_values(size):
    with pytest.raises(aftmesh.InvalidSizeError):
        aftmesh.generate(box(0, 0, 1, 1), size)


@pytest.mark.parametrize(
    "bad, region",
    [
        (lambda x, y: np.where(x > 0.5, np.nan, 0.2), lambda x, y: x > 0.5 - 1e-5),
        (lambda x, y: 0.2 - y, lambda x, y: y > 0.2 - 1e-5),
        (
            lambda x, y: np.where((x - 1) ** 2 + (y - 1) ** 2 < 0.25, -1.0, 0.2),
            lambda x, y: (x - 1) ** 2 + (y - 1) ** 2 < 0.2501,
        ),
        (lambda x, y: np.where(x < 0.25, np.inf, 0.2), lambda x, y: x < 0.25 + 1e-5),
    ],
)
def test_size_callable_bad_somewhere(bad, region):
    with pytest.raises(aftmesh.InvalidSizeError) as err:
        aftmesh.generate(box(0, 0, 2, 2), bad)
    m = re.search(r"at \(([-+0-9.e]+), ([-+0-9.e]+)\)", str(err.value))
    assert m, str(err.value)
    x, y = float(m.group(1)), float(m.group(2))
    assert region(x, y), (x, y)


def test_size_callable_failing_or_wrong_shape():
    with pytest.raises(aftmesh.InvalidSizeError, match="ZeroDivisionError"):
        aftmesh.generate(box(0, 0, 1, 1), lambda x, y: 1 / 0)
    with pytest.raises(aftmesh.InvalidSizeError):
        aftmesh.generate(box(0, 0, 1, 1), lambda x, y: np.ones(3))
    with pytest.raises(aftmesh.InvalidSizeError):
        aftmesh.generate(box(0, 0, 1, 1), lambda x, y: "small")


@pytest.mark.parametrize(
    "option",
    [
        {"order": "sideways"},
        {"order": None},
        {"order": 0},
        {"max_triangles": 0},
        {"max_triangles": -3},
        {"max_triangles": 2.5},
        {"max_triangles": True},
        {"max_triangles": "10"},
        {"min_area": -1.0},
        {"min_area": float("nan")},
        {"min_area": float("inf")},
        {"close_factor": 2.0},
        {"close_factor": -0.1},
        {"close_factor": float("nan")},
        {"smooth": -1},
    ],
)
def test_bad_options(option):
    with pytest.raises(aftmesh.InvalidOptionError) as err:
        aftmesh.generate(box(0, 0, 1, 1), 0.3, **option)
    assert list(option)[0] in str(err.value)


@pytest.mark.parametrize("gradation", [0.5, 0.0, -1.0, float("nan"), float("inf")])
def test_bad_gradation(gradation):
    with pytest.raises(aftmesh.InvalidSizeError, match="gradation"):
        aftmesh.generate(box(0, 0, 1, 1), 0.3, gradation=gradation)


@pytest.mark.parametrize(
    "domain",
    [
        Polygon(),
        MultiPolygon(),
        GeometryCollection(),
        [],
        np.zeros((0, 2)),
        LineString([(0, 0), (1, 1)]),
        Point(0, 0),
        [(0, 0), (1, 1)],
        [(0, 0), (1, 0), (2, 0)],
        [(0, 0), (1, 0), (1, 0)],
        dict(vertices=[(0, 0), (1, 0), (0, 1)]),
        dict(vertices=np.zeros((0, 2)), segments=[]),
    ],
    ids=[
        "polygon",
        "multipolygon",
        "collection",
        "list",
        "array",
        "linestring",
        "point",
        "two-points",
        "collinear",
        "repeated",
        "dict-no-segments",
        "dict-empty",
    ],
)
def test_empty_or_degenerate_domains(domain):
    with pytest.raises(aftmesh.InvalidDomainError):
        aftmesh.generate(domain, 0.3)


@pytest.mark.parametrize(
    "domain, error, words",
    [
        ([(0, 0), (1, np.nan), (1, 1)], aftmesh.InvalidDomainError, ["vertex 1", "finite"]),
        ([(0, 0), (1, np.inf), (1, 1)], aftmesh.InvalidDomainError, ["vertex 1", "finite"]),
        (
            dict(vertices=[(0, 0), (1, 0), (0, 1)], segments=[(0, 1), (1, 5)]),
            aftmesh.InvalidInputError,
            ["segments[1]"],
        ),
        (
            dict(vertices=[(0, 0), (1, 0), (0, 1)], segments=[(0, 1), (1, -1)]),
            aftmesh.InvalidInputError,
            ["segments[1]"],
        ),
        (
            dict(vertices=[(0, 0), (1, 0), (np.nan, 1)], segments=[(0, 1), (1, 2), (2, 0)]),
            aftmesh.InvalidInputError,
            ["vertices[2]"],
        ),
        (
            dict(vertices=[(0, 0), (1, 0), (0, 1)], segments=[(0, 1), (1, 1), (2, 0)]),
            aftmesh.InvalidInputError,
            ["segments[1]"],
        ),
        (
            dict(
                vertices=[(0, 0), (1, 0), (1, 1), (0, 1)],
                segments=[(0, 1), (1, 2), (2, 3), (3, 0)],
                holes=[(5, 5)],
            ),
            aftmesh.InvalidDomainError,
            ["holes[0]"],
        ),
        (
            dict(
                vertices=[(0, 0), (1, 0), (1, 1), (0, 1)],
                segments=[(0, 1), (1, 2), (2, 3), (3, 0)],
                regions=[(0.5, 0.5)],
            ),
            aftmesh.InvalidInputError,
            ["regions"],
        ),
        (dict(segments=[(0, 1)]), aftmesh.InvalidInputError, ["vertices"]),
        (
            GeometryCollection([box(0, 0, 1, 1), LineString([(0.5, 0.5), (3, 3)])]),
            aftmesh.InvalidDomainError,
            ["constraint line 0"],
        ),
        (
            GeometryCollection([box(0, 0, 1, 1), Point(3, 3)]),
            aftmesh.InvalidDomainError,
            ["fixed point 0"],
        ),
        (5, aftmesh.InvalidDomainError, ["int"]),
        ([box(0, 0, 1, 1), "square"], aftmesh.InvalidDomainError, ["region 1"]),
    ],
)
def test_bad_input_named(domain, error, words):
    with pytest.raises(error) as err:
        aftmesh.generate(domain, 0.3)
    for w in words:
        assert w in str(err.value), str(err.value)


def test_crossing_segments_named():
    d = dict(
        vertices=[(0, 0), (1, 0), (1, 1), (0, 1)],
        segments=[(0, 2), (1, 3), (0, 1), (1, 2), (2, 3), (3, 0)],
    )
    with pytest.raises(aftmesh.CrossingSegmentsError) as err:
        aftmesh.generate(d, split_boundary=False)
    assert set(err.value.segments) == {0, 1}
    assert "segments[0]" in str(err.value) and "segments[1]" in str(err.value)


@pytest.mark.parametrize("split_boundary", [True, False])
@pytest.mark.parametrize(
    "inner",
    [
        [(-1, 0), (1, 0), (0, -1), (0, 1)],  # both halved exactly at the crossing
        [(-1, 0), (1, 0), (0, -1), (0, 0.5)],  # one runs through the other's midpoint
        [(-1, 0.1), (1, -0.1), (0.3, -1), (-0.2, 1)],  # a plain crossing
    ],
)
def test_dict_crossings_are_refused_even_where_split_points_hide_them(inner, split_boundary):
    """A dict's crossing segments are refused, checked before the size splits them:
    split at size 1, the first two inner pairs meet at a split point, where their
    pieces no longer cross, and the boundary CDT would node them without a word."""
    d = dict(
        vertices=[(-2, -2), (2, -2), (2, 2), (-2, 2), *inner],
        segments=[(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (6, 7)],
    )
    for size in (1.0, 0.3):
        with pytest.raises(aftmesh.CrossingSegmentsError) as err:
            aftmesh.generate(d, size, split_boundary=split_boundary)
        assert set(err.value.segments) == {4, 5}, str(err.value)


def test_dict_sources_are_named_by_position_without_a_string_each():
    """A dict's sources are its segments, named ``segments[i]``: info["sources"]
    reads like that list (index, slice, equality, numpy, pickle) but holds no string
    per segment, which a call on a large input would otherwise pay for."""
    d = dict(
        vertices=[(0, 0), (1, 0), (1, 1), (0, 1)],
        segments=[(0, 1), (1, 2), (2, 3), (3, 0)],
    )
    mesh = valid(aftmesh.generate(d, 0.3), 1.0)
    names = mesh.info["sources"]
    listed = [f"segments[{i}]" for i in range(4)]
    assert names == listed and listed == names and list(names) == listed
    assert names[-1] == "segments[3]" and names[1:3] == listed[1:3]
    assert np.array(names)[mesh.segment_markers].tolist() == [
        listed[k] for k in mesh.segment_markers
    ]
    assert pickle.loads(pickle.dumps(names)) == listed
    assert names != listed[:3] and names != "segments[0]"
    with pytest.raises(IndexError, match="source 4"):
        names[4]
    assert not hasattr(names, "__dict__")  # two fields, whatever the input's size


def test_regression_crossing_error_names_input_segments():
    """When the size splits the crossing segments, the error names the pieces'
    internal indices (segments[7], segments[2] of a 6-segment input) instead of the
    caller's segments 0 and 1."""
    d = dict(
        vertices=[(0, 0), (1, 0), (1, 1), (0, 1)],
        segments=[(0, 2), (1, 3), (0, 1), (1, 2), (2, 3), (3, 0)],
    )
    with pytest.raises(aftmesh.CrossingSegmentsError) as err:
        aftmesh.generate(d, 0.3)
    assert set(err.value.segments) == {0, 1}, str(err.value)


def test_crossing_constraint_lines_are_noded():
    """Crossing LineStrings in a GeometryCollection are split where they cross."""
    gc = GeometryCollection(
        [
            box(0, 0, 2, 2),
            LineString([(0.5, 0.5), (1.5, 1.5)]),
            LineString([(0.5, 1.5), (1.5, 0.5)]),
        ]
    )
    mesh = valid(aftmesh.generate(gc, 0.2), 4.0)
    assert (1.0, 1.0) in dc.coordinate_keys(mesh.points)
    for a, b in (((0.5, 0.5), (1.5, 1.5)), ((0.5, 1.5), (1.5, 0.5))):
        assert covered_by_segments(mesh, a, b)


# -------------------------------------------- fuzz: a Mesh or a named ValueError
GRID = st.tuples(st.integers(0, 4), st.integers(0, 4))


@given(
    ring=st.lists(GRID, min_size=0, max_size=8),
    form=st.sampled_from(["array", "list", "polygon", "dict"]),
)
def test_any_ring_gives_mesh_or_input_error(ring, form):
    """Grid rings: duplicates, collinear runs, self-intersections, too few points.
    (size=None keeps the edges whole: this exercises input handling.)"""
    pts = np.array(ring, dtype=float).reshape(-1, 2)
    if form == "array":
        domain = pts
    elif form == "list":
        domain = [tuple(p) for p in ring]
    elif form == "polygon":
        domain = Polygon(pts) if len(pts) >= 3 else Polygon()
    else:
        n = len(pts)
        domain = dict(vertices=pts, segments=[(i, (i + 1) % n) for i in range(n)])
    try:
        mesh = aftmesh.generate(domain)
    except aftmesh.InvalidInputError:
        return
    poly = Polygon(pts)
    assert poly.is_valid or form == "dict"
    valid(mesh, mesh.area() if form == "dict" else poly.area)
