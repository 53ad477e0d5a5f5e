"""Segment provenance in the kernel and ``aftmesh.cdt(..., crossings="split")``.

Provenance: every output segment's marker must be the input segment it lies on,
decided exactly (orient2d == 0 and within the input segment's span), through splits
at vertices lying on segments and at crossing points.  Crossing splits: the result
must be Triangle's ``p`` triangulation of the same input.
"""

from __future__ import annotations

import numpy as np
import pytest
import triangle
from test_cdt import assert_exact_cdt, exact_report

import aftmesh
from aftmesh import _kernel
from aftmesh.errors import CrossingSegmentsError, InvalidOptionError


def _within_span(p, a, b):
    """p (collinear with a-b) lies on the closed segment a-b: exact coordinate tests."""
    return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])


def _contains(V, S, j, p):
    a, b = V[S[j, 0]], V[S[j, 1]]
    return _kernel.py_orient2d(a[0], a[1], b[0], b[1], p[0], p[1]) == 0 and _within_span(p, a, b)


def assert_pieces_on_their_segments(mesh, V, S):
    """Every output segment lies exactly on the input segment its marker names; where
    input segments overlap, the first one (the lowest index) names the piece, as in
    Triangle."""
    P = mesh.points
    assert len(mesh.segment_markers) == len(mesh.segments)
    for (u, v), j in zip(mesh.segments.tolist(), mesh.segment_markers.tolist()):
        holders = [
            k for k in range(len(S)) if _contains(V, S, k, P[u]) and _contains(V, S, k, P[v])
        ]
        assert holders, f"segment ({u}, {v}) lies on no input segment"
        assert j == min(holders), f"segment ({u}, {v}) is marked {j}, lies on {holders}"


def grid_segments_case(rng, n_segments=14, size=12, n_on=10):
    """A square ring on an integer grid holding random horizontal, vertical and
    diagonal (slope +-1) segments between grid points, which cross each other at
    exactly representable points (integers and halves), plus grid points lying on the
    segments (so segments are split at vertices too)."""
    V = [(0, 0), (size, 0), (size, size), (0, size)]
    S = [(0, 1), (1, 2), (2, 3), (3, 0)]
    dirs = np.array([(1, 0), (0, 1), (1, 1), (1, -1)])
    seen = set()
    while len(S) < 4 + n_segments:
        d = dirs[rng.integers(4)]
        a = rng.integers(1, size, 2)
        k = int(rng.integers(2, size))
        b = a + k * d
        if not ((1 <= b) & (b <= size - 1)).all() or (tuple(a), tuple(b)) in seen:
            continue
        seen.add((tuple(a), tuple(b)))
        V += [tuple(a), tuple(b)]
        S.append((len(V) - 2, len(V) - 1))
        # a grid point strictly inside this segment, as a lone vertex
        if len(V) < 4 + 2 * n_segments + n_on and k > 1:
            V.append(tuple(a + int(rng.integers(1, k)) * d))
    return np.array(V, dtype=np.float64), np.array(S, dtype=np.int64)


@pytest.mark.parametrize("seed", range(12))
def test_segment_ids_name_the_input_segment_each_piece_lies_on(seed, checked):
    rng = np.random.default_rng(seed)
    V, S = grid_segments_case(rng)
    mesh = checked(aftmesh.cdt(V, S, crossings="split"))
    assert_exact_cdt(mesh)
    assert_pieces_on_their_segments(mesh, V, S)
    # and every input segment is covered by the pieces lying on it, end to end
    P = mesh.points
    for j in range(len(S)):
        on = [
            k
            for k, (u, v) in enumerate(mesh.segments.tolist())
            if _contains(V, S, j, P[u]) and _contains(V, S, j, P[v])
        ]
        pieces = mesh.segments[on]
        length = np.abs(P[pieces[:, 1]] - P[pieces[:, 0]]).max(axis=1)
        assert length.sum() == np.abs(V[S[j, 1]] - V[S[j, 0]]).max(), j


def test_segment_ids_through_vertices_on_the_segment_in_the_kernel():
    # vertices 4, 5 lie on segment 0 (0 -> 1); segment 1 is a diagonal
    V = np.array([(0, 0), (4, 0), (4, 4), (0, 4), (1, 0), (3, 0)], dtype=np.float64)
    k = _kernel.Triangulation(V)
    k.insert_points(np.arange(len(V), dtype=np.int32))
    assert k.insert_segments(np.array([(0, 1), (0, 2), (1, 2)], dtype=np.int32), first_id=7) == 1
    a = k.arrays()
    ids = {tuple(sorted(s)): i for s, i in zip(a["segments"].tolist(), a["segment_ids"].tolist())}
    vm = a["vertex_map"]
    assert ids[tuple(sorted((vm[0], vm[4])))] == 7
    assert ids[tuple(sorted((vm[4], vm[5])))] == 7
    assert ids[tuple(sorted((vm[5], vm[1])))] == 7
    assert ids[tuple(sorted((vm[0], vm[2])))] == 8
    assert ids[tuple(sorted((vm[1], vm[2])))] == 9
    assert k.validate() == []


def test_crossing_error_names_both_input_segments_exactly():
    V = [(0, 0), (2, 0), (2, 2), (0, 2)]
    S = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)]
    with pytest.raises(CrossingSegmentsError) as err:
        aftmesh.cdt(V, S)
    assert set(err.value.segments) == {4, 5}


def test_crossings_option_is_checked():
    with pytest.raises(InvalidOptionError, match="'raise', 'split'"):
        aftmesh.cdt([(0, 0), (1, 0), (0, 1)], crossings="ignore")


def test_split_without_crossings_is_the_plain_cdt(rng):
    import pslg_cases as pc

    case = pc.box_with_segments(rng, 40, 20)
    plain = aftmesh.cdt(case["vertices"], case["segments"])
    split = aftmesh.cdt(case["vertices"], case["segments"], crossings="split")
    for name in ("points", "triangles", "segments", "segment_markers"):
        assert np.array_equal(getattr(plain, name), getattr(split, name)), name
    assert split.info["crossings"]["segments"] == []


def random_crossing_case(rng, n_segments):
    """The unit square's ring holding random segments that cross each other."""
    inner = 0.05 + 0.9 * rng.random((2 * n_segments, 2))
    V = np.vstack([[(0, 0), (1, 0), (1, 1), (0, 1)], inner])
    S = np.vstack([[(0, 1), (1, 2), (2, 3), (3, 0)], 4 + np.arange(2 * n_segments).reshape(-1, 2)])
    return V, S


def _triangle_p(V, S):
    out = triangle.triangulate(
        {
            "vertices": V,
            "segments": S.astype(np.int32),
            "segment_markers": (np.arange(len(S)) + 1).astype(np.int32).reshape(-1, 1),
        },
        "p",
    )
    return out


def _pair_vertices(ours, theirs, ulps=4):
    """For each of our points, the index of Triangle's point at the same place: the
    same coordinates, or else the nearest within `ulps` units in the last place."""
    from scipy.spatial import cKDTree

    tol = ulps * np.spacing(np.abs(theirs).max())
    dist, idx = cKDTree(theirs).query(ours)
    exact = (theirs[idx] == ours).all(axis=1)
    assert (exact | (dist <= tol)).all(), "a vertex with no counterpart in Triangle's output"
    return idx


@pytest.mark.parametrize("seed", range(16))
def test_split_crossings_matches_triangle(seed, checked):
    rng = np.random.default_rng(1000 + seed)
    V, S = random_crossing_case(rng, int(rng.integers(2, 9)))
    mesh = checked(aftmesh.cdt(V, S, crossings="split"))
    assert_exact_cdt(mesh)
    ref = _triangle_p(V, S)
    report = mesh.info["crossings"]
    # each reported point is a vertex of the mesh, between the segments it names
    assert np.array_equal(mesh.points[report["vertices"]], report["points"])
    assert all(len(s) >= 2 for s in report["segments"])
    n_added_ref = len(ref["vertices"]) - len(V)
    assert len(report["points"]) == n_added_ref
    assert len(mesh.points) == len(ref["vertices"])
    # the input vertices keep their place, and vertex_map says where
    assert np.array_equal(mesh.points[mesh.info["vertex_map"]], V)
    # Our crossing points and Triangle's are each the exact crossing rounded, by
    # different formulas: pair every vertex with Triangle's at the same place (input
    # vertices exactly, crossing points within a few ulps) and compare the triangles
    # and the markers of the segment pieces through that pairing.
    ref_pts = np.asarray(ref["vertices"])
    pair = _pair_vertices(mesh.points, ref_pts)
    assert sorted(pair.tolist()) == list(range(len(ref_pts))), "no one-to-one pairing"
    ours = {tuple(sorted(t)) for t in pair[mesh.triangles].tolist()}
    theirs = {tuple(sorted(t)) for t in np.asarray(ref["triangles"]).tolist()}
    ref_rep = exact_report(ref_pts, ref["triangles"], ref["segments"])
    if ref_rep["cocircular"] == 0:
        assert ours == theirs, f"triangles differ: {sorted(ours ^ theirs)[:6]}"
    else:
        assert len(ours) == len(theirs)
    our_marks = {
        frozenset(s): m for s, m in zip(pair[mesh.segments].tolist(), mesh.segment_markers.tolist())
    }
    their_marks = {
        frozenset(s): m - 1
        for s, m in zip(
            np.asarray(ref["segments"]).tolist(),
            np.asarray(ref["segment_markers"]).ravel().tolist(),
        )
    }
    assert our_marks == their_marks, "segment pieces or their markers differ from Triangle's"
    # every piece's marker is one of the input segments through both of its ends
    # (pieces of crossing-split segments are within an ulp of the segment, so this is
    # checked by the crossing report rather than by orient2d)
    crossing_of = {int(v): set(s) for v, s in zip(report["vertices"], report["segments"])}
    vm = mesh.info["vertex_map"]
    owner = {}
    for j, (a, b) in enumerate(S.tolist()):
        owner.setdefault(int(vm[a]), set()).add(j)
        owner.setdefault(int(vm[b]), set()).add(j)
    for (u, v), m in zip(mesh.segments.tolist(), mesh.segment_markers.tolist()):
        for w in (u, v):
            assert m in crossing_of.get(w, set()) | owner.get(w, set()), (u, v, m)
