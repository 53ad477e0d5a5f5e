"""The kernel's proof that a lone polygon is valid (cython_ext/simple_rings.pxi, used
by inputs.proved_polygon in place of GEOS's validity check) against GEOS: what it
proves valid GEOS finds valid, the Domain it leads to is the one from_geometry makes,
and what it cannot prove meshes, or is refused, as before."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import shapely.affinity
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import MultiPolygon, Polygon, box

import aftmesh
from aftmesh import _kernel, inputs
from aftmesh.errors import InvalidDomainError

DOMAIN_ARRAYS = (
    "vertices",
    "segments",
    "segment_edge",
    "edge_source",
    "edge_midpoints",
    "edge_is_ring",
)
DOMAIN_FIELDS = ("source_names", "cleanup", "report", "area", "n_rings", "holes", "region_points")


def assert_same_domain(a, b):
    for name in DOMAIN_ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name
    for name in DOMAIN_FIELDS:
        assert getattr(a, name) == getattr(b, name), name
    assert len(a.polygons) == len(b.polygons)
    assert all(p.equals_exact(q, 0.0) for p, q in zip(a.polygons, b.polygons))


def check_against_geos(poly: Polygon | MultiPolygon) -> bool:
    """proved_polygon(poly), held to GEOS and to from_geometry; whether it proved."""
    proved = inputs.proved_polygon(poly)
    if proved is None:
        return False
    assert poly.is_valid, poly.wkt
    assert_same_domain(proved, inputs.from_geometry(poly))
    return True


# Few values on a small grid: rings that touch, overlap, fold back and nest often.
grid = st.integers(0, 4).map(float)


@st.composite
def grid_polygons(draw):
    def ring(lo, hi, n):
        return draw(st.lists(st.tuples(lo, hi), min_size=n, max_size=n + 5))

    shell = ring(grid, grid, 3)
    holes = [ring(grid, grid, 3) for _ in range(draw(st.integers(0, 2)))]
    return Polygon(shell, holes)


@given(grid_polygons())
def test_what_the_kernel_proves_valid_geos_finds_valid(poly):
    check_against_geos(poly)


@given(st.lists(grid_polygons(), min_size=1, max_size=3), st.lists(st.integers(0, 5)))
def test_what_the_kernel_proves_a_valid_multipolygon_geos_finds_valid(polygons, shifts):
    # parts moved apart by whole grid units: apart, touching, overlapping or nested
    moved = [
        shapely.affinity.translate(p, 2.0 * (shifts[k] if k < len(shifts) else 0), 0.0)
        for k, p in enumerate(polygons)
    ]
    check_against_geos(MultiPolygon(moved))


# Triangles and quadrilaterals with corners on a small grid, as holes of a square or as
# parts beside it: they touch the square and each other at shared corners often, and
# at edges, cross or nest as often.
grid_ring = st.lists(st.tuples(grid, grid), min_size=3, max_size=4)


@given(st.lists(grid_ring, min_size=1, max_size=4), st.lists(grid_ring, max_size=3))
def test_rings_touching_at_corners_are_proved_only_where_geos_finds_them_valid(holes, parts):
    square = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], holes)
    check_against_geos(square)
    if parts:
        check_against_geos(MultiPolygon([square] + [Polygon(p) for p in parts]))


def diamonds(rows: int, per_row: int, row_gap: float) -> list[list[tuple[float, float]]]:
    """Rows of diamonds (squares turned by 45 degrees, half-diagonal 1), each touching
    the next in its row at a corner; rows row_gap apart."""
    out = []
    for j in range(rows):
        y = 1.0 + row_gap * j
        for i in range(per_row):
            x = 1.0 + 2.0 * i
            out.append([(x - 1, y), (x, y - 1), (x + 1, y), (x, y + 1)])
    return out


def test_chains_of_touching_holes_are_proved_and_meshed_as_without_the_proof(checked, monkeypatch):
    # 8 rows of 8 holes, each row a chain touching the exterior at its left end: the
    # touches form no cycle, so the interior is connected
    holes = diamonds(8, 8, 3.0)
    left_side = [(0.0, 1.0 + 3.0 * j) for j in range(7, -1, -1)]  # the rows' left corners
    poly = Polygon([(0, -1), (17, -1), (17, 24), (0, 24)] + left_side, holes)
    assert check_against_geos(poly)
    mesh = checked(aftmesh.generate(poly, 0.7))
    with monkeypatch.context() as m:
        m.setattr(inputs, "proved_polygon", lambda p: None)
        plain = aftmesh.generate(poly, 0.7)
    assert np.array_equal(mesh.points, plain.points)
    assert np.array_equal(mesh.triangles, plain.triangles)


def test_holes_touching_in_a_cycle_are_left_to_geos():
    # two rows of diamonds touching each other too: every four enclose a piece of the
    # interior, which is then not connected
    poly = Polygon([(-1, -1), (9, -1), (9, 9), (-1, 9)], diamonds(2, 4, 2.0))
    assert not poly.is_valid
    assert inputs.proved_polygon(poly) is None
    with pytest.raises(InvalidDomainError, match="not a valid polygon"):
        aftmesh.generate(poly, 0.5)


# A unit square, and a hole whose corners sit a few ulps from its edges or from each
# other: near-degenerate cases the proof must decide exactly.
ulps = st.integers(-3, 3)


@given(st.lists(st.tuples(ulps, ulps), min_size=4, max_size=4), st.floats(0.0, 1.0))
def test_holes_an_ulp_from_the_exterior_are_judged_as_geos_judges_them(moves, t):
    corners = [(0.5 * t, 0.0), (1.0, 0.5 * t), (1.0 - 0.5 * t, 1.0), (0.0, 1.0 - 0.5 * t)]
    hole = [
        (x + dx * math.ulp(1.0), y + dy * math.ulp(1.0)) for (x, y), (dx, dy) in zip(corners, moves)
    ]
    check_against_geos(Polygon([(0, 0), (1, 0), (1, 1), (0, 1)], [hole]))


SQUARE = [(0, 0), (4, 0), (4, 4), (0, 4)]
PINNED = {
    # name: (polygon, proved, valid)
    "square": (Polygon(SQUARE), True, True),
    "square with a hole": (Polygon(SQUARE, [[(1, 1), (2, 1), (2, 2)]]), True, True),
    "repeated vertices": (Polygon([(0, 0), (0, 0), (4, 0), (4, 4), (4, 4), (0, 4)]), True, True),
    "collinear vertices": (Polygon([(0, 0), (2, 0), (4, 0), (4, 4), (0, 4)]), True, True),
    "bow tie": (Polygon([(0, 0), (4, 4), (4, 0), (0, 4)]), False, False),
    "spike folding back": (Polygon([(0, 0), (4, 0), (2, 0), (2, 4)]), False, False),
    "ring touching itself": (
        Polygon([(0, 0), (4, 0), (2, 2), (4, 4), (0, 4), (2, 2)]),
        False,
        False,
    ),
    "hole touching the exterior at a corner": (
        Polygon(SQUARE, [[(0, 0), (1, 2), (2, 1)]]),
        True,
        True,
    ),
    "hole touching an exterior edge": (Polygon(SQUARE, [[(2, 0), (3, 1), (1, 1)]]), False, True),
    "holes touching at a point": (
        Polygon(SQUARE, [[(1, 1), (2, 2), (1, 2)], [(2, 2), (3, 3), (3, 2)]]),
        True,
        True,
    ),
    "two holes touching the exterior at one corner": (
        Polygon(SQUARE, [[(0, 0), (2, 0.5), (2, 1.5)], [(0, 0), (1.5, 2), (0.5, 2)]]),
        True,
        True,
    ),
    "hole touching the exterior twice": (
        Polygon(SQUARE, [[(0, 0), (2, 1), (4, 4), (1, 2)]]),
        False,
        False,
    ),
    "holes and the exterior touching in a cycle": (
        Polygon(SQUARE, [[(0, 0), (2, 1), (2, 2)], [(2, 2), (1, 2.5), (0, 4)]]),
        False,
        False,
    ),
    "holes sharing an edge from a corner": (
        Polygon(SQUARE, [[(0, 0), (2, 1), (2, 2), (1, 2)], [(0, 0), (1, 2), (0.5, 2.5)]]),
        False,
        False,
    ),
    "hole through the exterior at a corner": (
        Polygon(SQUARE, [[(0, 0), (-1, 1), (1, 1)]]),
        False,
        False,
    ),
    "hole inside a hole it touches": (
        Polygon(SQUARE, [[(1, 1), (3, 1), (3, 3), (1, 3)], [(3, 3), (2, 2.5), (2.5, 2)]]),
        False,
        False,
    ),
    "hole along an exterior edge from a corner": (
        Polygon(SQUARE, [[(0, 0), (2, 0), (1, 1)]]),
        False,
        False,
    ),
    "hole outside": (Polygon(SQUARE, [[(5, 5), (6, 5), (6, 6)]]), False, False),
    "nested holes": (
        Polygon(
            SQUARE, [[(0.5, 0.5), (3.5, 0.5), (3.5, 3.5), (0.5, 3.5)], [(1, 1), (2, 1), (2, 2)]]
        ),
        False,
        False,
    ),
    "crossing holes": (
        Polygon(SQUARE, [[(1, 1), (2, 1), (2, 2), (1, 2)], [(1.5, 1.5), (3, 1.5), (3, 3)]]),
        False,
        False,
    ),
    "z values": (Polygon([(0, 0, 1), (4, 0, 1), (4, 4, 1), (0, 4, 1)]), False, True),
    "two parts apart": (MultiPolygon([box(0, 0, 1, 1), box(2, 0, 3, 1)]), True, True),
    "one part in a hole of the other": (
        MultiPolygon(
            [Polygon(SQUARE, [[(1, 1), (3, 1), (3, 3), (1, 3)]]), box(1.5, 1.5, 2.5, 2.5)]
        ),
        True,
        True,
    ),
    "one part of a multipolygon": (MultiPolygon([Polygon(SQUARE)]), True, True),
    # every corner of a ring touching others: placed from a touched corner
    "a square touching others at all its corners": (
        MultiPolygon(
            [box(i, j, i + 1, j + 1) for i in range(3) for j in range(3) if (i + j) % 2 == 0]
        ),
        True,
        True,
    ),
    "a part touching the hole it is in at all its corners": (
        MultiPolygon(
            [
                Polygon(SQUARE, [[(1, 1), (2, 1), (3, 1), (3, 2), (3, 3), (2, 3), (1, 3), (1, 2)]]),
                Polygon([(2, 1), (3, 2), (2, 3), (1, 2)]),
            ]
        ),
        True,
        True,
    ),
    "a hole touching others at all its corners": (
        Polygon(
            [(0, 0), (6, 0), (6, 6), (0, 6)],
            [[(0, 0), (2, 1), (1, 2)], [(2, 1), (4, 1), (3, 2)], [(1, 2), (2, 4), (1, 4)]],
        ),
        True,
        True,
    ),
    "a part inside another, touching it at all its corners": (
        MultiPolygon(
            [
                Polygon([(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (0, 1)]),
                Polygon([(1, 0), (2, 1), (1, 2), (0, 1)]),
            ]
        ),
        False,
        False,
    ),
    "parts touching at a corner": (MultiPolygon([box(0, 0, 1, 1), box(1, 1, 2, 2)]), True, True),
    "parts touching at two points": (
        MultiPolygon(
            [
                Polygon([(0, 0), (2, 0), (1.5, 1), (2, 2), (0, 2)]),
                Polygon([(2, 0), (3, 1), (2, 2), (2.5, 1)]),
            ]
        ),
        True,
        True,
    ),
    "part in a hole it touches": (
        MultiPolygon(
            [
                Polygon(SQUARE, [[(1, 1), (3, 1), (3, 3), (1, 3)]]),
                Polygon([(1, 1), (2.5, 1.5), (1.5, 2.5)]),
            ]
        ),
        True,
        True,
    ),
    "parts sharing an edge": (MultiPolygon([box(0, 0, 1, 1), box(1, 0, 2, 1)]), False, False),
    "one part inside the other": (MultiPolygon([box(0, 0, 4, 4), box(1, 1, 2, 2)]), False, False),
    "overlapping parts": (MultiPolygon([box(0, 0, 2, 2), box(1, 1, 3, 3)]), False, False),
}


@pytest.mark.parametrize("name", list(PINNED))
def test_pinned_polygons_are_proved_only_when_valid_and_touching_at_most_at_vertices(name):
    poly, proved, valid = PINNED[name]
    assert poly.is_valid == valid
    assert check_against_geos(poly) == proved


@pytest.mark.parametrize("name", [n for n, (_, _, valid) in PINNED.items() if valid])
def test_valid_polygons_mesh_the_same_with_and_without_the_proof(name, monkeypatch, checked):
    poly = PINNED[name][0]
    mesh = checked(aftmesh.generate(poly, 0.5))
    with monkeypatch.context() as m:
        m.setattr(inputs, "proved_polygon", lambda p: None)
        plain = aftmesh.generate(poly, 0.5)
    for array in ("points", "triangles", "segments", "segment_sources", "regions"):
        assert np.array_equal(getattr(mesh, array), getattr(plain, array)), array
    assert mesh.info["cleanup"] == plain.info["cleanup"]
    assert mesh.info["sources"] == plain.info["sources"]


@pytest.mark.parametrize("name", [n for n, (_, _, valid) in PINNED.items() if not valid])
def test_invalid_polygons_are_still_refused_or_merged_as_before(name, monkeypatch):
    domain = PINNED[name][0]
    if isinstance(domain, Polygon):
        with pytest.raises(InvalidDomainError, match="not a valid polygon"):
            aftmesh.generate(domain, 0.5)
        return
    # an invalid multipolygon's parts are merged by their union, as before
    mesh = aftmesh.generate(domain, 0.5)
    with monkeypatch.context() as m:
        m.setattr(inputs, "proved_polygon", lambda p: None)
        plain = aftmesh.generate(domain, 0.5)
    assert np.array_equal(mesh.points, plain.points)
    assert np.array_equal(mesh.triangles, plain.triangles)


def test_a_polygon_with_many_holes_apart_is_proved_and_meshed(checked):
    holes = [
        shapely.Point(1 + 2 * i, 1 + 2 * j).buffer(0.4, 3).exterior.coords
        for i in range(8)
        for j in range(8)
    ]
    poly = Polygon(box(0, 0, 16, 16).exterior.coords, holes)
    assert check_against_geos(poly)
    mesh = checked(aftmesh.generate(poly, 0.5))
    assert abs(mesh.area() - poly.area) < 1e-9 * poly.area


def test_a_thousand_holes_are_placed_without_a_test_per_ring_pair():
    # 900 holes in rows, each touching the next: the rings are placed by their rays'
    # crossings over a band's segments, not ring by ring against every other ring
    holes = [
        [(i + 0.1, j + 0.5), (i + 0.5, j + 0.2), (i + 1.1, j + 0.5), (i + 0.5, j + 0.8)]
        for i in range(30)
        for j in range(30)
    ]
    poly = Polygon([(0, 0), (32, 0), (32, 31), (0, 31)], holes)
    assert check_against_geos(poly)


def test_rings_proved_valid_refuses_indices_outside_its_arrays():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    edge = np.arange(3, dtype=np.int64)
    ring = np.zeros(3, dtype=np.int64)
    good = np.array([[0, 1], [1, 2], [2, 0]], dtype=np.int64)
    one = np.array([0, 1], dtype=np.int64)
    assert _kernel.rings_proved_valid(pts, good, edge, ring, one)
    with pytest.raises(ValueError, match="segment 2"):
        _kernel.rings_proved_valid(pts, np.array([[0, 1], [1, 2], [2, 3]]), edge, ring, one)
    with pytest.raises(ValueError, match="segment 0"):
        _kernel.rings_proved_valid(pts, good, np.array([5, 1, 2]), ring, one)
