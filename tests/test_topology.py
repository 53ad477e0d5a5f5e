"""Mesh topology: the connected-components routine, pieces, holes, region seeds."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import GeometryCollection, LineString, MultiPolygon, Point, box

import aftmesh
from aftmesh import checks, topology
from aftmesh.topology import components, hole_points, region_points, triangle_components

csgraph = pytest.importorskip("scipy.sparse.csgraph")
sparse = pytest.importorskip("scipy.sparse")


def _scipy_labels(n, a, b):
    graph = sparse.coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n))
    return csgraph.connected_components(graph, directed=False)[1]


def _same_partition(x, y):
    """Two labelings put the same items together."""
    pairs = np.unique(np.c_[x, y], axis=0)
    return len(pairs) == len(np.unique(x)) == len(np.unique(y))


@given(
    st.integers(1, 60).flatmap(
        lambda n: st.tuples(
            st.just(n),
            st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=90),
        )
    )
)
def test_components_match_scipy_and_label_by_the_smallest_item(case):
    n, pairs = case
    a = np.array([p[0] for p in pairs], dtype=np.int64)
    b = np.array([p[1] for p in pairs], dtype=np.int64)
    labels = components(n, a, b)
    assert _same_partition(labels, _scipy_labels(n, a, b))
    for label in np.unique(labels):
        assert label == np.flatnonzero(labels == label).min()


def test_a_long_path_numbered_backwards_is_one_component():
    # the worst order for hooking onto the smaller root: every pair joins two roots
    n = 5000
    order = np.arange(n)[::-1]
    labels = components(n, order[:-1], order[1:])
    assert (labels == 0).all()


def _neighbour_components(mesh):
    ti, k = np.nonzero(mesh.neighbors >= 0)
    return _scipy_labels(mesh.n_triangles, ti, mesh.neighbors[ti, k])


def test_triangle_components_of_separate_pieces(checked):
    pieces = MultiPolygon([box(4, 0, 5, 1), box(0, 0, 1, 1), box(2, 0, 3, 2)])
    mesh = checked(aftmesh.generate(pieces, size=0.3))
    comp = triangle_components(mesh)
    assert comp.max() == 2
    assert _same_partition(comp, _neighbour_components(mesh))
    # numbered in the order of their first triangles
    _, first = np.unique(comp, return_index=True)
    assert (np.diff(first) > 0).all()
    # the checker's name for it is the same routine
    assert checks.triangle_components is topology.triangle_components


def test_pieces_cut_at_segments(checked):
    # a line across a rectangle and a closed inner square: three pieces, one component
    dom = GeometryCollection(
        [
            box(0, 0, 3, 1),
            LineString([(1, 0), (1, 1)]),
            LineString([(2, 0.25), (2.5, 0.25), (2.5, 0.75), (2, 0.75), (2, 0.25)]),
        ]
    )
    mesh = checked(aftmesh.generate(dom, size=0.2))
    assert triangle_components(mesh).max() == 0
    piece = triangle_components(mesh, cut_at_segments=True)
    assert piece.max() == 2
    centroid = mesh.points[mesh.triangles].mean(axis=1)
    left = centroid[:, 0] < 1
    inner = (centroid[:, 0] > 2) & (centroid[:, 0] < 2.5) & (np.abs(centroid[:, 1] - 0.5) < 0.25)
    parts = (left, inner, ~left & ~inner)
    for part in parts:
        assert len(np.unique(piece[part])) == 1
    assert len({int(piece[part][0]) for part in parts}) == 3


def test_hole_points_and_region_points(checked):
    outer = box(0, 0, 4, 2).difference(Point(3, 1).buffer(0.4))
    core = box(0.5, 0.5, 1.5, 1.5)
    mesh = checked(aftmesh.generate([outer.difference(core), core], size=0.2))
    holes = hole_points(mesh)
    assert holes.shape == (1, 2)
    assert Point(3, 1).buffer(0.4).contains(Point(holes[0]))
    rows = region_points(mesh)
    assert sorted(rows[:, 2].tolist()) == [0, 1]
    for x, y, r in rows:
        assert (core.contains(Point(x, y))) == (r == 1)


def test_empty_mesh_topology():
    mesh = aftmesh.Mesh(
        np.zeros((0, 2)), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 2)), np.zeros(0)
    )
    assert triangle_components(mesh).shape == (0,)
    assert hole_points(mesh).shape == (0, 2) and region_points(mesh).shape == (0, 3)
