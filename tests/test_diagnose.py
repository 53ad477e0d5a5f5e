"""aftmesh.diagnose: every bad triangle gets exactly one class, by the stated rules."""

import math

import numpy as np
from shapely.geometry import Point, Polygon, box

from aftmesh.diagnose import CLASSES, diagnose, smallest_angle
from aftmesh.mesh import triangle_quality


def _domain():
    # a plate with holes of very different sizes: boundary, size and interior classes
    plate = box(0.0, 0.0, 2.0, 1.0)
    for x, y, r in ((0.4, 0.5, 0.2), (1.2, 0.3, 0.02), (1.5, 0.7, 0.05)):
        plate = plate.difference(Point(x, y).buffer(r, 8))
    return plate


def test_every_bad_triangle_has_one_class(checked):
    d = diagnose(_domain(), 0.06, threshold=0.95)
    checked(d.mesh)
    rr = triangle_quality(d.mesh.points, d.mesh.triangles)["radius_ratio"]
    assert np.array_equal(d.bad, np.flatnonzero(rr < 0.95))
    assert len(d.bad) > 0
    assert set(d.labels) <= set(CLASSES)
    assert sum(d.counts.values()) == len(d.bad)


def test_boundary_class_touches_an_input_segment():
    d = diagnose(_domain(), 0.06, threshold=0.95)
    on_segment = np.zeros(len(d.mesh.points), dtype=bool)
    on_segment[d.mesh.segments.ravel()] = True
    tris = d.mesh.triangles[d.bad]
    touching = on_segment[tris].any(axis=1)
    assert touching[d.labels == "boundary"].all()
    # boundary outranks size, collision and other: those never touch a segment
    later = np.isin(d.labels, ["size", "collision", "other"])
    assert not touching[later].any()


def test_without_smoothing_nothing_is_blamed_on_it():
    d = diagnose(_domain(), 0.06, threshold=0.95, smooth=0)
    assert d.counts["smoothing"] == 0


def test_diagnosis_of_a_domain_wide_enough_for_the_scaffold(checked):
    """A domain many sizes wide gets the scaffold in the compiled loop and none in the
    Python loop; both runs are made without it, so their vertices correspond."""
    d = diagnose(box(0.0, 0.0, 1.0, 1.0), 0.02, threshold=0.99)
    checked(d.mesh)
    assert d.mesh.info["scaffold"] == 0
    assert sum(d.counts.values()) == len(d.bad) > 0


def test_diagnosis_of_a_mesh_with_valence_splits(checked):
    """Smoothing's valence splits add points after all the others: the diagnosis still
    pairs the two meshes' vertices (it refused such meshes before)."""
    plate = box(0.0, 0.0, 2.0, 1.0)
    for x, y, r in ((0.45, 0.5, 0.22), (1.2, 0.3, 0.08), (1.55, 0.7, 0.15), (1.0, 0.8, 0.05)):
        plate = plate.difference(Point(x, y).buffer(r, 24))
    d = diagnose(plate, 0.03, threshold=0.9)
    checked(d.mesh)
    assert d.mesh.info["valence_splits"] > 0
    rr = triangle_quality(d.mesh.points, d.mesh.triangles)["radius_ratio"]
    assert np.array_equal(d.bad, np.flatnonzero(rr < 0.9))
    assert sum(d.counts.values()) == len(d.bad) > 0


def _spiked(tip: float) -> Polygon:
    # a spike of `tip` degrees at the origin, opening into a wider body
    t = math.tan(math.radians(tip / 2))
    return Polygon([(0.0, 0.0), (2.0, -2.0 * t), (3.0, -1.0), (3.0, 1.0), (2.0, 2.0 * t)])


def _angle(p, q, r) -> float:
    # the angle at p of the triangle p, q, r, in degrees
    u, w = q - p, r - p
    return math.degrees(math.atan2(abs(u[0] * w[1] - u[1] * w[0]), u @ w))


def test_smallest_angle_is_that_of_the_roundest_triangle_at_the_threshold():
    """The isosceles triangle with apex smallest_angle(q) has radius ratio q."""
    for q in (0.5, 0.9, 0.95):
        a = math.radians(smallest_angle(q))
        pts = np.array(
            [[0.0, 0.0], [math.cos(a / 2), -math.sin(a / 2)], [math.cos(a / 2), math.sin(a / 2)]]
        )
        rr = triangle_quality(pts, np.array([[0, 1, 2]]))["radius_ratio"][0]
        assert abs(rr - q) < 1e-12


def test_triangles_in_an_input_wedge_too_narrow_for_the_threshold_are_input_angle(checked):
    """A 20 degree spike: the triangles at its tip are bad whatever the mesher does,
    and are labelled input_angle; every input_angle triangle has an angle below
    smallest_angle at a vertex on a segment."""
    d = diagnose(_spiked(20.0), 0.1, threshold=0.9)
    checked(d.mesh)
    m = d.mesh
    labelled = d.bad[d.labels == "input_angle"]
    on_segment = np.zeros(len(m.points), dtype=bool)
    on_segment[m.segments.ravel()] = True
    p = m.points[m.triangles]
    for i in labelled:
        angles = [_angle(p[i, k], p[i, (k + 1) % 3], p[i, (k + 2) % 3]) for k in range(3)]
        k = int(np.argmin(angles))
        assert angles[k] < smallest_angle(0.9) and on_segment[m.triangles[i, k]]
    tip = np.flatnonzero(np.all(m.points == (0.0, 0.0), axis=1))[0]
    at_tip = np.flatnonzero((m.triangles == tip).any(axis=1))
    assert len(at_tip) >= 1 and set(at_tip) <= set(labelled)
    # a wider spike leaves room for good triangles: nothing is forced there
    wide = diagnose(_spiked(50.0), 0.1, threshold=0.9)
    assert wide.counts["input_angle"] == 0
