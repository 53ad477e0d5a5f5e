"""Smoothing slides the points that split an input edge along it (slide_boundary)."""

import domain_cases as dc
import fuzz_domains as fd
import numpy as np
import pytest
from shapely.geometry import GeometryCollection, LineString, Point, Polygon, box

import aftmesh
from aftmesh.mesh import triangle_quality


def _wavy():
    """A lobed outline with a hole: input edges a few sizes long at many directions,
    so the boundary's split points sit where the fronts close at poor angles."""
    t = np.linspace(0.0, 2.0 * np.pi, 37)[:-1]
    r = 1.0 + 0.25 * np.sin(5 * t) + 0.1 * np.cos(11 * t)
    return Polygon(np.c_[r * np.cos(t), r * np.sin(t)]).difference(Point(0.2, 0.1).buffer(0.3, 7))


def _poor_at_boundary(mesh) -> int:
    rr = triangle_quality(mesh.points, mesh.triangles)["radius_ratio"]
    on_segment = np.zeros(len(mesh.points), dtype=bool)
    on_segment[mesh.segments.ravel()] = True
    return int(((rr < 0.9) & on_segment[mesh.triangles].any(axis=1)).sum())


def test_split_points_slide_along_their_edges_and_mend_triangles_there(checked):
    poly = _wavy()
    case = fd.FuzzCase("wavy", poly, 0.05, {}, [poly])
    slid = aftmesh.generate(poly, 0.05)
    fixed = aftmesh.generate(poly, 0.05, slide_boundary=False)
    # both are correct meshes of the domain: every segment point on its input edge
    # within the oracle's rounding allowance, the CDT of the mesh's own vertices
    fd.verify(slid, case, check=checked)
    fd.verify(fixed, case, check=checked)
    dc.assert_cdt(slid)
    assert len(slid.points) == len(fixed.points) and len(slid.triangles) == len(fixed.triangles)
    moved = dc.edge_keys(slid.points, slid.segments) ^ dc.edge_keys(fixed.points, fixed.segments)
    assert moved, "no split point slid"
    # the input vertices stay, exactly
    assert dc.coordinate_keys(np.asarray(poly.exterior.coords)) <= dc.coordinate_keys(slid.points)
    # measured: 33 poor triangles at the boundary without sliding, 27 with
    assert _poor_at_boundary(slid) < _poor_at_boundary(fixed)
    assert slid.quality()["radius_ratio_mean"] > fixed.quality()["radius_ratio_mean"]


def test_interface_split_points_slide_on_their_line_with_both_regions_kept(checked):
    """A split point inside the domain (on an interface) slides too, judged on the
    triangles of both sides, and the regions keep their areas."""
    outer = box(-1.5, -1.5, 1.5, 1.5)
    inner = _wavy()
    mesh = aftmesh.generate([outer.difference(inner), inner], 0.06)
    case = fd.FuzzCase(
        "regions", [outer.difference(inner), inner], 0.06, {}, [outer.difference(inner), inner]
    )
    fd.verify(mesh, case, check=checked)
    fixed = aftmesh.generate([outer.difference(inner), inner], 0.06, slide_boundary=False)
    assert dc.edge_keys(mesh.points, mesh.segments) != dc.edge_keys(fixed.points, fixed.segments)
    areas = triangle_quality(mesh.points, mesh.triangles)["area"]
    assert areas[mesh.regions == 1].sum() == pytest.approx(inner.area, rel=1e-12)


def test_constraint_line_points_slide_on_the_line(checked):
    line = LineString([(-0.6, -0.5), (0.7, 0.55)])
    domain = GeometryCollection([box(-1, -1, 1, 1), line])
    mesh = aftmesh.generate(domain, 0.13)
    case = fd.FuzzCase("line", domain, 0.13, {}, [box(-1, -1, 1, 1)], [line])
    fd.verify(mesh, case, check=checked)
    fixed = aftmesh.generate(domain, 0.13, slide_boundary=False)
    assert dc.edge_keys(mesh.points, mesh.segments) != dc.edge_keys(fixed.points, fixed.segments)


def test_split_points_stay_where_sliding_is_off_or_no_vertex_is_added(checked):
    """slide_boundary=False, no smoothing and greedy keep the discretization, whatever
    the interior's mesh (the minimum-angle pass, off here, may split a segment where
    the interior needs it)."""
    poly = _wavy()
    kw = dict(min_angle=None)
    fixed = checked(aftmesh.generate(poly, 0.05, slide_boundary=False, **kw))
    unsmoothed = checked(aftmesh.generate(poly, 0.05, smooth=0, **kw))
    greedy = checked(aftmesh.generate(poly, 0.05, greedy=True, **kw))
    keys = dc.edge_keys(fixed.points, fixed.segments)
    assert keys == dc.edge_keys(unsmoothed.points, unsmoothed.segments)
    assert keys == dc.edge_keys(greedy.points, greedy.segments)


def test_slide_boundary_must_be_a_flag():
    with pytest.raises(aftmesh.InvalidOptionError, match="slide_boundary must be True or False"):
        aftmesh.generate(box(0, 0, 1, 1), 0.2, slide_boundary="yes")
