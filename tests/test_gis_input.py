"""Real GIS input: messages that say where an invalid polygon or a stray line is,
``repair=True`` (shapely.make_valid), ``tolerance=`` (merge near vertices, snap line
ends), and input vertices on straight edges kept."""

import re

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import (
    GeometryCollection,
    LineString,
    MultiLineString,
    Point,
    Polygon,
    box,
)

import aftmesh
from aftmesh.checks import check_mesh
from aftmesh.errors import InvalidDomainError, InvalidOptionError
from aftmesh.mesh import triangle_quality

# an exterior that touches itself at (2, 0) (a spike folded back onto the ring)
SELF_TOUCHING = [(0, 0), (2, 0), (3, 1), (2, 0), (4, 0), (4, 4), (0, 4)]
HOLES = [
    [(0.5, 2), (1.5, 2), (1.5, 3), (0.5, 3)],  # hole 0
    [(3, 3), (3.5, 3), (3.5, 3.5)],  # hole 1
    [(1, 2.5), (2, 2.5), (2, 3.5), (1, 3.5)],
]  # hole 2 overlaps hole 0


def _coordinates(msg):
    return [tuple(map(float, m)) for m in re.findall(r"\(([-0-9.e]+), ([-0-9.e]+)\)", msg)]


def test_overlapping_holes_are_named_with_where_they_overlap():
    bad = Polygon(SELF_TOUCHING, HOLES)
    domain = GeometryCollection([box(10, 10, 11, 11), bad])
    with pytest.raises(InvalidDomainError) as err:
        aftmesh.generate(domain, 0.3)
    msg = str(err.value)
    assert "polygon 1" in msg and "holes 0 and 2 overlap at" in msg, msg
    at = msg.split("holes 0 and 2 overlap at")[1]
    x, y = _coordinates(at)[0]
    overlap = Polygon(HOLES[0]).intersection(Polygon(HOLES[2]))
    assert overlap.covers(Point(x, y)), (x, y)
    # the exterior's own problem is reported at its own place, not at the holes'
    assert "the exterior ring" in msg
    ext_at = _coordinates(msg.split("the exterior ring")[1])[0]
    assert not overlap.covers(Point(ext_at))


def test_hole_outside_the_exterior_is_named():
    bad = Polygon([(0, 0), (2, 0), (2, 2), (0, 2)], [[(1.5, 1.5), (3, 1.5), (3, 3)]])
    with pytest.raises(InvalidDomainError, match=r"hole 0 is not inside the exterior ring \(at"):
        aftmesh.generate(bad, 0.3)


def test_line_leaving_the_domain_names_the_part_and_the_place():
    lines = MultiLineString([[(0.2, 0.2), (0.4, 0.4)], [(0.5, 0.3), (1.5, 0.3)]])
    domain = GeometryCollection([box(0, 0, 1, 1), LineString([(0.1, 0.8), (0.9, 0.8)]), lines])
    with pytest.raises(InvalidDomainError) as err:
        aftmesh.generate(domain, 0.2)
    msg = str(err.value)
    assert msg.startswith("part 1 of constraint line 1 is not inside the domain"), msg
    assert _coordinates(msg) == [(1.0, 0.3)], msg


def test_single_line_leaving_the_domain_has_coordinates():
    domain = GeometryCollection([box(0, 0, 1, 1), LineString([(0.5, 0.5), (2, 2)])])
    with pytest.raises(InvalidDomainError, match=r"constraint line 0 .* at \(1\.0, 1\.0\)"):
        aftmesh.generate(domain, 0.2)


def test_repair_meshes_a_self_touching_polygon_and_reports_the_sliver(checked):
    # a bow-tie plus a spike: make_valid gives two triangles and a zero-width line
    bow = Polygon([(0, 0), (2, 2), (2, 0), (0, 2), (0, 0)])
    with pytest.raises(InvalidDomainError):
        aftmesh.generate(bow, 0.2)
    spiky = Polygon([(0, 0), (4, 0), (4, 2), (5, 2), (4, 2), (4, 4), (0, 4)])
    crack = LineString([(1, 1), (3, 3)])
    outside = LineString([(6, 6), (7, 7)])
    domain = GeometryCollection([spiky, crack, outside])
    mesh = checked(aftmesh.generate(domain, 0.4, repair=True), domain_area=16.0)
    rep = mesh.info["repair"]
    assert rep["repaired"] and "the polygon" in rep["repaired"][0]
    dropped = " ".join(rep["dropped"])
    assert "sliver of length 1" in dropped and "(6.0, 6.0)" in dropped, rep
    # the crack inside the repaired domain stays a constraint
    P = mesh.points
    on_crack = [
        np.isclose(P[s, 0], P[s, 1]).all() and (P[s] > 0.99).all() and (P[s] < 3.01).all()
        for s in mesh.segments
    ]
    assert sum(on_crack) >= 3
    checked(aftmesh.generate(bow, 0.2, repair=True), domain_area=2.0)


def test_repair_of_a_valid_domain_changes_nothing():
    domain = box(0, 0, 2, 1).difference(Point(1, 0.5).buffer(0.2))
    a = aftmesh.generate(domain, 0.1)
    b = aftmesh.generate(domain, 0.1, repair=True)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.triangles, b.triangles)
    assert b.info["repair"] == {"repaired": [], "dropped": []}


def test_repair_must_be_a_flag():
    with pytest.raises(InvalidOptionError, match="repair"):
        aftmesh.generate(box(0, 0, 1, 1), 0.1, repair="yes")


def _faults(gap):
    """A box crossed by two fault lines that should meet at (1, 1) but whose ends
    are `gap` apart (as exported from another mesher)."""
    a = LineString([(0.3, 0.4), (1.0, 1.0)])
    b = LineString([(1.0 + gap, 1.0), (1.6, 1.5)])
    return GeometryCollection([box(0, 0, 2, 2), a, b])


def test_tolerance_merges_line_ends_closer_than_it(checked):
    domain = _faults(1.6e-12)
    exact = checked(aftmesh.generate(domain, 0.2), domain_area=4.0)
    # without a tolerance both ends stay, 1.6e-12 apart, and force a sliver there
    ends = [tuple(p) for p in exact.points.tolist()]
    assert (1.0, 1.0) in ends and (1 + 1.6e-12, 1.0) in ends
    assert triangle_quality(exact.points, exact.triangles)["min_angle"].min() < 1.0
    mesh = checked(aftmesh.generate(domain, 0.2, tolerance=1e-9), domain_area=4.0)
    assert mesh.info["tolerance"]["merged"] == 1, mesh.info["tolerance"]
    assert triangle_quality(mesh.points, mesh.triangles)["min_angle"].min() > 15
    near = np.hypot(mesh.points[:, 0] - 1.0, mesh.points[:, 1] - 1.0) < 1e-6
    assert near.sum() == 1


def test_tolerance_snaps_a_line_end_onto_a_line(checked):
    # a line ending 1e-12 short of another line's interior (a T-junction)
    domain = GeometryCollection(
        [
            box(0, 0, 2, 2),
            LineString([(0.2, 1.0), (1.8, 1.0)]),
            LineString([(1.0, 0.3), (1.0, 1.0 - 1e-12)]),
        ]
    )
    mesh = checked(aftmesh.generate(domain, 0.2, tolerance=1e-9), domain_area=4.0)
    assert mesh.info["tolerance"]["snapped"] >= 1, mesh.info["tolerance"]
    assert triangle_quality(mesh.points, mesh.triangles)["min_angle"].min() > 15


def test_tolerance_zero_is_exact_and_unreported():
    mesh = aftmesh.generate(box(0, 0, 1, 1), 0.2)
    assert "tolerance" not in mesh.info
    with pytest.raises(InvalidOptionError, match="tolerance"):
        aftmesh.generate(box(0, 0, 1, 1), 0.2, tolerance=-1.0)


@pytest.mark.parametrize("form", ["polygon", "ring", "regions"])
def test_input_vertex_in_the_middle_of_a_straight_edge_is_a_mesh_vertex(checked, form):
    ring = [(0, 0), (0.37, 0), (1, 0), (1, 1), (0, 1)]  # (0.37, 0) is a load point
    domain = {"polygon": Polygon(ring), "ring": np.array(ring), "regions": [Polygon(ring)]}[form]
    mesh = checked(aftmesh.generate(domain, 0.3), domain_area=1.0)
    assert ((mesh.points[:, 0] == 0.37) & (mesh.points[:, 1] == 0.0)).any()
    assert not any("collinear" in note for note in mesh.info["cleanup"])


def test_vertices_on_a_straight_edge_closer_than_the_tolerance_are_merged(checked):
    ring = [(0, 0), (0.5, 0), (0.5 + 1e-10, 0), (1, 0), (1, 1), (0, 1)]
    mesh = checked(aftmesh.generate(Polygon(ring), 0.3, tolerance=1e-8), domain_area=1.0)
    assert mesh.info["tolerance"]["merged"] == 1
    assert np.sum(np.abs(mesh.points[:, 0] - 0.5) < 1e-6) == 1
    assert any("merged 1 vertices" in note for note in mesh.info["cleanup"])


def test_make_valid_result_is_accepted_with_repair(checked):
    bad = Polygon(SELF_TOUCHING, HOLES)
    mesh = checked(aftmesh.generate(bad, 0.25, repair=True))
    assert mesh.info["repair"]["repaired"]
    assert abs(mesh.area() - shapely.make_valid(bad).area) < 1e-9


# random inputs: any ring of random points is meshable with repair=True, and random
# nearly meeting constraint lines are with a tolerance

coords = st.integers(0, 20).map(lambda v: v / 20)


@settings(max_examples=30)
@given(st.lists(st.tuples(coords, coords), min_size=4, max_size=9))
def test_repair_meshes_any_ring_with_area(ring):
    repaired = shapely.make_valid(Polygon(ring))
    area = sum(
        p.area for p in shapely.get_parts(repaired) if p.geom_type in ("Polygon", "MultiPolygon")
    )
    if area < 1e-3:
        with pytest.raises(InvalidDomainError):
            aftmesh.generate(np.array(ring), 0.1, repair=True)
        return
    mesh = aftmesh.generate(np.array(ring), 0.1, repair=True)
    check_mesh(mesh, domain_area=area)
    assert mesh.info["repair"]["repaired"] or Polygon(ring).is_valid


@settings(max_examples=30)
@given(
    st.lists(
        st.tuples(coords, coords, st.sampled_from([0.0, 1e-13, -7e-13, 2e-12])),
        min_size=2,
        max_size=5,
    )
)
def test_nearly_meeting_lines_mesh_with_a_tolerance(joints):
    # a chain of constraint lines inside (0.1, 0.9)^2, each ending a rounding-sized
    # gap away from where the next begins
    pts = [(0.1 + 0.8 * x, 0.1 + 0.8 * y, gap) for x, y, gap in joints]
    lines = []
    for (xa, ya, _), (xb, yb, gap) in zip(pts[:-1], pts[1:]):
        if (xa, ya) != (xb, yb):
            lines.append(LineString([(xa + gap, ya), (xb, yb)]))
    domain = GeometryCollection([box(0, 0, 1, 1), *lines])
    mesh = aftmesh.generate(domain, 0.15, tolerance=1e-9)
    check_mesh(mesh, domain_area=1.0)
    # no two mesh vertices are closer than the tolerance
    P = mesh.points
    d = np.hypot(*(P[:, None, :] - P[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(d, np.inf)
    assert d.min() > 1e-9


def test_tolerance_on_a_dict_domain_merges_fault_ends(checked):
    # the square's ring, and two fault segments meant to meet at (1, 1)
    d = {
        "vertices": [
            (0, 0),
            (2, 0),
            (2, 2),
            (0, 2),
            (0.3, 0.4),
            (1, 1),
            (1 + 1.6e-12, 1),
            (1.6, 1.5),
        ],
        "segments": [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (6, 7)],
        "segment_markers": [1, 1, 1, 1, 2, 3],
    }
    exact = checked(aftmesh.generate(d, 0.2), domain_area=4.0)
    # without a tolerance both ends stay, 1.6e-12 apart, and force a sliver there
    ends = [tuple(p) for p in exact.points.tolist()]
    assert (1.0, 1.0) in ends and (1 + 1.6e-12, 1.0) in ends
    assert triangle_quality(exact.points, exact.triangles)["min_angle"].min() < 1.0
    mesh = checked(aftmesh.generate(d, 0.2, tolerance=1e-9), domain_area=4.0)
    assert mesh.info["tolerance"] == {"merged": 1, "snapped": 0}
    assert triangle_quality(mesh.points, mesh.triangles)["min_angle"].min() > 15
    assert sorted(set(mesh.segment_markers.tolist())) == [1, 2, 3]
    assert sorted(set(mesh.segment_sources.tolist())) == list(range(6))
