"""The size field (sizing.py, cython_ext/sizing.pxi): sizes on a background
triangulation of the input, so its cost follows the input and it realises sizes a
grid could not.  Each test measures the size the mesh realises against the size asked.
"""

import numpy as np
import pytest
from shapely import Polygon, box

import aftmesh
from aftmesh import examples
from aftmesh.sizing import BOUNDARY_REACH, RESOLVE_EVALUATIONS, RESOLVE_ROUNDS, make_size_field

# triangles per factor e between the chamfer's size and the square's, around one
# corner: a quarter of the 2 pi / (0.43 rate^2) of a full graded disk (rate 0.3),
# with a margin
RINGS_PER_E_FOLD = 150


def _edges_at(mesh, vertex: int) -> np.ndarray:
    """Lengths of the mesh edges at one vertex."""
    e = np.asarray(mesh.edges)
    at = e[(e[:, 0] == vertex) | (e[:, 1] == vertex)]
    p = np.asarray(mesh.points)
    return np.linalg.norm(p[at[:, 0]] - p[at[:, 1]], axis=1)


def _vertex(mesh, xy) -> int:
    p = np.asarray(mesh.points)
    return int(np.flatnonzero((p == np.asarray(xy, dtype=float)).all(axis=1))[0])


@pytest.mark.parametrize("cut", [1e-6, 1e-8])
def test_short_edge_gets_its_own_size_and_good_angles(cut, checked):
    """A unit square with one corner cut by a tiny chamfer: the background grid could
    not go below about 0.3 of a cell there, so the triangles on the chamfer were
    needles (0.62 degrees at 1e-6, 0.007 at 1e-8).  Now the size next to the chamfer
    is its own length, and every angle meets the bound (no input angle is small)."""
    poly = Polygon([(0, 0), (1, 0), (1, 1 - cut), (1 - cut, 1), (0, 1)])
    mesh = checked(aftmesh.generate(poly, 0.05), domain_area=poly.area, area_rtol=1e-9)
    chamfer = np.hypot(cut, cut)
    for corner in ((1, 1 - cut), (1 - cut, 1)):
        lengths = _edges_at(mesh, _vertex(mesh, corner))
        assert lengths.min() == pytest.approx(chamfer, rel=1e-6)  # the chamfer itself
        assert lengths.max() < 4 * chamfer  # the size asked there: the chamfer's length
    assert mesh.quality()["min_angle"] >= 28.0 - 1e-9
    # the small size stays local: as many triangles as without the chamfer plus the
    # graded rings around it, whose number is logarithmic in 0.05 / cut
    plain = aftmesh.generate(box(0, 0, 1, 1), 0.05)
    assert len(mesh.triangles) < len(plain.triangles) + RINGS_PER_E_FOLD * np.log(0.05 / cut)


def test_kept_whole_edges_ask_the_geometric_mean_where_they_meet_wide(checked):
    """split_boundary=False keeps a long edge whole beside a short one, so a vertex
    joining them at a wide angle asks for the geometric mean of the two lengths (the
    shortest drew graded rings around every short edge and flattened the long edge's
    triangle onto them); when edges may be split, the vertex asks for its shortest
    edge (sharp corners: test_input_kernels)."""
    ring = [(0, 0), (1, 0), (1.01, 0), (2.01, 0), (2.01, 0.3), (0, 0.3)]
    poly = Polygon(ring)
    kept = checked(aftmesh.generate(poly, 0.5, split_boundary=False), domain_area=poly.area)
    split = checked(aftmesh.generate(poly, 0.5), domain_area=poly.area)
    for end in ((1, 0), (1.01, 0)):  # edges 1 and 0.01 in a straight line
        assert kept.info["size_field"](*end) == pytest.approx(0.1, rel=1e-12)
        assert split.info["size_field"](*end) == pytest.approx(0.01, rel=1e-12)
    assert len(kept.triangles) < len(split.triangles)


def test_field_cost_follows_the_input_not_the_bounding_box():
    """A long thin domain with one short edge: the field holds the input's vertices
    and the box's four corners, nothing proportional to the box's area."""
    ring = [(0, 0), (1000, 0), (1000, 0.01), (500.001, 0.01), (500, 0.01), (0, 0.01)]
    mesh = aftmesh.generate(Polygon(ring), 0.005)
    field = mesh.info["size_field"]
    assert len(field.points) == len(ring) + 4
    assert field(500.0005, 0.01) == pytest.approx(0.001, rel=1e-6)


def test_size_callable_at_a_reentrant_corner_is_honoured(checked):
    """H r^(1/3) at an L-shape's re-entrant corner (the size a finite-element study of
    the corner singularity asks for), with gradation=1 so that the callable is taken
    as given: the mesh follows it, is never coarser than asked near the corner (finer
    where the callable grows faster than the front does, by about 1.22 per layer),
    and halving H makes the corner mesh finer.  On the grid the corner's size was
    whatever the nearest grid node gave, so halving H could make it coarser."""
    L = Polygon([(-1, -1), (1, -1), (1, 1), (0, 1), (0, 0), (-1, 0)])
    near = []
    for H in (0.2, 0.1, 0.05):

        def size(x, y, H=H):
            return H * np.maximum(np.hypot(x, y), 1e-9) ** (1 / 3)

        mesh = checked(aftmesh.generate(L, size, gradation=1.0), domain_area=L.area)
        p = np.asarray(mesh.points)
        e = np.asarray(mesh.edges)
        mid = 0.5 * (p[e[:, 0]] + p[e[:, 1]])
        r = np.hypot(mid[:, 0], mid[:, 1])
        ratio = np.linalg.norm(p[e[:, 0]] - p[e[:, 1]], axis=1) / size(mid[:, 0], mid[:, 1])
        assert 0.8 < np.median(ratio[(r > 0.3) & (r < 1.0)]) < 1.2
        assert np.percentile(ratio[r < 0.3], 95) < 1.3
        near.append(int((r < 0.1).sum()))
    assert near[0] < near[1] < near[2]


# "A few thousand" evaluations for the graded airfoil: 2,183 with the midpoints of a
# round thinned (sizing.RESOLVE_THIN), 5,977 without, 136,704 on the old grid.
FEW_THOUSAND = 3000


def test_callable_costs_a_few_thousand_evaluations(checked):
    """The graded airfoil of the examples: its size callable (a distance to the
    airfoil) is evaluated at background vertices and at the midpoints of edges, one
    per cell among edges of similar length, in a few batched calls."""
    foil, size = examples.airfoil_channel()
    count = []

    def counted(x, y):
        count.append(len(x))
        return size(x, y)

    checked(aftmesh.generate(foil, counted), domain_area=foil.area)
    assert sum(count) <= min(FEW_THOUSAND, RESOLVE_EVALUATIONS)
    assert len(count) <= RESOLVE_ROUNDS + 1


def test_reach_then_gradation():
    """The field at a short edge's end is its length, holds for BOUNDARY_REACH lengths,
    then grows at the gradation rate, up to the user's size."""
    f = make_size_field(1.0, ((0.0, 0.0), (10.0, 10.0)), np.array([[5.0, 5.0]]), np.array([0.01]))
    assert f(5.0, 5.0) == pytest.approx(0.01)
    assert f(5.0 + BOUNDARY_REACH * 0.01, 5.0) == pytest.approx(0.01)
    assert f(6.0, 5.0) == pytest.approx(0.01 + 0.3 * (1.0 - BOUNDARY_REACH * 0.01))
    assert f(9.0, 9.0) == 1.0


@pytest.mark.parametrize("scale", [1.0, 0.3])
def test_compiled_discretization_follows_the_size(scale):
    """The kernel's discretize_segments (the integral of 1/h along each segment, from
    a few samples per piece): as many pieces as a fine numerical integral of 1/h
    says (rounded; one more or less where it is near a half), split points in order
    strictly inside their segment, and each piece within a third of the size at its
    middle."""
    from aftmesh import _kernel

    ring = np.array(
        [(0, 0), (3, 0.1), (3.05, 0.12), (6, 0), (6, 4), (3.5, 4.2), (3.45, 4.18), (0, 4)],
        dtype=float,
    )
    seg = np.c_[np.arange(len(ring)), (np.arange(len(ring)) + 1) % len(ring)].astype(np.int32)
    field = aftmesh.generate(Polygon(ring), 0.4 * scale).info["size_field"]
    pieces, pts, row = _kernel.discretize_segments(*field.kernel_args(), ring, seg, 32, np.inf)
    fine = np.linspace(0.0, 1.0, 4001)
    for i, (a, b) in enumerate(ring[seg]):
        x = a[None, :] + fine[:, None] * (b - a)[None, :]
        integral = np.trapezoid(1.0 / field(x[:, 0], x[:, 1]), dx=np.linalg.norm(b - a) / 4000)
        assert abs(pieces[i] - max(1.0, np.rint(integral))) <= 1
        chain = np.vstack([a, pts[row == i], b])
        t = (chain - a) @ (b - a) / ((b - a) @ (b - a))
        assert np.all(np.diff(t) > 0)
        mid = 0.5 * (chain[1:] + chain[:-1])
        ratio = np.linalg.norm(np.diff(chain, axis=0), axis=1) / field(mid[:, 0], mid[:, 1])
        if pieces[i] > 1:
            assert np.all((ratio > 0.67) & (ratio < 1.5)), ratio


def test_compiled_chains_equal_the_numpy_chains():
    """discretize_boundary (the whole new PSLG in the kernel) gives exactly what the
    retry path's numpy _chains makes of the same split points."""
    from aftmesh import _kernel, boundary

    ring = np.array([(0, 0), (5, 0), (5, 0.01), (5.02, 3), (0, 3)], dtype=float)
    seg = np.c_[np.arange(5), (np.arange(5) + 1) % 5].astype(np.int32)
    src = np.arange(5, dtype=np.int32)
    for size in (0.3, 0.05, lambda x, y: 0.02 + 0.1 * x):
        field = aftmesh.generate(Polygon(ring), size).info["size_field"]
        fast = boundary.discretize(ring, seg, src, field)
        pieces, pts, row = _kernel.discretize_segments(*field.kernel_args(), ring, seg, 32, np.inf)
        split = np.flatnonzero(pieces > 1)
        a, b = ring[seg[:, 0]], ring[seg[:, 1]]
        slow = boundary._chains(
            ring, seg, src, pieces == 1, split, row, pieces[split] - 1, pts, a, b
        )
        assert len(fast[1]) > len(seg)
        for x, y in zip(fast, slow):
            assert np.array_equal(x, y)


def _numpy_round(keys, passed, n, xy, size, u, thin):
    """One round of the callable's sampling as numpy states it (the definition the
    kernel's resolve_rounds computes, resolve.pxi): the edges to sample, their
    midpoints and sizes there, the passed edges after the round, the midpoints to
    insert."""
    from aftmesh.sizing import RESOLVE_COARSEST, RESOLVE_SPAN, RESOLVE_TOLERANCE

    keys = keys[~np.isin(keys, passed)]
    a, b = keys // n, keys % n
    mid = 0.5 * (xy[a] + xy[b])
    length = np.linalg.norm(xy[b] - xy[a], axis=1)
    um = size(mid[:, 0], mid[:, 1])
    miss = np.abs(0.5 * (u[a] + u[b]) - um) > RESOLVE_TOLERANCE * um
    bad = (miss & (length > RESOLVE_SPAN * um)) | (length > RESOLVE_COARSEST * um)
    at = np.flatnonzero(bad)
    level = np.floor(np.log2(length[at]))
    cell = thin * np.exp2(level)
    low = mid[at].min(axis=0) if len(at) else np.zeros(2)
    ix = np.floor((mid[at, 0] - low[0]) / cell)
    iy = np.floor((mid[at, 1] - low[1]) / cell)
    order = np.lexsort((iy, ix, level))
    first = np.ones(len(at), dtype=bool)
    first[1:] = np.diff(level[order]) != 0
    first[1:] |= (np.diff(ix[order]) != 0) | (np.diff(iy[order]) != 0)
    return keys, mid, um, np.sort(np.concatenate([passed, keys[~bad]])), np.sort(at[order[first]])


def _numpy_rounds(xy, u, size, budget, rounds):
    """sizing._resolve_callable's rounds as numpy states them, each round's midpoints
    inserted in BRIO order with their walks started at their edges' first ends:
    (points, sizes) at the end."""
    from aftmesh import _kernel
    from aftmesh._order import brio_order
    from aftmesh.sizing import RESOLVE_THIN

    tri = _kernel.Triangulation(xy)
    tri.insert_points(brio_order(xy))
    n, passed, calls = len(xy) + budget, np.zeros(0, np.int64), 0
    for _ in range(rounds):
        keys, mid, um, after, at = _numpy_round(
            tri.edge_keys(n), passed, n, xy, size, u, RESOLVE_THIN
        )
        if len(keys) == 0 or calls + len(keys) > budget:
            break
        calls, passed = calls + len(keys), after
        if len(at) == 0:
            break
        at = at[brio_order(mid[at])]
        tri.add_points(np.ascontiguousarray(mid[at]), (keys[at] // n).astype(np.int32))
        xy, u = np.concatenate([xy, mid[at]]), np.concatenate([u, um[at]])
    return xy, u


def _kernel_rounds(xy, u, size, budget, rounds):
    from aftmesh import _kernel
    from aftmesh._order import brio_order, round_keys
    from aftmesh.sizing import RESOLVE_COARSEST, RESOLVE_SPAN, RESOLVE_THIN, RESOLVE_TOLERANCE

    tri = _kernel.Triangulation(xy)
    tri.insert_points(brio_order(xy))
    return _kernel.resolve_rounds(
        tri, u, lambda mid: size(mid[:, 0], mid[:, 1]), round_keys, budget, rounds,
        RESOLVE_TOLERANCE, RESOLVE_SPAN, RESOLVE_COARSEST, RESOLVE_THIN,
    )  # fmt: skip


@pytest.mark.parametrize(
    ("seed", "budget", "rounds"), [(0, 20_000, 24), (1, 20_000, 24), (2, 20_000, 2), (3, 1_500, 24)]
)
def test_kernel_sampling_rounds_are_the_numpy_rounds(seed, budget, rounds):
    """The size callable's sampling rounds in the kernel (which edges to sample, which
    midpoints to insert, in what order, what passed) give exactly the points and sizes
    of the numpy definition, round after round, on a random background; stopped by
    the rounds, the evaluations' budget or a round with nothing to insert."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-3, 7, (300, 2))

    def size(x, y):
        return 0.05 + 0.3 * np.abs(np.sin(x)) * (1 + y * y)

    u = size(xy[:, 0], xy[:, 1])
    want = _numpy_rounds(xy, u, size, budget, rounds)
    got = _kernel_rounds(xy, u, size, budget, rounds)
    assert len(want[0]) > len(xy)
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])


def test_kernel_sampling_rounds_refuse_what_they_cannot_use():
    """Sizes not one per vertex, samples or round keys of the wrong length are a
    ValueError naming the counts, not a read past the arrays; the callable's own
    error comes through as it is."""
    from aftmesh import _kernel
    from aftmesh._order import round_keys

    xy = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0]])
    tri = _kernel.Triangulation(xy)
    tri.insert_points(np.arange(4, dtype=np.int32))
    args = (20_000, 24, 0.2, 1.0, 8.0, 0.5)
    with pytest.raises(ValueError, match=r"one size per vertex \(4\), got 3"):
        _kernel.resolve_rounds(tri, np.ones(3), lambda m: np.ones(len(m)), round_keys, *args)
    with pytest.raises(ValueError, match="for 5 midpoints"):
        _kernel.resolve_rounds(tri, np.ones(4), lambda m: np.ones(2), round_keys, *args)
    with pytest.raises(ValueError, match="points"):
        _kernel.resolve_rounds(
            tri,
            np.ones(4),
            lambda m: np.full(len(m), 0.1),
            lambda n: np.zeros(n + 1, np.int64),
            *args,
        )
    with pytest.raises(ZeroDivisionError):
        _kernel.resolve_rounds(tri, np.ones(4), lambda m: 1 / 0, round_keys, *args)


@pytest.mark.parametrize("n_points", [4, 60, 2000])
def test_edge_keys_are_the_finite_triangles_edges_sorted(n_points):
    """Triangulation.edge_keys lists every edge of the finite triangles once, as a n + b
    with a < b, in increasing order (built vertex by vertex, without a sort of the
    whole list), also with duplicate points (merged, in no triangle) and a vertex of
    many neighbours (the centre of a fan)."""
    from aftmesh import _kernel

    rng = np.random.default_rng(n_points)
    t = np.linspace(0, 2 * np.pi, n_points, endpoint=False)
    r, s = rng.uniform(1.5, 3.0, n_points), rng.uniform(0, 2 * np.pi, n_points)
    outside = np.c_[r * np.cos(s), r * np.sin(s)]  # leaves the fan around (0, 0) whole
    xy = np.concatenate([[[0.0, 0.0]], np.c_[np.cos(t), np.sin(t)], outside])
    xy = np.concatenate([xy, xy[:3]])
    tri = _kernel.Triangulation(xy)
    tri.insert_points(np.arange(len(xy), dtype=np.int32))
    n = len(xy) + 5
    tv, _ = tri.finite_triangles()
    e = np.sort(np.concatenate([tv[:, [0, 1]], tv[:, [1, 2]], tv[:, [2, 0]]]), axis=1)
    assert np.array_equal(tri.edge_keys(n), np.unique(e[:, 0].astype(np.int64) * n + e[:, 1]))
    assert (e == 0).sum() >= n_points - 1  # the fan's centre: one neighbour per rim point
