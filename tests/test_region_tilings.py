"""Many regions in one call (a tiling of parcels or materials): the region checks and
the classification of the pieces look only at neighbours (tree queries), and give
what asking every polygon about every piece gives."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import MultiPoint, Polygon, box

import aftmesh
from aftmesh import inputs, noding, regions
from aftmesh.checks import check_mesh
from aftmesh.inputs import REGION_OVERLAP, first_overlap


def grid(k: int) -> list[Polygon]:
    return [box(i, j, i + 1, j + 1) for i in range(k) for j in range(k)]


def voronoi(n: int, seed: int, seg: float | None = None) -> list[Polygon]:
    """Voronoi cells clipped to the unit square; with `seg`, each cell's edges are
    split on its own, so neighbours' shared edges differ by rounding (slivers, near
    crossings: what real parcel data has)."""
    rng = np.random.default_rng(seed)
    cells = shapely.get_parts(
        shapely.voronoi_polygons(MultiPoint(rng.random((n, 2))), extend_to=box(0, 0, 1, 1))
    )
    cells = shapely.intersection(cells, box(0, 0, 1, 1))
    return list(cells if seg is None else shapely.segmentize(cells, seg))


def pairwise_overlap(polygons):
    """first_overlap's definition, every pair asked."""
    for i in range(len(polygons)):
        for j in range(i + 1, len(polygons)):
            overlap = polygons[i].intersection(polygons[j]).area
            if overlap > REGION_OVERLAP * min(polygons[i].area, polygons[j].area):
                return i, j, overlap
    return None


def regions_by_centroid(mesh, polygons):
    """Each triangle's region from its centroid, for a mesh whose triangles are not
    slivers across two regions."""
    c = np.asarray(mesh.points)[np.asarray(mesh.triangles)].mean(axis=1)
    out = np.full(len(c), -1)
    for k, p in enumerate(polygons):
        out[shapely.contains_xy(p, c[:, 0], c[:, 1]) & (out < 0)] = k
    return out


@pytest.mark.parametrize("polygons", [grid(6), voronoi(60, seed=3)], ids=["grid", "voronoi"])
def test_tiling_regions_are_the_polygons_holding_the_triangles(polygons, checked):
    mesh = checked(aftmesh.generate(polygons, 0.12 if len(polygons) == 36 else 0.03))
    found = regions_by_centroid(mesh, polygons)
    assert (found == np.asarray(mesh.regions)).all()
    areas = np.bincount(np.asarray(mesh.regions), weights=_areas(mesh), minlength=len(polygons))
    assert areas == pytest.approx([p.area for p in polygons], rel=1e-9)


def _areas(mesh):
    p = np.asarray(mesh.points)[np.asarray(mesh.triangles)]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def test_tiling_with_rounding_slivers_is_meshed_and_checked():
    """Cells whose shared edges differ by rounding (Triangle's `pq` refuses this one):
    meshed, every triangle in one region, the regions' areas the cells' within the
    slivers' rounding."""
    cells = voronoi(40, seed=5, seg=0.01)
    mesh = aftmesh.generate(cells, 0.04)
    check_mesh(mesh, domain_area=1.0)
    assert set(np.unique(np.asarray(mesh.regions)).tolist()) == set(range(len(cells)))


@pytest.mark.parametrize(
    "polygons",
    [
        grid(5),
        grid(5) + [box(2.5, 2.5, 3.5, 3.5)],  # overlaps four cells: the first pair named
        [box(0, 0, 1, 1), box(2, 0, 3, 1), box(2.5, 0.5, 4, 2)],
        voronoi(30, seed=1) + [box(0.4, 0.4, 0.45, 0.45)],
        voronoi(30, seed=2, seg=0.02),  # rounding overlaps below REGION_OVERLAP
    ],
)
def test_first_overlap_is_the_first_pair_of_the_pairwise_search(polygons):
    assert first_overlap(polygons) == pairwise_overlap(polygons)


def test_overlap_in_a_large_tiling_names_its_regions():
    polygons = grid(12) + [box(7.5, 3.25, 7.75, 3.5)]
    with pytest.raises(aftmesh.InvalidDomainError, match=r"regions 87 and 144 overlap"):
        aftmesh.generate(polygons, 0.3)


def test_classification_by_tree_is_the_one_by_every_polygon(monkeypatch):
    """The pieces of a tiling with rounding slivers (probes on edges, so the exact
    fallback runs): the tree's candidates give the answer of every polygon asked."""
    cells = voronoi(50, seed=7, seg=0.01)
    seen = {}
    real = regions.classify_pieces

    def keep(polygons, probes, corners):
        seen["args"] = (polygons, probes, corners)
        return real(polygons, probes, corners)

    monkeypatch.setattr("aftmesh._stages.classify_pieces", keep)
    aftmesh.generate(cells, 0.05)
    polygons, probes, corners = seen["args"]
    by_tree = real(polygons, probes, corners)
    monkeypatch.setattr(regions, "FEW_POLYGONS", len(polygons))
    assert len(regions._probes_not_inside(probes, corners)) > 0
    assert (real(polygons, probes, corners) == by_tree).all()


def _reference_inside(poly, corners):
    """The even-odd test of _exact_inside with every comparison in rationals."""
    px = sum(Fraction(float(v)) for v in corners[:, 0]) / 3
    py = sum(Fraction(float(v)) for v in corners[:, 1]) / 3
    inside = False
    for part in shapely.get_parts(poly):
        for ring in [part.exterior, *part.interiors]:
            c = np.asarray(ring.coords)[:, :2]
            for (xa, ya), (xb, yb) in zip(c[:-1].tolist(), c[1:].tolist()):
                if (ya > py) != (yb > py):
                    x = Fraction(xa) + (py - Fraction(ya)) * (Fraction(xb) - Fraction(xa)) / (
                        Fraction(yb) - Fraction(ya)
                    )
                    if px < x:
                        inside = not inside
    return inside


@given(
    st.lists(st.integers(-6, 6), min_size=6, max_size=6),
    st.sampled_from([1.0, 0.1, 1e-9, 3.0**-20]),
)
def test_exact_inside_decides_as_rationals_do(ints, scale):
    """Triangles whose centroids sit on a ring vertex's y (or within an ulp of it):
    the float pre-test decides only where it is sure."""
    poly = Polygon(
        np.array([(0, 0), (4, 0), (4, 1), (2, 1), (2, 3), (4, 3), (4, 4), (0, 4)]) * scale,
        [np.array([(0.5, 1.5), (1.5, 1.5), (1.5, 2.5), (0.5, 2.5)]) * scale],
    )
    corners = (np.array(ints, dtype=np.float64).reshape(3, 2) / 3.0 + 2.0) * scale
    inside = regions._exact_inside(regions._ring_coordinates(poly), corners)
    assert inside == _reference_inside(poly, corners)


@pytest.mark.parametrize(
    "polygons",
    [grid(4), voronoi(25, seed=4), voronoi(25, seed=4, seg=0.02)],
    ids=["grid", "voronoi", "voronoi-slivers"],
)
def test_crossing_proof_leaves_the_domain_node_crossings_makes(polygons, monkeypatch):
    kept = inputs.to_domain(polygons)
    monkeypatch.setattr(noding, "_proved_uncrossed", lambda verts, segs: False)
    noded = inputs.to_domain(polygons)
    for name in ("vertices", "segments", "segment_edge", "edge_source"):
        assert np.array_equal(getattr(kept, name), getattr(noded, name)), name
    assert kept.cleanup == noded.cleanup


# ----------------------------------------------------- constraint lines and points
# The input side of a domain with many constraint lines or fixed points works on all
# of them at once; these references are the one-by-one forms it replaced.


def _reference_line_chain(coords):
    c = np.asarray(coords, dtype=np.float64)
    keep = np.ones(len(c), dtype=bool)
    keep[:-1] = (c[:-1] != c[1:]).any(axis=1)
    mid = 0.5 * (c[:-1] + c[1:])
    return c[keep], np.flatnonzero(keep), max(len(c) - 1, 0), mid


def _reference_with_lines(rings, lines, line_names, points):
    verts, segs, edges, source, mids, names = rings
    names = list(names)
    verts, segs, edges, source, mids = [verts], [segs], [edges], [source], [mids]
    n_vertices, n_edges = len(verts[0]), len(mids[0])
    for line, name in zip(lines, line_names):
        c, ids, n, mid = _reference_line_chain(np.asarray(line.coords)[:, :2])
        source.append(np.full(n, len(names)))
        names.append(name)
        mids.append(mid)
        if len(c) >= 2:
            idx = np.arange(len(c))
            verts.append(c)
            segs.append(np.c_[idx[:-1], idx[1:]] + n_vertices)
            edges.append(ids[: len(c) - 1] + n_edges)
            n_vertices += len(c)
        elif len(c):
            verts.append(c)
            n_vertices += 1
        n_edges += n
    if points:
        verts.append(np.concatenate([np.asarray(p.coords)[:, :2] for p in points]))
    cat = np.concatenate
    return cat(verts), cat(segs), cat(edges), cat(source), cat(mids), names


coordinate = st.integers(0, 4).map(float)
line_coords = st.lists(st.tuples(coordinate, coordinate), min_size=2, max_size=6)


@given(st.lists(line_coords, min_size=1, max_size=6), st.integers(0, 3))
def test_lines_taken_together_as_one_by_one(lines_xy, n_points):
    """Repeated vertices (runs, whole lines at one place) included."""
    from shapely.geometry import LineString, Point

    rings = inputs._ring_arrays([box(-1, -1, 6, 6)], ["the polygon"], [])
    lines = [LineString(c) for c in lines_xy]
    names = [f"constraint line {k}" for k in range(len(lines))]
    points = [Point(k, 0.5) for k in range(n_points)]
    got = inputs._with_lines(rings, lines, names, points)
    want = _reference_with_lines(rings, lines, names, points)
    for a, b in zip(got[:5], want[:5]):
        assert np.array_equal(a, b) and a.dtype == b.dtype
    assert got[5] == want[5]


def test_collection_parts_are_sorted_and_named_as_before():
    from shapely.geometry import (
        GeometryCollection,
        LinearRing,
        LineString,
        MultiLineString,
        MultiPoint,
        MultiPolygon,
        Point,
    )

    parts = [
        box(0, 0, 10, 10),
        LineString([(1, 1), (2, 2)]),
        MultiLineString([[(3, 1), (4, 2)], [(5, 1), (6, 2)]]),
        MultiPoint([(7, 7), (8, 8)]),
        MultiLineString([[(1, 5), (2, 5)]]),
        MultiPolygon([box(20, 0, 21, 1), box(22, 0, 23, 1)]),
        LinearRing([(1, 8), (2, 8), (2, 9)]),
        Point(9, 9),
    ]
    polygons, lines, names, points = inputs._split_geometry(GeometryCollection(parts))
    assert [p.bounds for p in polygons] == [
        (0, 0, 10, 10),
        (20, 0, 21, 1),
        (22, 0, 23, 1),
    ]
    assert names == [
        "constraint line 0",
        "part 0 of constraint line 1",
        "part 1 of constraint line 1",
        "constraint line 2",
        "constraint line 3",
    ]
    assert [np.asarray(x.coords).tolist() for x in lines][1] == [[3, 1], [4, 2]]
    assert [p.coords[0] for p in points] == [(7, 7), (8, 8), (9, 9)]
    with pytest.raises(aftmesh.InvalidDomainError, match="cannot mesh a GeometryCollection"):
        inputs._split_geometry(GeometryCollection([box(0, 0, 1, 1), GeometryCollection(parts)]))


def _reference_node_crossings(verts, segs, src):
    """One round of node_crossings as it was: the crossing points pair by pair, each
    segment cut at its points one segment at a time."""
    from shapely.geometry import Point

    lines, pairs = noding._crossing_pairs(verts, segs)
    base, extra, cuts = len(verts), [], {}
    for i, j in pairs.T:
        for p in shapely.get_parts(shapely.intersection(lines[i], lines[j])):
            if isinstance(p, Point):
                extra.append(np.asarray(p.coords)[0, :2])
                cuts.setdefault(int(i), []).append(base + len(extra) - 1)
                cuts.setdefault(int(j), []).append(base + len(extra) - 1)
    if not extra:
        return verts, segs, src
    verts = np.concatenate([verts, np.array(extra).reshape(-1, 2)])
    out_s, out_src = [], []
    for k in range(len(segs)):
        if k not in cuts:
            out_s.append(segs[k][None, :])
            out_src.append([src[k]])
            continue
        chain = noding._chain(verts, segs[k], cuts[k])
        out_s.append(np.c_[chain[:-1], chain[1:]])
        out_src.append([src[k]] * (len(chain) - 1))
    return verts, np.concatenate(out_s).astype(np.int64), np.concatenate(out_src).astype(np.int64)


@given(st.lists(st.tuples(coordinate, coordinate, coordinate, coordinate), min_size=2, max_size=8))
def test_crossings_found_together_as_pair_by_pair(quads):
    """Segments on a small grid of coordinates: crossings, three segments through one
    point, overlaps and shared ends."""
    xy = np.array([[q[0], q[1], q[2], q[3]] for q in quads]).reshape(-1, 2)
    verts, inverse = noding.unique_rows(xy)
    segs = inverse.reshape(-1, 2).astype(np.int64)
    segs = segs[segs[:, 0] != segs[:, 1]]
    if len(segs) < 2:
        return
    src = np.arange(len(segs), dtype=np.int64)
    lines, pairs = noding._crossing_pairs(verts, segs)
    extra, cuts = noding._crossing_points(lines, pairs, len(verts))
    got_v = np.concatenate([verts, extra]) if len(extra) else verts
    got_s, got_src = noding._cut(got_v, segs, src, cuts) if len(extra) else (segs, src)
    want_v, want_s, want_src = _reference_node_crossings(verts, segs, src)
    assert np.array_equal(got_v, want_v)
    assert np.array_equal(got_s, want_s) and np.array_equal(got_src, want_src)


def _nan_region():
    with np.errstate(invalid="ignore"):  # shapely warns as it builds the ring
        return Polygon([(17, 0), (18, float("nan")), (18, 1)])


@pytest.mark.parametrize(
    "bad, message",
    [
        (lambda: Polygon([(17, 0), (18, 1), (18, 0), (17, 1)]), r"region 12 is not a valid"),
        (lambda: Polygon([(17, 0), (18, 0), (19, 0)]), r"region 12 is not a valid polygon: the"),
        (Polygon, r"region 12 is empty"),
        (_nan_region, r"region 12, exterior ring: vertex 1"),
    ],
    ids=["bowtie", "flat", "empty", "nan"],
)
def test_bad_region_among_many_named_as_alone(bad, message):
    """Many regions are checked all at once; a bad one is still named as
    check_polygon names it, and before a later region that is not a polygon."""
    regions = grid(4)[:12] + [bad()] + grid(4)[12:]
    with pytest.raises(aftmesh.InvalidDomainError, match=message):
        aftmesh.generate(regions, 0.5)
    with pytest.raises(aftmesh.InvalidDomainError, match=message):
        aftmesh.generate([*regions, "not a polygon"], 0.5)


def test_region_that_is_not_a_polygon_after_many_named():
    with pytest.raises(aftmesh.InvalidDomainError, match="region 16 is a str"):
        aftmesh.generate([*grid(4), "not a polygon"], 0.5)


@given(
    st.lists(st.integers(-3, 3), min_size=6, max_size=6),
    st.tuples(st.integers(-3, 3), st.integers(-3, 3)),
)
def test_probes_not_inside_as_one_by_one(ints, probe):
    """Flat triangles, probes on an edge or a corner, outside or strictly inside."""
    from aftmesh._kernel import py_orient2d

    corners = np.array(ints, dtype=np.float64).reshape(1, 3, 2) / 3.0
    probes = np.array([probe], dtype=np.float64) / 3.0
    (ax, ay), (bx, by), (cx, cy) = corners[0].tolist()
    x, y = probes[0].tolist()
    side = py_orient2d(ax, ay, bx, by, cx, cy)
    inside = (
        side != 0
        and py_orient2d(ax, ay, bx, by, x, y) == side
        and py_orient2d(bx, by, cx, cy, x, y) == side
        and py_orient2d(cx, cy, ax, ay, x, y) == side
    )
    assert regions._probes_not_inside(probes, corners).tolist() == ([] if inside else [0])


def test_bad_part_among_many_parts_named_as_alone():
    """A multipolygon's (or a collection's) many parts are checked all at once too; a
    bad part is still named as check_polygon names it."""
    from shapely.geometry import GeometryCollection, LineString, MultiPolygon

    parts = [box(2 * i, 0, 2 * i + 1, 1) for i in range(12)]
    bowtie = Polygon([(30, 0), (31, 1), (31, 0), (30, 1)])
    with pytest.raises(aftmesh.InvalidDomainError, match="polygon 5 is not a valid polygon"):
        aftmesh.generate(MultiPolygon(parts[:5] + [bowtie] + parts[5:]), 0.5)
    with pytest.raises(aftmesh.InvalidDomainError, match="polygon 12 is not a valid polygon"):
        aftmesh.generate(
            GeometryCollection([*parts, bowtie, LineString([(0.2, 0.5), (0.8, 0.5)])]), 0.5
        )
    mesh = aftmesh.generate(MultiPolygon(parts), 0.5)
    check_mesh(mesh, domain_area=12.0)
