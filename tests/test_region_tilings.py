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
