"""The compiled and shortcut pieces of the per-call input work (issue 12) against the
plain numpy rules they replace: ring clean-up, coordinate and segment checks, the
distinct points of a vertex list, repeated segments, the BRIO round keys."""

from __future__ import annotations

import gc

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aftmesh import _kernel, _order
from aftmesh.noding import _drop_repeats, unique_rows
from aftmesh.pslg import MAX_COORDINATE, MIN_COORDINATE

# Few distinct values, so that hypothesis makes repeats, +0.0 / -0.0 and ties often.
coordinate = st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 1e-3])


def reference_ring(c: np.ndarray):
    """One closed ring by the rule of inputs._ring_arrays, with numpy."""
    ring = c[:-1]
    succ = np.roll(ring, -1, axis=0)
    keep = (ring != succ).any(axis=1)
    return ring[keep], np.flatnonzero(keep), 0.5 * (ring + succ), int((~keep).sum())


@st.composite
def closed_rings(draw):
    rings = []
    for _ in range(draw(st.integers(1, 4))):
        pts = draw(st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=8))
        rings.append(np.array(pts + pts[:1], dtype=np.float64))
    return rings


@given(closed_rings())
def test_ring_chains_follows_the_ring_rule(rings):
    xy = np.concatenate(rings)
    ring_of = np.repeat(np.arange(len(rings)), [len(r) for r in rings])
    pts, segs, edge, mid, ring, removed = _kernel.ring_chains(xy, ring_of, len(rings))
    offset_pts = offset_edges = 0
    for r, c in enumerate(rings):
        want_pts, want_edge, want_mid, want_removed = reference_ring(c)
        n, m = len(c) - 1, len(want_pts)
        assert pts[offset_pts : offset_pts + m].tobytes() == want_pts.tobytes()
        assert (edge[offset_pts : offset_pts + m] == want_edge + offset_edges).all()
        assert mid[offset_edges : offset_edges + n].tobytes() == want_mid.tobytes()
        assert (ring[offset_edges : offset_edges + n] == r).all()
        assert removed[r] == want_removed
        if m:
            nxt = np.r_[np.arange(1, m), 0] + offset_pts
            assert (
                segs[offset_pts : offset_pts + m] == np.c_[np.arange(m) + offset_pts, nxt]
            ).all()
        offset_pts += m
        offset_edges += n
    assert len(pts) == len(segs) == len(edge) == offset_pts


def test_ring_chains_refuses_ring_numbers_that_skip_a_ring():
    xy = np.zeros((4, 2))
    with pytest.raises(ValueError, match="ring numbers"):
        _kernel.ring_chains(xy, np.array([0, 0, 2, 2]), 3)
    with pytest.raises(ValueError, match="ring numbers"):
        _kernel.ring_chains(xy, np.array([0, 0, 1, 1]), 3)


@given(
    st.lists(
        st.sampled_from([0.0, -0.0, 1.0, np.nan, np.inf, -np.inf, 2 * MAX_COORDINATE, 1e-300]),
        max_size=12,
    )
)
def test_coordinate_problems_flags_what_numpy_finds(values):
    xy = np.array(values + [0.0] * (len(values) % 2), dtype=np.float64).reshape(-1, 2)
    mag = np.abs(xy)
    want = (
        1 * bool((~np.isfinite(xy)).any())
        | 2 * bool((mag > MAX_COORDINATE).any())
        | 4 * bool(((mag < MIN_COORDINATE) & (mag > 0)).any())
    )
    assert _kernel.coordinate_problems(xy, MIN_COORDINATE, MAX_COORDINATE) == want


@given(st.lists(st.tuples(st.integers(-2, 6), st.integers(-2, 6)), max_size=10))
def test_segment_problems_flags_what_numpy_finds(pairs):
    xy = np.array([[0, 0], [1, 0], [1, 1], [0, 0], [2, 2]], dtype=np.float64)
    seg = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    bad = ((seg < 0) | (seg >= len(xy))).any(axis=1)
    ok = seg[~bad]
    zero = (ok[:, 0] == ok[:, 1]) | (xy[ok[:, 0]] == xy[ok[:, 1]]).all(axis=1)
    assert _kernel.segment_problems(seg, xy) == 1 * bool(bad.any()) | 2 * bool(zero.any())


@given(st.lists(st.tuples(coordinate, coordinate), max_size=12))
def test_unique_rows_is_numpy_unique(rows):
    pts = np.array(rows, dtype=np.float64).reshape(-1, 2)
    want, want_inverse = np.unique(pts, axis=0, return_inverse=True)
    got, inverse = unique_rows(pts)
    assert got.tobytes() == want.tobytes()
    assert (inverse == want_inverse.reshape(-1)).all()


@given(st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5)), max_size=12))
def test_drop_repeats_keeps_the_first_copy_of_each_segment(pairs):
    segs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    src = np.arange(len(segs))
    key = np.sort(segs, axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    first = np.sort(first[key[first, 0] != key[first, 1]])
    got, got_src = _drop_repeats(segs, src)
    assert (got == segs[first]).all() and (got_src == first).all()


@pytest.mark.parametrize("n", [1, 7, _order.CACHED_ROUNDS, _order.CACHED_ROUNDS + 1])
def test_cached_brio_round_keys_are_the_drawn_ones(n):
    assert (_order._round_keys(n, _order.SEED) == _order._draw_round_keys(n, _order.SEED)).all()


@given(st.lists(st.tuples(coordinate, coordinate), max_size=12))
def test_unique_points_gives_the_first_copy_of_each_distinct_point(rows):
    pts = np.array(rows, dtype=np.float64).reshape(-1, 2)
    found = _kernel.unique_points(pts)
    order = np.lexsort((pts[:, 1], pts[:, 0]))
    srt = pts[order]
    start = np.ones(len(pts), dtype=bool)
    start[1:] = (srt[1:] != srt[:-1]).any(axis=1)
    bits = srt.view(np.int64)
    if not (bits[1:][~start[1:]] == bits[:-1][~start[1:]]).all():
        assert found is None  # 0.0 and -0.0: left to np.unique
        return
    first, inverse = found
    assert (first == order[start]).all()
    assert (inverse[order] == np.cumsum(start) - 1).all()


def test_unique_points_leaves_non_finite_points_to_numpy():
    assert _kernel.unique_points(np.array([[0.0, 1.0], [np.nan, 0.0]])) is None


# Vertices of a square ring and of a second ring touching it, for rings_proper.
SQUARE = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]


@pytest.mark.parametrize(
    "extra, proper",
    [
        ([(0.5, 0.5), (1.5, 0.5), (1.0, 1.5)], True),  # a hole inside
        ([(1.0, 0.0), (1.5, 0.5), (0.5, 0.5)], False),  # a hole corner on an edge
        ([(2.0, 2.0), (1.5, 1.0), (1.0, 1.5)], True),  # touching at a shared corner
        ([(3.0, 0.0), (4.0, 0.0), (3.5, 1.0)], True),  # on the edge's line, beyond it
    ],
)
def test_rings_proper_agrees_with_the_split_at_vertices(extra, proper):
    from aftmesh.noding import split_at_vertices

    pts = np.array(SQUARE + extra, dtype=np.float64)
    first, inverse = _kernel.unique_points(pts)
    uniq = pts[first]
    ring = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 4]])
    segs = inverse[ring]
    src = np.arange(len(segs))
    split, _ = split_at_vertices(uniq, segs, src, None, 0.0, np.ones(len(src), dtype=bool))
    assert (len(split) == len(segs)) == proper
    assert _kernel.rings_proper(uniq, np.ascontiguousarray(segs, dtype=np.int64)) == proper


@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), max_size=8))
def test_rings_proper_refuses_repeated_and_zero_length_segments(pairs):
    xy = np.array([[0, 0], [4, 1], [3, 5], [-1, 3], [1, 2.5]], dtype=np.float64)
    segs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    got, _ = _drop_repeats(segs, np.arange(len(segs)))
    on_interior = False  # no vertex of these five is on a segment between two others
    want = len(got) == len(segs) and not on_interior
    assert _kernel.rings_proper(xy, segs) == want


@given(st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5)), max_size=10))
def test_shortest_edges_is_the_numpy_minimum(pairs):
    rng = np.random.default_rng(len(pairs))
    xy = rng.normal(size=(6, 2))
    seg = np.array(pairs, dtype=np.int32).reshape(-1, 2)
    lengths = np.linalg.norm(xy[seg[:, 1]] - xy[seg[:, 0]], axis=1)
    want = np.full(len(xy), np.inf)
    np.minimum.at(want, seg[:, 0], lengths)
    np.minimum.at(want, seg[:, 1], lengths)
    assert _kernel.shortest_edges(xy, seg).tobytes() == want.tobytes()


@given(st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5)), max_size=10))
def test_kept_whole_sizes_are_the_geometric_mean_at_wide_two_edge_vertices(pairs):
    rng = np.random.default_rng(len(pairs))
    xy = rng.normal(size=(6, 2))
    seg = np.array(pairs, dtype=np.int32).reshape(-1, 2)
    want = _kernel.shortest_edges(xy, seg)
    ends = [[int(b) for a, b in np.concatenate([seg, seg[:, ::-1]]) if a == v] for v in range(6)]
    for v, far in enumerate(ends):
        if len(far) != 2 or not want[v] > 0:
            continue
        u, w = xy[far[0]] - xy[v], xy[far[1]] - xy[v]
        lu, lw = np.linalg.norm(u), np.linalg.norm(w)
        if u @ w < 0.5 * lu * lw:  # wider than 60 degrees
            want[v] = np.sqrt(want[v]) * np.sqrt(max(lu, lw))
    got = _kernel.shortest_edges(xy, seg, kept_whole=True)
    np.testing.assert_allclose(got, want, rtol=1e-14)


def reference_hilbert_key(x: int, y: int, bits: int) -> int:
    """The Hilbert index of cell (x, y), one level at a time (the textbook xy -> d)."""
    d, side = 0, (1 << bits) - 1
    for level in reversed(range(bits)):
        s = 1 << level
        rx, ry = int(bool(x & s)), int(bool(y & s))
        d += s * s * ((3 * rx) ^ ry)
        if ry == 0:
            if rx == 1:
                x, y = side - x, side - y
            x, y = y, x
    return d


@pytest.mark.parametrize("bits", [1, 2, 3, 7, 16, 31])
def test_hilbert_keys_two_levels_at_a_time_are_the_textbook_keys(bits):
    rng = np.random.default_rng(bits)
    side = (1 << bits) - 1
    cells = rng.integers(0, side + 1, size=(300, 2))
    cells[:4] = [[0, 0], [side, 0], [0, side], [side, side]]
    # points at the cells' corners, in a box of side `side`: the cell is the point
    xy = np.ascontiguousarray(cells.astype(np.float64))
    got = _kernel.hilbert_keys(xy, bits)
    want = [reference_hilbert_key(int(x), int(y), bits) for x, y in cells]
    assert got.tolist() == want


@pytest.mark.parametrize("n", [0, 1, 2, 9, 200, 5000])
def test_brio_keys_order_is_the_stable_numpy_argsort(n):
    rng = np.random.default_rng(n)
    # a coarse grid: many points share a Hilbert cell, so the sort's ties matter
    xy = np.ascontiguousarray(rng.integers(0, 4, size=(n, 2)).astype(np.float64))
    rounds = _order._draw_round_keys(n, _order.SEED)
    keys = rounds | _kernel.hilbert_keys(xy)
    want = np.argsort(keys, kind="stable").astype(np.int32)
    assert (_kernel.brio_keys_order(xy, rounds) == want).all()


@pytest.mark.parametrize("n", [3, 10, 300])
def test_background_field_is_the_triangulation_and_gradation_it_replaces(n):
    rng = np.random.default_rng(n)
    xy = rng.integers(0, 12, size=(n, 2)).astype(np.float64)  # repeats: merged points
    xy[:3] = [[-1.0, -1.0], [13.0, -1.0], [6.0, 13.0]]  # never all collinear
    g = rng.uniform(0.1, 2.0, n)
    g[rng.integers(0, n, n // 3)] = np.inf
    tri = _kernel.Triangulation(xy)
    tri.insert_points(_order.brio_order(xy))
    want_tv, want_nb = tri.finite_triangles()
    want_g = g.copy()
    _kernel.limit_gradation_mesh(xy, want_tv, want_g, 0.3)
    used = np.zeros(n, dtype=bool)
    used[want_tv.ravel()] = True
    want_g[~used] = np.inf
    got_g = g.copy()
    tv, nb, finite = _kernel.background_field(xy, _order.round_keys(n), got_g, 0.3)
    assert (tv == want_tv).all() and (nb == want_nb).all()
    assert got_g.tobytes() == want_g.tobytes()
    assert finite == bool(np.isfinite(want_g[used]).all())


@pytest.mark.parametrize("n", [3, 10, 300])
def test_edge_keys_are_the_unique_sorted_edges_of_the_finite_triangles(n):
    # the size field's sampling rounds (sizing._resolve_callable) take their edges here
    rng = np.random.default_rng(n)
    xy = rng.integers(0, 12, size=(n, 2)).astype(np.float64)  # repeats: merged points
    xy[:3] = [[-1.0, -1.0], [13.0, -1.0], [6.0, 13.0]]
    tri = _kernel.Triangulation(xy)
    tri.insert_points(_order.brio_order(xy))
    tv, _nb = tri.finite_triangles()
    e = np.sort(np.concatenate([tv[:, [0, 1]], tv[:, [1, 2]], tv[:, [2, 0]]]), axis=1)
    big = n + 7
    want = np.unique(e[:, 0].astype(np.int64) * big + e[:, 1])
    assert (tri.edge_keys(big) == want).all()
    with pytest.raises(ValueError, match="vertex count"):
        tri.edge_keys(n - 1)


def _pslg_by_steps(xy, seg, from_hull):
    tri = _kernel.Triangulation(xy)
    merged = tri.insert_points(_order.brio_order(xy))
    split = tri.insert_segments(np.ascontiguousarray(merged[seg], dtype=np.int32))
    tri.carve(np.zeros((0, 2)), from_hull)
    return tri, merged, split


@pytest.mark.parametrize("from_hull", [True, False])
@pytest.mark.parametrize("n", [4, 40, 400])
def test_insert_pslg_is_the_insertions_and_carve_it_replaces(n, from_hull):
    rng = np.random.default_rng(n)
    ring = np.c_[np.cos(np.linspace(0, 2 * np.pi, n, endpoint=False)), np.zeros(n)]
    ring[:, 1] = np.sin(np.linspace(0, 2 * np.pi, n, endpoint=False))
    inner = rng.uniform(-0.5, 0.5, size=(n, 2)).round(1)  # repeats: merged points
    xy = np.ascontiguousarray(np.r_[ring, inner, ring[:1]])  # and a repeated corner
    seg = np.c_[np.arange(n), (np.arange(n) + 1) % n].astype(np.int32)
    seg = np.r_[seg, [[n, n + 1], [2 * n, 1]]].astype(np.int32)  # one ends at the copy
    want, want_merged, want_split = _pslg_by_steps(xy, seg, from_hull)
    got = _kernel.Triangulation(xy)
    merged, n_merged, split = got.insert_pslg(_order.round_keys(len(xy)), seg, from_hull)
    assert (merged == want_merged).all() and split == want_split
    assert n_merged == int((want_merged != np.arange(len(xy))).sum()) > 0
    for name, value in want.raw().items():
        assert (got.raw()[name] == value).all(), name


def test_insert_pslg_names_the_crossing_segment():
    xy = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=np.float64)
    seg = np.array([[0, 2], [1, 3]], dtype=np.int32)
    with pytest.raises(_kernel.CrossingError) as info:
        _kernel.Triangulation(xy).insert_pslg(_order.round_keys(4), seg, True)
    assert info.value.index == 1 and info.value.blocker_segment == 0


@given(st.lists(st.integers(-1, 4), max_size=10))
def test_take_or_none_is_the_lookup_with_minus_one_for_none(index):
    table = np.array([7, -1, 3, 0, 9], dtype=np.int32)
    idx = np.array(index, dtype=np.int32)
    want = np.where(idx < 0, -1, table[np.maximum(idx, 0)])
    assert (_kernel.take_or_none(table, idx) == want).all()


def test_take_or_none_refuses_an_index_outside_the_table():
    with pytest.raises(IndexError):
        _kernel.take_or_none(np.zeros(3, dtype=np.int32), np.array([0, 3], dtype=np.int32))


@given(st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=12))
def test_bounding_box_is_the_numpy_minimum_and_maximum(rows):
    xy = np.array(rows, dtype=np.float64)
    lo, hi = _kernel.bounding_box(xy)
    assert lo == tuple(xy.min(axis=0)) and hi == tuple(xy.max(axis=0))


def test_unique_points_of_many_points_is_numpy_unique():
    # above the kernel's NOGIL_MIN_ITEMS: the same routine without the GIL
    pts = np.random.default_rng(7).integers(0, 40, size=(5000, 2)).astype(np.float64)
    want, want_inverse = np.unique(pts, axis=0, return_inverse=True)
    got, inverse = unique_rows(pts)
    assert got.tobytes() == want.tobytes() and (inverse == want_inverse.reshape(-1)).all()


# Grid coordinates at several scales: vertices exactly on segments, on their lines
# beyond their ends, and coordinates far from the origin (where the reach is wide).
grid_coordinate = st.integers(0, 6)
grid_scale = st.sampled_from([1.0, 0.1, 1e-9, 3e7])


@given(
    st.lists(st.tuples(grid_coordinate, grid_coordinate), min_size=3, max_size=40),
    st.lists(st.tuples(st.integers(0, 39), st.integers(0, 39)), min_size=1, max_size=30),
    grid_scale,
    st.sampled_from([0.0, 1e-12, 0.05]),
)
def test_vertices_near_segments_finds_every_vertex_within_reach(rows, pairs, scale, reach):
    """The grid search replaces a tree query of the points within reach of each
    segment (shapely's dwithin): it must find all of those pairs (it may find a few
    more, which split_at_vertices then judges exactly)."""
    import shapely

    pts = np.unique(np.array(rows, dtype=np.float64) * scale, axis=0)
    seg = np.array([(a % len(pts), b % len(pts)) for a, b in pairs], dtype=np.int64)
    seg = np.ascontiguousarray(seg[seg[:, 0] != seg[:, 1]])
    if len(seg) == 0:
        return
    reach *= scale
    vi, si = _kernel.vertices_near_segments_pairs(pts, seg, reach)
    got = set(zip(vi.tolist(), si.tolist()))
    assert all(v not in seg[k] for v, k in got)  # never a segment's own end
    lines = shapely.linestrings(np.stack([pts[seg[:, 0]], pts[seg[:, 1]]], axis=1))
    v, k = shapely.STRtree(lines).query(shapely.points(pts), predicate="dwithin", distance=reach)
    want = {(a, b) for a, b in zip(v.tolist(), k.tolist()) if a not in seg[b]}
    assert want <= got


def test_vertices_near_segments_with_segments_across_the_whole_box():
    """512 segments across the box, all through its centre: each covers a whole row
    of the grid their number asks for, so the grid is coarsened, and the centre is
    still found on every one of them, and the point just above it on none."""
    y = np.arange(512) / 1024.0  # dyadic: 1 - y is exact, so the centre is exactly on
    pts = np.r_[np.c_[np.zeros(512), y], np.c_[np.ones(512), 1.0 - y], [[0.5, 0.5]]]
    pts = np.r_[pts, [[0.5, 0.5 + 2.0**-12]]]
    seg = np.c_[np.arange(512), np.arange(512) + 512].astype(np.int64)
    vi, si = _kernel.vertices_near_segments_pairs(pts, seg, 1e-12)
    assert set(zip(vi.tolist(), si.tolist())) == {(1024, k) for k in range(512)}


@pytest.mark.parametrize("n", [4, 300])
def test_arrays_release_gives_the_same_arrays_and_leaves_an_empty_kernel(n):
    """arrays(release=True) frees each kernel array after its last use (generate's and
    cdt's peak memory): the same result as arrays(), and afterwards an empty
    triangulation that answers further calls instead of reading freed memory."""
    from aftmesh.pslg import build_cdt

    rng = np.random.default_rng(n)
    t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t)] * 0.3
    square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    pts = np.r_[square, ring, rng.uniform(-0.9, 0.9, (n, 2))]
    pts = pts[(np.hypot(pts[:, 0], pts[:, 1]) > 0.35) | (np.arange(len(pts)) < 16)]
    segs = np.r_[[[0, 1], [1, 2], [2, 3], [3, 0]], [[4 + i, 4 + (i + 1) % 12] for i in range(12)]]
    kept = build_cdt(pts, segs, np.array([[0.0, 0.0]]), None, carve=True).kernel.arrays()
    kernel = build_cdt(pts, segs, np.array([[0.0, 0.0]]), None, carve=True).kernel
    released = kernel.arrays(release=True)
    assert released.keys() == kept.keys()
    for name in kept:
        assert released[name].shape == kept[name].shape, name
        assert released[name].dtype == kept[name].dtype, name
        assert released[name].tobytes() == kept[name].tobytes(), name
    assert len(kept["triangles"]) > 0
    again = kernel.arrays()
    assert all(len(again[name]) == 0 for name in ("points", "triangles", "segments"))
    assert kernel.state_counts() == (0, 0, 0)
    # the triangles, regions and neighbours are the kernel's own blocks, now owned by
    # the arrays: they outlive the kernel and may be written
    del kernel, again
    gc.collect()
    for name in ("triangles", "regions", "neighbors"):
        assert released[name].flags.writeable and released[name].flags.c_contiguous
        assert released[name].tobytes() == kept[name].tobytes(), name
