"""Minimal failures found by the robustness suite and fuzzing, pinned.

Each test is the smallest input found for one failure class, named
``test_<what>_<short-description>`` (the description says what went wrong), and
asserts the right behaviour, so it fails until the bug is fixed.  Calls that hung or
could exhaust memory run in a forked child with a time and memory limit
(``fuzz_domains.isolated``), so a regression fails its test instead of the run.
"""
from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pytest
from shapely.geometry import GeometryCollection, LineString, Polygon, box

import aftmesh
from aftmesh import (CrossingSegmentsError, InvalidInputError, InvalidOptionError,
                     InvalidSizeError)

import fuzz_domains as fd

SQ = box(0, 0, 1, 1)


def _in_child(fn, *args, timeout=30.0, memory_gb=4.0, **kw):
    return fd.isolated(fn, *args, timeout=timeout, memory_gb=memory_gb, **kw)


# ------------------------------------------------------------ sizes and their limits
@pytest.mark.parametrize("size", [1e-300, 5e-324, [3.6303995510890073e-261]])
def test_size_tiny_constant_zero_division(size):
    """generate(square, 1e-300): ZeroDivisionError from the triangle-count estimate
    (h_min ** 2 underflows to 0) instead of an InvalidSizeError.  Also as a
    per-region list (found by the garbage fuzzer)."""
    with pytest.raises(InvalidSizeError):
        _in_child(aftmesh.generate, SQ, size)


def test_size_far_too_small_not_refused():
    """generate(square, 1e-6) asks for ~5e12 triangles, beyond what int32 indices can
    number: it should be refused at once (InvalidSizeError), not discretize 4e6
    boundary points and then run for hours towards an index overflow."""
    t = time.perf_counter()
    with pytest.raises(InvalidSizeError):
        _in_child(aftmesh.generate, SQ, 1e-6, timeout=20)
    assert time.perf_counter() - t < 5


def test_max_triangles_boundary_work_not_capped():
    """generate(square, 1e-7, max_triangles=1000): the boundary is discretized into
    4e7 points (tens of seconds, GBs, MemoryError under a 4 GB limit) before the
    formula-(3) refusal; the number of boundary pieces is known before that."""
    t = time.perf_counter()
    with pytest.raises(InvalidSizeError):
        _in_child(aftmesh.generate, SQ, 1e-7, max_triangles=1000, timeout=30)
    assert time.perf_counter() - t < 5


def test_boundary_short_edge_next_to_long_edge_explodes(checked):
    """A quadrilateral with one edge of length 1e-9 next to edges of length ~1: the
    boundary discretization integrates 1/h with 32 trapezoid samples, and the first
    sample interval of each long edge (1/31 long, h = 1e-9 at one end) counts ~1.6e7
    pieces: 3.9e7 boundary points (0.04 / eps in general) where the graded size asks
    for a few hundred.  Found as a 'hang' on a slot 1e-9 wide."""
    poly = Polygon([(0, 0), (1, 0), (1, 1), (0, 1e-9)])
    mesh = _in_child(aftmesh.generate, poly, timeout=30)
    checked(mesh, domain_area=poly.area, area_rtol=1e-9)
    assert mesh.n_points < 20000, f"{mesh.n_points} points"


def test_boundary_short_edge_slot_hang(checked):
    """The fuzzer's original: a slot 1.7e-9 wide cut into the unit square, no size."""
    poly = Polygon([(0, 0), (1, 0), (1, 1), (0.7239563302418025, 1),
                    (0.7239563302418025, 0.75), (0.7239563285035484, 0.75),
                    (0.7239563285035484, 1), (0, 1)])
    mesh = _in_child(aftmesh.generate, poly, timeout=30)
    checked(mesh, domain_area=fd.exact_area([poly]))


def test_size_zero_dim_array_type_error(checked):
    """size=np.array(0.1) (a 0-d array, a number): TypeError 'iteration over a 0-d
    array' (it is taken for a per-region list)."""
    mesh = aftmesh.generate(SQ, np.array(0.1))
    checked(mesh, domain_area=1.0)
    ref = aftmesh.generate(SQ, 0.1)
    assert np.array_equal(mesh.triangles, ref.triangles)


# ------------------------------------------------------------------ coordinates
def test_coordinates_huge_overflow_error():
    """A triangle with legs 1e200: OverflowError (34, 'Numerical result out of range')
    from the triangle-count estimate; the dict / cdt path refuses |x| > 1e100 with an
    InvalidInputError, the polygon path does not check."""
    with pytest.raises(InvalidInputError):
        _in_child(aftmesh.generate, [(0, 0), (1e200, 0), (0, 1e200)], 1e199)


def test_coordinates_huge_misleading_message():
    """The same with size=None and legs 1e300: 'size=None takes the size from the
    input edges, but there are none' (their lengths overflow); the message should say
    that the coordinates are too large."""
    with pytest.raises(InvalidInputError) as info:
        _in_child(aftmesh.generate, [(0, 0), (1e300, 0), (0, 1e300)])
    assert "there are none" not in str(info.value)


# -------------------------------------------------------------------- options
def test_option_min_area_text_type_error():
    """min_area='a': TypeError from np.isfinite instead of InvalidOptionError."""
    with pytest.raises(InvalidOptionError, match="min_area"):
        aftmesh.generate(SQ, 0.1, min_area="a")


def test_option_min_area_empty_list_ambiguous_truth():
    """min_area=[]: bare ValueError 'The truth value of an empty array is ambiguous'
    from `np.isfinite(min_area) and ...` (found by the garbage fuzzer)."""
    with pytest.raises(InvalidOptionError, match="min_area"):
        aftmesh.generate(SQ, 0.1, min_area=[])


def test_option_close_factor_none_type_error():
    """close_factor=None: TypeError from np.isfinite."""
    with pytest.raises(InvalidOptionError, match="close_factor"):
        aftmesh.generate(SQ, 0.1, close_factor=None)


def test_option_gradation_text_type_error():
    """gradation='x': TypeError from np.isfinite (gradation errors are InvalidSizeError)."""
    with pytest.raises(InvalidInputError, match="gradation"):
        aftmesh.generate(SQ, 0.1, gradation="x")


def test_option_order_unhashable_type_error():
    """order=[]: TypeError 'unhashable type: list' from the dict lookup."""
    with pytest.raises(InvalidOptionError, match="order"):
        aftmesh.generate(SQ, 0.1, order=[])


def test_option_strategy_wrong_type_attribute_error():
    """strategy=1: AttributeError "'int' object has no attribute 'is_builtin'"."""
    with pytest.raises(InvalidOptionError, match="strategy"):
        aftmesh.generate(SQ, 0.1, strategy=1)


def test_option_max_triangles_huge_overflow_error(checked):
    """max_triangles=2**70: OverflowError converting to a C long long; a cap above
    any possible mesh is no cap (or an InvalidOptionError)."""
    try:
        mesh = aftmesh.generate(SQ, 0.1, max_triangles=2 ** 70)
    except InvalidOptionError:
        return
    checked(mesh, domain_area=1.0)


def test_option_smooth_huge_overflow_error(checked):
    """smooth=2**40: OverflowError 'value too large to convert to int'."""
    try:
        mesh = _in_child(aftmesh.generate, SQ, 0.1, smooth=2 ** 40, timeout=20)
    except InvalidOptionError:
        return
    checked(mesh, domain_area=1.0)


def test_option_smooth_many_rounds_hang(checked):
    """smooth=10**9 on a 230-triangle mesh runs 10**9 passes (no stop when a pass
    moves nothing) inside one nogil call that never checks for Ctrl-C: an
    uninterruptible hang."""
    try:
        mesh = _in_child(aftmesh.generate, SQ, 0.1, smooth=10 ** 9, timeout=20)
    except InvalidOptionError:
        return
    checked(mesh, domain_area=1.0)


def test_ctrl_c_ignored_during_smoothing():
    """SIGINT while smoothing runs (after the compiled loop is done) is only seen when
    smoothing returns: with smooth=10**6 never.  It should stop within a second.
    (smooth is now capped at 1000 rounds and stops when a round moves nothing; the
    test uses the cap.)"""
    def run():
        state = {}

        def fire():
            time.sleep(0.5)
            state["sent"] = time.perf_counter()
            os.kill(os.getpid(), signal.SIGINT)

        def progress(f):
            if f > 0.95 and "armed" not in state:
                state["armed"] = True
                threading.Thread(target=fire, daemon=True).start()
        try:
            aftmesh.generate(SQ, 0.002, smooth=1000, progress=progress)
        except KeyboardInterrupt:
            return "interrupted", time.perf_counter() - state["sent"]
        return "finished", state.get("sent")

    what, value = _in_child(run, timeout=30)
    if what == "finished":
        assert value is None, "finished after the signal without a KeyboardInterrupt"
    else:
        assert value < 1.0, f"KeyboardInterrupt {value:.2f} s after SIGINT"


# --------------------------------------------------------------- signals
def test_signal_handler_exception_replaced_by_keyboardinterrupt():
    """A SIGALRM handler raising its own exception during the compiled loop (how
    pytest-timeout and many watchdogs work) surfaces as KeyboardInterrupt: the loop
    clears the pending exception after PyErr_CheckSignals and returns
    ERR_INTERRUPTED.  The handler's exception should propagate."""
    class Watchdog(Exception):
        pass

    def run():
        def handler(sig, frame):
            raise Watchdog("time is up")
        signal.signal(signal.SIGALRM, handler)
        signal.setitimer(signal.ITIMER_REAL, 0.5)
        try:
            aftmesh.generate(SQ, 0.001)
        except BaseException as exc:          # noqa: BLE001
            return type(exc).__name__
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        return "finished"

    assert _in_child(run, timeout=60) == "Watchdog"


# ------------------------------------------------------------------- domains
def test_constraints_crossing_lines_not_noded(checked):
    """Two constraint lines crossing in an X: domain.py computes the crossing point
    with shapely but splits a segment there only if the point is exactly on it
    (orient2d == 0), which a rounded crossing point almost never is, so the lines
    still cross: CrossingSegmentsError between 'constraint line 1' and 'constraint
    line 0' (with size None or 0.1; size 0.3 happens to work)."""
    gc = GeometryCollection([box(0, 0, 2, 1), LineString([(0.2, 0.2), (1.8, 0.8)]),
                             LineString([(0.2, 0.8), (1.8, 0.2)])])
    for size in (None, 0.1):
        mesh = aftmesh.generate(gc, size)
        checked(mesh, domain_area=2.0)


def test_constraints_crossing_lines_hypothesis_minimal(checked):
    """The example hypothesis shrank to: a triangle with two crossing lines."""
    tri = Polygon([(-0.5, 0.8660254037844387), (-0.5, -0.8660254037844385),
                   (1.0, -2.4492935982947064e-16)])
    gc = GeometryCollection([tri, LineString([(0.5, -0.25), (0, 0.5)]),
                             LineString([(0.5, 0), (0, 0)])])
    mesh = aftmesh.generate(gc, 0.5728219618694801)
    checked(mesh, domain_area=fd.exact_area([tri]))


def test_dict_crossing_segments_accepted_for_some_sizes():
    """A dict whose two diagonals cross: CrossingSegmentsError with size None, 0.15,
    0.2, 0.3 or 0.5, but a mesh with size 0.1, where both diagonals happen to be cut
    at their midpoint (0.5, 0.5).  The policy (pslg.py) is to refuse crossing
    segments, whatever the size."""
    d = {"vertices": [(0, 0), (1, 0), (1, 1), (0, 1)],
         "segments": [(0, 2), (1, 3), (0, 1), (1, 2), (2, 3), (3, 0)]}
    with pytest.raises(CrossingSegmentsError):
        aftmesh.generate(d, 0.3)
    with pytest.raises(CrossingSegmentsError):
        aftmesh.generate(d, 0.1)


def test_region_ring_too_short_plain_valueerror():
    """A region given as a ring of two points: shapely's bare ValueError 'A linearring
    requires at least 4 coordinates.' instead of an InvalidInputError naming region 1."""
    with pytest.raises(InvalidInputError, match="region 1"):
        aftmesh.generate([SQ, [(2, 0), (3, 0)]], 0.1)


def test_segment_markers_beyond_int32_silently_wrap():
    """segment_markers=[2**40, 2, 3]: cast to int32 without a check, so the first
    segment's marker silently becomes 0."""
    d = {"vertices": [(0, 0), (1, 0), (0, 1)], "segments": [(0, 1), (1, 2), (2, 0)],
         "segment_markers": [2 ** 40, 2, 3]}
    try:
        mesh = aftmesh.generate(d, 0.5)
    except InvalidInputError:
        return
    assert 2 ** 40 in set(np.asarray(mesh.segment_markers).tolist())


def test_dict_segment_markers_ragged_plain_valueerror():
    """segment_markers=[None, [[0.0]]]: numpy's bare ValueError 'setting an array
    element with a sequence ... inhomogeneous shape' from np.asarray in _from_dict,
    not an InvalidInputError naming segment_markers (found by the garbage fuzzer)."""
    d = {"vertices": [(0, 0), (1, 0), (0, 1)], "segments": [(0, 1), (1, 2), (2, 0)],
         "segment_markers": [None, np.array([[0.0]]), 1]}
    with pytest.raises(InvalidInputError, match="segment_markers"):
        aftmesh.generate(d, 0.5)


def test_check_mesh_stale_neighbors_index_error():
    """check_mesh on a mesh whose first triangle was dropped without renumbering the
    neighbors: it notes the neighbor mismatch but then indexes triangles with the
    stale neighbors in the Delaunay check, IndexError 'index 43 is out of bounds',
    instead of a MeshCheckError listing the problems (found by the oracle's
    self-test)."""
    from aftmesh.checks import MeshCheckError, check_mesh
    good = aftmesh.generate(SQ, 0.25)
    T = np.asarray(good.triangles)[1:]
    N = np.asarray(good.neighbors)[1:]
    assert N.max() == len(T)
    broken = aftmesh.Mesh(points=good.points, triangles=T, neighbors=N,
                          segments=good.segments, regions=np.zeros(len(T), dtype=np.int32))
    with pytest.raises(MeshCheckError):
        check_mesh(broken, domain_area=1.0)


def test_constraints_far_from_origin_rejected(checked):
    """A constraint line well inside box(1e6, 1e6, 1e6 + 2, 1e6 + 1): 'constraint line
    0 is not inside the domain'.  domain.py tests it against
    union.buffer(1e-12 * union.length), a distance far below the coordinates' ulp,
    and GEOS returns an EMPTY polygon for that buffer.  (Found at offset 6.7e7.)"""
    off = 1e6
    b = box(off, off, off + 2, off + 1)
    gc = GeometryCollection([b, LineString([(off + 0.5, off + 0.5), (off + 1.5, off + 0.5)])])
    mesh = aftmesh.generate(gc, 0.2)
    checked(mesh, domain_area=2.0)


def test_size_short_edge_floods_grid_cell(checked):
    """A constraint line 1.4e-9 long inside the square [-1, 1]^2 with size 0.5: the
    size field puts the edge's length on the four grid nodes around it, so the whole
    grid cell (4e-3 wide) gets h = 1.4e-9, ~1e13 triangles: meshing never ends (0.8 s
    for a fraction 9e-14 of the area).  The size should grow away from the short
    edge at the gradation rate instead (a few hundred triangles more)."""
    gc = GeometryCollection([box(-1, -1, 1, 1), LineString([(0, 0), (1e-9, 1e-9)])])
    mesh = _in_child(aftmesh.generate, gc, 0.5, timeout=30)
    checked(mesh, domain_area=4.0)
    assert mesh.n_triangles < 20000


def test_predicates_underflow_tiny_triangle_called_collinear():
    """cdt of a right triangle with legs 1e-200: 'all 3 vertices are collinear'.  The
    exact predicates' products underflow below ~1e-308 (orient2d of these points is
    0), so for coordinate differences below ~1e-154 every answer may be wrong (a
    fuzzed polygon with a vertex 1e-250 from another got a false
    CrossingSegmentsError, a constraint line 3e-130 long a non-Delaunay mesh).  Either
    triangulate it, or refuse such coordinates with a message that says so."""
    P = [(0.0, 0.0), (1e-200, 0.0), (0.0, 1e-200)]
    try:
        mesh = aftmesh.cdt(P)
    except InvalidInputError as exc:
        assert "collinear" not in str(exc), str(exc)
        return
    assert mesh.n_triangles == 1


@pytest.mark.parametrize("regions", [False, 0, 1.5])
def test_dict_regions_scalar_type_error(regions):
    """A dict domain whose 'regions' is a scalar (False, 0, 1.5): TypeError "object of
    type 'bool' has no len()" from `len(regions)` in _from_dict; cdt() with the same
    regions says 'regions must be rows of (x, y, marker)' (found by the garbage fuzzer,
    long profile)."""
    d = {"vertices": [(0, 0), (1, 0), (0, 1)], "segments": [(0, 1), (1, 2), (2, 0)],
         "regions": regions}
    with pytest.raises(InvalidInputError, match="regions"):
        aftmesh.generate(d, 0.5)
