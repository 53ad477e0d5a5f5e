"""aftmesh.diagnose: every bad triangle gets exactly one class, by the stated rules."""

import numpy as np
from shapely.geometry import Point, box

from aftmesh.diagnose import CLASSES, diagnose
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
