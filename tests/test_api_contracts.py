"""API contracts of ``aftmesh.generate`` that users build on: how the size callable is
called, and what it must return."""

import numpy as np
import pytest
from shapely.geometry import Point, box

import aftmesh
from aftmesh.errors import InvalidSizeError

scipy_spatial = pytest.importorskip("scipy.spatial")

SQUARE = box(0, 0, 1, 1)


def test_size_callable_receives_1d_arrays_of_equal_length(checked):
    seen = []

    def size(x, y):
        seen.append((np.ndim(x), np.ndim(y), np.shape(x) == np.shape(y)))
        return 0.05 + 0.1 * x

    checked(aftmesh.generate(SQUARE, size), domain_area=1.0)
    assert seen and all(s == (1, 1, True) for s in seen), seen


def test_size_from_a_kdtree_query_on_stacked_points(checked):
    # the size grows with the distance to a few "sensor" points: a callable built on
    # cKDTree(points).query(np.c_[x, y]), which takes (n, 2) points
    sensors = np.array([[0.2, 0.2], [0.8, 0.5]])
    tree = scipy_spatial.cKDTree(sensors)

    def size(x, y):
        dist, _ = tree.query(np.c_[x, y])
        return 0.02 + 0.3 * dist

    mesh = checked(aftmesh.generate(SQUARE, size), domain_area=1.0)
    P = mesh.points
    e = mesh.edges
    mid = 0.5 * (P[e[:, 0]] + P[e[:, 1]])
    length = np.linalg.norm(P[e[:, 1]] - P[e[:, 0]], axis=1)
    near = tree.query(mid)[0] < 0.05
    far = tree.query(mid)[0] > 0.4
    assert near.any() and far.any()
    assert length[near].mean() < 0.5 * length[far].mean()


def test_size_callable_on_point_rows(checked):
    def h(points):
        assert points.ndim == 2 and points.shape[1] == 2
        return 0.04 + 0.1 * np.hypot(points[:, 0], points[:, 1])

    domain = box(0, 0, 2, 1).difference(Point(1.4, 0.5).buffer(0.2))
    checked(aftmesh.generate(domain, lambda x, y: h(np.c_[x, y])), domain_area=domain.area)


def test_size_callable_returning_a_scalar(checked):
    checked(aftmesh.generate(SQUARE, lambda x, y: 0.1), domain_area=1.0)


@pytest.mark.parametrize(
    "result, shape",
    [
        (lambda x, y: np.c_[x, y][:, :1] * 0 + 0.1, "(n, 1)"),
        (lambda x, y: np.full(3, 0.1), "(3,)"),
        (lambda x, y: np.full((len(x), 2), 0.1), "(n, 2)"),
    ],
)
def test_size_callable_of_the_wrong_shape_is_refused(result, shape):
    with pytest.raises(InvalidSizeError, match="shape .* 1-D arrays x, y of length"):
        aftmesh.generate(SQUARE, result)


def test_size_callable_is_sampled_in_a_few_batched_calls():
    """The callable gets 1-D float64 arrays, a bounded number of times and points in
    all (sizing.RESOLVE_ROUNDS, RESOLVE_EVALUATIONS); the field asks for no more than
    it gave at the background's vertices, and at the samples it did not keep, no more
    than RESOLVE_TOLERANCE above it."""
    from aftmesh.sizing import RESOLVE_EVALUATIONS, RESOLVE_ROUNDS, RESOLVE_TOLERANCE

    calls = []

    def size(x, y):
        assert x.ndim == 1 and x.shape == y.shape and x.dtype == np.float64
        calls.append(np.c_[x, y].copy())
        return 0.05 + 0.05 * x * y

    mesh = aftmesh.generate(SQUARE, size)
    field = mesh.info["size_field"]
    assert 1 < len(calls) <= RESOLVE_ROUNDS + 1
    assert sum(map(len, calls)) <= RESOLVE_EVALUATIONS + len(field.points)
    seen = np.concatenate(calls)
    asked = 0.05 + 0.05 * seen[:, 0] * seen[:, 1]
    assert np.all(field(seen[:, 0], seen[:, 1]) <= asked * (1 + RESOLVE_TOLERANCE))
    p = field.points
    assert np.all(field(p[:, 0], p[:, 1]) <= (0.05 + 0.05 * p[:, 0] * p[:, 1]) * (1 + 1e-12))
