"""The compiled and shortcut pieces of the per-call input work (issue 12) against the
plain numpy rules they replace: ring clean-up, coordinate and segment checks, the
distinct points of a vertex list, repeated segments, the BRIO round keys."""

from __future__ import annotations

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
