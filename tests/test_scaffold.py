"""The scaffold (``generate(..., scaffold=...)``): temporary vertices planted in the
unmeshed CDT before the front starts, each removed before the front reaches it.

What it must not change, checked on every mesh made here with the scaffold forced on:

* the mesh is valid, conforming and the CDT of its vertices and the input edges
  (Triangle as the oracle, exact arithmetic where points are cocircular);
* no scaffold vertex is left: the points are the boundary's plus those Basic_aft made
  (``info['new_vertices']``), and the count formula (6) holds;
* with ``max_triangles`` (formula (4)) nothing is planted: the lattice follows the
  size asked, not the capped output;
* it is never planted for greedy meshing, and a domain too small for one lattice
  point gets exactly the mesh it gets with scaffold=False.
"""

from __future__ import annotations

import domain_cases as dc
import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from shapely.geometry import Polygon

import aftmesh
from aftmesh.checks import check_mesh, count_formula
from aftmesh.errors import InvalidOptionError

# Sizes at which these domains (about 2 units across) hold a few to a few hundred
# scaffold vertices: the lattice is 16 sizes apart.
FINE = 0.02
# Hypothesis examples per test here: each mesh has ~1e4 triangles and goes through
# Triangle and the exact checks.
EXAMPLES = 15


def _made(mesh) -> int:
    """Vertices made by Basic_aft, by smoothing's valence splits and by the
    minimum-angle pass."""
    refined = mesh.info["min_angle"]
    made = mesh.info["new_vertices"] + mesh.info["valence_splits"]
    return made + (refined["inserted"] if refined else 0)


def assert_scaffold_gone(mesh, domain_area: float, without) -> None:
    """The checks every scaffolded mesh must pass; `without` is the same call's mesh
    with scaffold=False (the boundary and its point count do not depend on the
    option)."""
    check_mesh(mesh, domain_area=domain_area)
    dc.assert_cdt(mesh)
    info = mesh.info
    assert info["scaffold_kept"] == 0
    before = without.n_points - _made(without)
    assert mesh.n_points == before + _made(mesh)
    assert dc.edge_keys(mesh.points, mesh.segments) == dc.edge_keys(
        without.points, without.segments
    )
    for T, Eb, Vi, m in count_formula(mesh):
        assert T == Eb + 2 * Vi + 2 * (m - 1), dict(T=T, E_b=Eb, V_i=Vi, m=m)


def _square_with_holes() -> Polygon:
    holes = [shapely.Point(x, y).buffer(0.2, quad_segs=4) for x, y in ((0.6, 0.6), (1.4, 1.2))]
    return shapely.box(0, 0, 2, 2).difference(shapely.union_all(holes))


@pytest.mark.parametrize(
    "geom",
    [shapely.box(0, 0, 2, 1), _square_with_holes(), dc.l_shape().domain, dc.annulus().domain],
    ids=["rectangle", "holes", "L", "annulus"],
)
def test_scaffolded_mesh_is_the_cdt_without_scaffold_vertices(geom):
    # (the split points stay put: their slides would depend on the interior)
    kw = dict(slide_boundary=False)
    mesh = aftmesh.generate(geom, FINE, scaffold=True, **kw)
    assert mesh.info["scaffold"] > 0
    assert_scaffold_gone(mesh, geom.area, aftmesh.generate(geom, FINE, scaffold=False, **kw))


def test_scaffold_keeps_the_quality_of_the_uniform_square():
    on = aftmesh.generate(shapely.box(0, 0, 1, 1), 0.01, scaffold=True)
    off = aftmesh.generate(shapely.box(0, 0, 1, 1), 0.01, scaffold=False)
    assert on.info["scaffold"] > 0 and off.info["scaffold"] == 0
    q_on, q_off = on.quality(), off.quality()
    assert abs(on.n_triangles - off.n_triangles) <= 0.01 * off.n_triangles
    assert q_on["radius_ratio_mean"] >= q_off["radius_ratio_mean"] - 1e-3
    assert q_on["min_angle"] >= 40.0


def test_scaffold_is_not_planted_under_max_triangles():
    # the lattice follows the size asked, not the capped output
    geom = shapely.box(0, 0, 2, 2)
    mesh = aftmesh.generate(geom, FINE, scaffold=True, max_triangles=3000, min_angle=None)
    assert mesh.info["scaffold"] == 0
    assert mesh.n_triangles <= 3000
    check_mesh(mesh, domain_area=geom.area)


def test_scaffold_regions_keep_their_areas():
    outer = shapely.box(0, 0, 2, 2)
    inner = shapely.box(0.5, 0.5, 1.5, 1.5)
    mesh = aftmesh.generate([outer.difference(inner), inner], FINE, scaffold=True)
    assert mesh.info["scaffold"] > 0
    check_mesh(mesh, domain_area=4.0)
    dc.assert_cdt(mesh)
    P, T, R = np.asarray(mesh.points), np.asarray(mesh.triangles), np.asarray(mesh.regions)
    a, b, c = P[T[:, 0]], P[T[:, 1]], P[T[:, 2]]
    area = 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    assert sorted(np.bincount(R, weights=area).round(9)) == [1.0, 3.0]


def test_scaffold_is_never_planted_for_greedy_meshing():
    mesh = aftmesh.generate(shapely.box(0, 0, 2, 2), FINE, scaffold=True, greedy=True)
    assert mesh.info["scaffold"] == 0


def test_small_domain_mesh_does_not_depend_on_the_option():
    geom = dc.l_shape().domain
    meshes = [aftmesh.generate(geom, 0.1, scaffold=s) for s in (True, False)]
    assert all(m.info["scaffold"] == 0 for m in meshes)
    for m in meshes[1:]:
        assert np.array_equal(m.points, meshes[0].points)
        assert np.array_equal(m.triangles, meshes[0].triangles)


@pytest.mark.parametrize("bad", ["yes", 1, 0.5, None])
def test_scaffold_option_is_checked(bad):
    with pytest.raises(InvalidOptionError, match="scaffold"):
        aftmesh.generate(shapely.box(0, 0, 1, 1), 0.1, scaffold=bad)


@settings(max_examples=EXAMPLES)
@given(poly=dc.polygons_with_circular_holes())
def test_random_circular_holes_with_scaffold(poly):
    size = 1.5 * FINE
    kw = dict(slide_boundary=False)
    mesh = aftmesh.generate(poly, size, scaffold=True, **kw)
    assert_scaffold_gone(mesh, poly.area, aftmesh.generate(poly, size, scaffold=False, **kw))


@settings(max_examples=EXAMPLES)
@given(poly=dc.star_polygons())
def test_random_star_polygons_with_scaffold(poly):
    kw = dict(split_boundary=False)
    mesh = aftmesh.generate(poly, FINE, scaffold=True, **kw)
    assert_scaffold_gone(mesh, poly.area, aftmesh.generate(poly, FINE, scaffold=False, **kw))
