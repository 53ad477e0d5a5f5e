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
import traceback

import fuzz_domains as fd
import numpy as np
import pytest
from shapely.geometry import GeometryCollection, LineString, Point, Polygon, box

import aftmesh
from aftmesh import (
    CrossingSegmentsError,
    InvalidDomainError,
    InvalidInputError,
    InvalidOptionError,
    InvalidSizeError,
)

SQ = box(0, 0, 1, 1)
# how long after smoothing starts the Ctrl-C test sends its signal: well inside the
# first round, which takes tens of milliseconds on the test square
SIGNAL_INTO_SMOOTHING_S = 0.005


def _in_child(fn, *args, timeout=30.0, memory_gb=4.0, **kw):
    return fd.isolated(fn, *args, timeout=timeout, memory_gb=memory_gb, **kw)


# ------------------------------------------------------------ sizes and their limits
@pytest.mark.parametrize("size", [1e-300, 5e-324, [3.6303995510890073e-261]])
def test_size_that_underflows_is_refused(size):
    """generate(square, 1e-300): ZeroDivisionError from the triangle-count estimate
    (h_min ** 2 underflows to 0) instead of an InvalidSizeError.  Also as a
    per-region list (found by the garbage fuzzer)."""
    with pytest.raises(InvalidSizeError):
        _in_child(aftmesh.generate, SQ, size)


def test_size_asking_too_many_triangles_refused_at_once(time_limit):
    """generate(square, 1e-6) asks for ~5e12 triangles, beyond what int32 indices can
    number: it should be refused at once (InvalidSizeError), not discretize 4e6
    boundary points and then run for hours towards an index overflow."""
    t = time.perf_counter()
    with pytest.raises(InvalidSizeError):
        _in_child(aftmesh.generate, SQ, 1e-6, timeout=20)
    time_limit(time.perf_counter() - t, 5, "refusal_s")


def test_max_triangles_refuses_before_discretizing_the_boundary(time_limit):
    """generate(square, 1e-7, max_triangles=1000): the boundary is discretized into
    4e7 points (tens of seconds, GBs, MemoryError under a 4 GB limit) before the
    formula-(3) refusal; the number of boundary pieces is known before that."""
    t = time.perf_counter()
    with pytest.raises(InvalidSizeError):
        _in_child(aftmesh.generate, SQ, 1e-7, max_triangles=1000, timeout=30)
    time_limit(time.perf_counter() - t, 5, "refusal_s")


def test_short_edge_next_to_long_edges_keeps_boundary_graded(checked):
    """A quadrilateral with one edge of length 1e-9 next to edges of length ~1: the
    boundary discretization integrates 1/h with 32 trapezoid samples, and the first
    sample interval of each long edge (1/31 long, h = 1e-9 at one end) counts ~1.6e7
    pieces: 3.9e7 boundary points (0.04 / eps in general) where the graded size asks
    for a few hundred.  Found as a 'hang' on a slot 1e-9 wide."""
    poly = Polygon([(0, 0), (1, 0), (1, 1), (0, 1e-9)])
    mesh = _in_child(aftmesh.generate, poly, timeout=30)
    checked(mesh, domain_area=poly.area, area_rtol=1e-9)
    assert mesh.n_points < 20000, f"{mesh.n_points} points"


def test_slot_a_few_nanometres_wide_is_meshed(checked):
    """The fuzzer's original: a slot 1.7e-9 wide cut into the unit square, no size."""
    poly = Polygon(
        [
            (0, 0),
            (1, 0),
            (1, 1),
            (0.7239563302418025, 1),
            (0.7239563302418025, 0.75),
            (0.7239563285035484, 0.75),
            (0.7239563285035484, 1),
            (0, 1),
        ]
    )
    mesh = _in_child(aftmesh.generate, poly, timeout=30)
    checked(mesh, domain_area=fd.exact_area([poly]))


def test_size_as_zero_dim_array_is_a_number(checked):
    """size=np.array(0.1) (a 0-d array, a number): TypeError 'iteration over a 0-d
    array' (it is taken for a per-region list)."""
    mesh = aftmesh.generate(SQ, np.array(0.1))
    checked(mesh, domain_area=1.0)
    ref = aftmesh.generate(SQ, 0.1)
    assert np.array_equal(mesh.triangles, ref.triangles)


# ------------------------------------------------------------------ coordinates
def test_huge_coordinates_refused_with_invalid_input():
    """A triangle with legs 1e200: OverflowError (34, 'Numerical result out of range')
    from the triangle-count estimate; the dict / cdt path refuses |x| > 1e100 with an
    InvalidInputError, the polygon path does not check."""
    with pytest.raises(InvalidInputError):
        _in_child(aftmesh.generate, [(0, 0), (1e200, 0), (0, 1e200)], 1e199)


def test_huge_coordinates_message_names_the_coordinates():
    """The same with size=None and legs 1e300: 'size=None takes the size from the
    input edges, but there are none' (their lengths overflow); the message should say
    that the coordinates are too large."""
    with pytest.raises(InvalidInputError) as info:
        _in_child(aftmesh.generate, [(0, 0), (1e300, 0), (0, 1e300)])
    assert "there are none" not in str(info.value)


# -------------------------------------------------------------------- options
def test_min_area_text_refused_as_invalid_option():
    """min_area='a': TypeError from np.isfinite instead of InvalidOptionError."""
    with pytest.raises(InvalidOptionError, match="min_area"):
        aftmesh.generate(SQ, 0.1, min_area="a")


def test_min_area_empty_list_refused_as_invalid_option():
    """min_area=[]: bare ValueError 'The truth value of an empty array is ambiguous'
    from `np.isfinite(min_area) and ...` (found by the garbage fuzzer)."""
    with pytest.raises(InvalidOptionError, match="min_area"):
        aftmesh.generate(SQ, 0.1, min_area=[])


def test_close_factor_none_refused_as_invalid_option():
    """close_factor=None: TypeError from np.isfinite."""
    with pytest.raises(InvalidOptionError, match="close_factor"):
        aftmesh.generate(SQ, 0.1, close_factor=None)


def test_gradation_text_refused_as_invalid_input():
    """gradation='x': TypeError from np.isfinite (gradation errors are InvalidSizeError)."""
    with pytest.raises(InvalidInputError, match="gradation"):
        aftmesh.generate(SQ, 0.1, gradation="x")


def test_order_unhashable_refused_as_invalid_option():
    """order=[]: TypeError 'unhashable type: list' from the dict lookup."""
    with pytest.raises(InvalidOptionError, match="order"):
        aftmesh.generate(SQ, 0.1, order=[])


def test_strategy_of_wrong_type_refused_as_invalid_option():
    """strategy=1: AttributeError "'int' object has no attribute 'is_builtin'"."""
    with pytest.raises(InvalidOptionError, match="strategy"):
        aftmesh.generate(SQ, 0.1, strategy=1)


def test_max_triangles_beyond_int64_is_no_cap_or_refused(checked):
    """max_triangles=2**70: OverflowError converting to a C long long; a cap above
    any possible mesh is no cap (or an InvalidOptionError)."""
    try:
        mesh = aftmesh.generate(SQ, 0.1, max_triangles=2**70)
    except InvalidOptionError:
        return
    checked(mesh, domain_area=1.0)


def test_smooth_beyond_int_range_is_capped_or_refused(checked):
    """smooth=2**40: OverflowError 'value too large to convert to int'."""
    try:
        mesh = _in_child(aftmesh.generate, SQ, 0.1, smooth=2**40, timeout=20)
    except InvalidOptionError:
        return
    checked(mesh, domain_area=1.0)


def test_smooth_many_rounds_stops_when_nothing_moves(checked):
    """smooth=10**9 on a 230-triangle mesh runs 10**9 passes (no stop when a pass
    moves nothing) inside one nogil call that never checks for Ctrl-C: an
    uninterruptible hang."""
    try:
        mesh = _in_child(aftmesh.generate, SQ, 0.1, smooth=10**9, timeout=20)
    except InvalidOptionError:
        return
    checked(mesh, domain_area=1.0)


def test_ctrl_c_during_smoothing_interrupts(time_limit):
    """SIGINT while smoothing runs (after the compiled loop is done) must stop it
    within a second, not only when smoothing returns.  smooth is capped at 1000 rounds
    and stops when a round moves nothing; the test asks for the cap.  The signal is
    sent SIGNAL_INTO_SMOOTHING_S after smoothing starts, so it lands inside it:
    smoothing this square takes tens of milliseconds (more in a debug build), and a
    signal timed from the front's progress instead could arrive after generate had
    returned."""
    from aftmesh import _stages

    def run():
        state = {}
        signal.signal(signal.SIGINT, signal.default_int_handler)  # even if inherited ignored
        real_smooth = _stages.smooth

        def fire():
            time.sleep(SIGNAL_INTO_SMOOTHING_S)
            state["sent"] = time.perf_counter()
            os.kill(os.getpid(), signal.SIGINT)

        def smooth_with_signal(*args, **kwargs):
            threading.Thread(target=fire, daemon=True).start()
            try:
                return real_smooth(*args, **kwargs)
            except KeyboardInterrupt as exc:
                # raised by the kernel's smoothing itself, not by Python on a signal
                # still pending when it returned
                innermost = traceback.extract_tb(exc.__traceback__)[-1].name
                state["in_smoothing"] = innermost.endswith("Triangulation.smooth")
                raise

        _stages.smooth = smooth_with_signal
        try:
            # a progress callable keeps generate on the stages, which call _stages.smooth
            aftmesh.generate(SQ, 0.002, smooth=1000, progress=lambda f: None)
        except KeyboardInterrupt:
            return "interrupted", (time.perf_counter() - state["sent"], state.get("in_smoothing"))
        finally:
            _stages.smooth = real_smooth
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # a late signal: not a crash
        return "finished", state.get("sent")

    what, value = _in_child(run, timeout=30)
    assert what == "interrupted", "smoothing ran to the end with a signal pending"
    latency, in_smoothing = value
    assert in_smoothing, "the interrupt surfaced only after smoothing had returned"
    time_limit(latency, 1.0, "interrupt_latency_s")


# --------------------------------------------------------------- signals
def test_signal_handler_exception_propagates_from_the_loop():
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
        except BaseException as exc:  # noqa: BLE001
            return type(exc).__name__
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        return "finished"

    assert _in_child(run, timeout=60) == "Watchdog"


# ------------------------------------------------------------------- domains
def test_crossing_constraint_lines_are_noded(checked):
    """Two constraint lines crossing in an X: domain.py computes the crossing point
    with shapely but splits a segment there only if the point is exactly on it
    (orient2d == 0), which a rounded crossing point almost never is, so the lines
    still cross: CrossingSegmentsError between 'constraint line 1' and 'constraint
    line 0' (with size None or 0.1; size 0.3 happens to work)."""
    gc = GeometryCollection(
        [
            box(0, 0, 2, 1),
            LineString([(0.2, 0.2), (1.8, 0.8)]),
            LineString([(0.2, 0.8), (1.8, 0.2)]),
        ]
    )
    for size in (None, 0.1):
        mesh = aftmesh.generate(gc, size)
        checked(mesh, domain_area=2.0)


def test_crossing_constraint_lines_in_a_triangle_are_noded(checked):
    """The example hypothesis shrank to: a triangle with two crossing lines."""
    tri = Polygon(
        [(-0.5, 0.8660254037844387), (-0.5, -0.8660254037844385), (1.0, -2.4492935982947064e-16)]
    )
    gc = GeometryCollection(
        [tri, LineString([(0.5, -0.25), (0, 0.5)]), LineString([(0.5, 0), (0, 0)])]
    )
    mesh = aftmesh.generate(gc, 0.5728219618694801)
    checked(mesh, domain_area=fd.exact_area([tri]))


def test_dict_crossing_segments_refused_whatever_the_size():
    """A dict whose two diagonals cross: CrossingSegmentsError with size None, 0.15,
    0.2, 0.3 or 0.5, but a mesh with size 0.1, where both diagonals happen to be cut
    at their midpoint (0.5, 0.5).  The policy (pslg.py) is to refuse crossing
    segments, whatever the size."""
    d = {
        "vertices": [(0, 0), (1, 0), (1, 1), (0, 1)],
        "segments": [(0, 2), (1, 3), (0, 1), (1, 2), (2, 3), (3, 0)],
    }
    with pytest.raises(CrossingSegmentsError):
        aftmesh.generate(d, 0.3)
    with pytest.raises(CrossingSegmentsError):
        aftmesh.generate(d, 0.1)


def test_region_ring_too_short_names_the_region():
    """A region given as a ring of two points: shapely's bare ValueError 'A linearring
    requires at least 4 coordinates.' instead of an InvalidInputError naming region 1."""
    with pytest.raises(InvalidInputError, match="region 1"):
        aftmesh.generate([SQ, [(2, 0), (3, 0)]], 0.1)


def test_segment_markers_beyond_int32_kept_or_refused():
    """segment_markers=[2**40, 2, 3]: cast to int32 without a check, so the first
    segment's marker silently becomes 0."""
    d = {
        "vertices": [(0, 0), (1, 0), (0, 1)],
        "segments": [(0, 1), (1, 2), (2, 0)],
        "segment_markers": [2**40, 2, 3],
    }
    try:
        mesh = aftmesh.generate(d, 0.5)
    except InvalidInputError:
        return
    assert 2**40 in set(np.asarray(mesh.segment_markers).tolist())


def test_dict_segment_markers_ragged_refused_by_name():
    """segment_markers=[None, [[0.0]]]: numpy's bare ValueError 'setting an array
    element with a sequence ... inhomogeneous shape' from np.asarray in _from_dict,
    not an InvalidInputError naming segment_markers (found by the garbage fuzzer)."""
    d = {
        "vertices": [(0, 0), (1, 0), (0, 1)],
        "segments": [(0, 1), (1, 2), (2, 0)],
        "segment_markers": [None, np.array([[0.0]]), 1],
    }
    with pytest.raises(InvalidInputError, match="segment_markers"):
        aftmesh.generate(d, 0.5)


def test_check_mesh_reports_stale_neighbors():
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
    broken = aftmesh.Mesh(
        points=good.points,
        triangles=T,
        neighbors=N,
        segments=good.segments,
        regions=np.zeros(len(T), dtype=np.int32),
    )
    with pytest.raises(MeshCheckError):
        check_mesh(broken, domain_area=1.0)


def test_constraint_line_far_from_origin_accepted(checked):
    """A constraint line well inside box(1e6, 1e6, 1e6 + 2, 1e6 + 1): 'constraint line
    0 is not inside the domain'.  domain.py tests it against
    union.buffer(1e-12 * union.length), a distance far below the coordinates' ulp,
    and GEOS returns an EMPTY polygon for that buffer.  (Found at offset 6.7e7.)"""
    off = 1e6
    b = box(off, off, off + 2, off + 1)
    gc = GeometryCollection([b, LineString([(off + 0.5, off + 0.5), (off + 1.5, off + 0.5)])])
    mesh = aftmesh.generate(gc, 0.2)
    checked(mesh, domain_area=2.0)


def test_size_grows_away_from_a_very_short_edge(checked):
    """A constraint line 1.4e-9 long inside the square [-1, 1]^2 with size 0.5: the
    grid size field of the time put the edge's length on the four nodes around it, so the whole
    grid cell (4e-3 wide) gets h = 1.4e-9, ~1e13 triangles: meshing never ends (0.8 s
    for a fraction 9e-14 of the area).  The size should grow away from the short
    edge at the gradation rate instead (a few hundred triangles more)."""
    gc = GeometryCollection([box(-1, -1, 1, 1), LineString([(0, 0), (1e-9, 1e-9)])])
    mesh = _in_child(aftmesh.generate, gc, 0.5, timeout=30)
    checked(mesh, domain_area=4.0)
    assert mesh.n_triangles < 20000


def test_tiny_triangle_triangulated_or_refused_not_called_collinear():
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
def test_dict_regions_scalar_refused_by_name(regions):
    """A dict domain whose 'regions' is a scalar (False, 0, 1.5): TypeError "object of
    type 'bool' has no len()" from `len(regions)` in _from_dict; cdt() with the same
    regions says 'regions must be rows of (x, y, marker)' (found by the garbage fuzzer,
    long profile)."""
    d = {
        "vertices": [(0, 0), (1, 0), (0, 1)],
        "segments": [(0, 1), (1, 2), (2, 0)],
        "regions": regions,
    }
    with pytest.raises(InvalidInputError, match="regions"):
        aftmesh.generate(d, 0.5)


def test_constraint_ending_just_inside_edge_crossed_by_split_points(checked):
    """A crack from the centre of a triangle to the midpoint of an edge, computed as
    a + 0.5 (b - a): the rounded end is strictly inside, 6e-18 from the edge.  The
    PSLG is fine (no crossing), but the points that split the edge for the size are
    rounded too, and a piece of the split edge then passes on the other side of the
    end: CrossingSegmentsError 'the polygon, exterior ring ... and constraint line 0'
    with size None or 0.2 (size 0.5, no split point nearby, works).  Found by the
    fuzzer (lines ending on the boundary)."""
    w = np.ones(3)
    theta = np.cumsum(w) / w.sum() * 2 * np.pi
    r = np.array([1.0, 1.0, 0.5])
    ring = np.c_[r * np.cos(theta), r * np.sin(theta)]
    end = ring[1] + 0.5 * (ring[2] - ring[1])
    assert end.tolist() == [-2.220446049250313e-16, -0.43301270189221924]
    poly = Polygon(ring)
    line = LineString([(0.0, 0.0), tuple(end)])
    for size in (None, 0.2):
        mesh = aftmesh.generate(GeometryCollection([poly, line]), size)
        checked(mesh, domain_area=fd.exact_area([poly]))
        assert tuple(end) in set(map(tuple, np.asarray(mesh.points).tolist()))


@pytest.mark.parametrize("t", [0.1, 0.3, 0.6])
def test_constraint_ending_on_edge_far_from_origin(t, checked):
    """A regular 12-gon of radius 1 around (1e7, -1e7) and a crack from near the
    centre to a point of its last edge (computed at the origin, then moved): t=0.1
    'constraint line 0 is not inside the domain' (the tolerance is 1e-9 of the line's
    length, the rounding is an ulp of 1e7, 1.9e-9), t=0.3 / 0.6 CrossingSegmentsError
    between the line and itself or the ring.  The same at the origin meshes.  Found
    by the fuzzer (constraints+offset)."""
    th = 2 * np.pi * np.arange(1, 13) / 12
    ring = np.c_[np.cos(th), np.sin(th)]
    off = np.array([1e7, -1e7])
    a, b = ring[11], ring[0]
    end = a + t * (b - a)
    poly = Polygon(ring + off)
    gc = GeometryCollection(
        [poly, LineString([tuple(np.array([0.1, 0.05]) + off), tuple(end + off)])]
    )
    mesh = aftmesh.generate(gc, 0.2)
    checked(
        mesh,
        domain_area=fd.exact_area([poly]),
        area_rtol=fd.area_tolerance(
            fd.FuzzCase("12-gon", poly, 0.2, {}, [poly]), fd.exact_area([poly])
        ),
    )


@pytest.mark.parametrize("size", [5e-9, 1e-9])
def test_size_below_coordinate_resolution_zero_length_segments(size, checked):
    """A square of side 1e-7 at (4.5e7, 4.5e7), where an ulp is 7.45e-9, with a size
    below the ulp: the boundary is split into pieces whose rounded ends coincide, and
    build_cdt reports 'segments[1] = [4, 5] has zero length', indices of pieces the
    user never gave.  Either mesh it (no split below the coordinates' resolution) or
    say that the size is below what the coordinates can resolve.  Found by the fuzzer
    (extreme+offset)."""
    off = 4.5e7
    sq = box(off, off, off + 1e-7, off + 1e-7)
    try:
        mesh = aftmesh.generate(sq, size)
    except InvalidSizeError as exc:
        assert "segments[" not in str(exc), str(exc)
        return
    checked(
        mesh,
        domain_area=fd.exact_area([sq]),
        area_rtol=fd.area_tolerance(fd.FuzzCase("sq", sq, size, {}, [sq]), fd.exact_area([sq])),
    )


def test_grazing_constraint_pieces_cross_after_discretization(checked):
    """A constraint line 3e-14 rad off a boundary edge, ending on it: no vertex is
    within rounding of another segment, so the noded input is clean, but near the
    shared end the two are only an ulp apart, and the rounded points that split them
    for the size make a piece of one cross a piece of the other (CrossingSegmentsError
    naming the exterior ring and constraint line 0).  generate now discretizes again
    without the split points that close to another segment.  Found by a search for
    grazing lines after the snapping fix."""
    a, b = (0.0, 0.0), (1.0, 0.40525141301762135)
    q, end = (0.09628104213614674, 0.039018028372485636), (0.9628104213614773, 0.3901802837248301)
    poly = Polygon([a, b, (0.5, 1.0)])
    retried = 0
    # which sizes put split points that close depends on the discretization's
    # arithmetic: several sizes, every mesh valid, the repair exercised by some
    for size in (0.02, 0.0052, 0.0055, 0.006):
        mesh = aftmesh.generate(GeometryCollection([poly, LineString([q, end])]), size)
        checked(mesh, domain_area=poly.area)
        retried += "left out split points within rounding of other segments" in mesh.info["cleanup"]
    assert retried  # the test would otherwise not test the repair
    assert {q, end} <= set(map(tuple, np.asarray(mesh.points).tolist()))


def test_constraint_ending_an_ulp_outside_the_boundary(checked):
    """A line from inside to a point computed on an edge that rounds 1.4e-17 outside
    the triangle.  Accepting lines outside by less than 1e-9 of their length (the rule
    before) let far bigger misses through; a buffer of a few ulps (GEOS rounds a buffer
    that thin back onto the polygon) refused this one as 'constraint line 0 is not
    inside the domain'.  Now the outside part's ends and middle must lie within the
    snapping tolerance of the domain.  Found by the fuzzer (constraints)."""
    poly = Polygon(
        [
            (-0.6541631149290893, 0.618118612457408),
            (0.46312640783270953, -0.796575090255773),
            (0.9924533439941903, -2.4308096220511445e-16),
        ]
    )
    end = (-0.4895014690367614, 0.5563067512116672)
    assert not poly.covers(Point(end))
    line = LineString([(0.6264150616181526, 0.0), end])
    mesh = checked(aftmesh.generate(GeometryCollection([poly, line]), 0.35), domain_area=poly.area)
    assert end in set(map(tuple, np.asarray(mesh.points).tolist()))
    # a line that really leaves the domain is still refused
    with pytest.raises(InvalidDomainError, match="constraint line 0"):
        aftmesh.generate(GeometryCollection([poly, LineString([(0.6, 0.0), (-0.5, 0.6)])]), 0.35)


def test_needle_an_ulp_wide_is_not_folded_by_snapping(checked):
    """A spike whose two sides are 1.5 ulps apart at its base: the base vertex is
    within the snapping tolerance of the spike's other side, and splitting that side
    there folded the spike onto it (the doubled piece dropped), losing the corner at
    its tip ('input corner (1.229e-07, 1e-06) is not a mesh vertex').  A vertex joined
    by a segment to an end of the segment is not snapped onto it.  Found by the fuzzer
    (walk+small, split_boundary=False)."""
    ring = [
        (4.314853096290475e-7, 8.461878383307198e-7),
        (7.891278723393342e-7, 8.99208396012279e-7),
        (8.808360498265026e-7, 5.923608809873998e-7),
        (0.0, 3.778579095052713e-7),
        (1.544068913417336e-7, 9.999999999999997e-7),
        (1.229362482212402e-7, 1e-6),
        (9.508644384332265e-7, 9.999999999999997e-7),
    ]
    poly = Polygon(ring)
    assert poly.is_valid
    for split in (False, True):
        mesh = checked(
            aftmesh.generate(poly, 4.5452462393882883e-07, split_boundary=split),
            domain_area=poly.area,
            area_rtol=1e-9,
        )
        assert (1.229362482212402e-7, 1e-6) in set(map(tuple, np.asarray(mesh.points).tolist()))


def test_gap_of_a_few_ulps_far_from_origin_is_not_closed(checked):
    """A random-walk polygon around 7.1e7, where an ulp is 1.5e-8: one vertex is 3
    ulps from an edge it is not joined to.  Snapping within 8 ulps split the edge there
    and closed the gap, bending the boundary by 2.98e-8 ('mesh segment point ... is
    2.98e-08 away from every input edge'); the tolerance is 2 ulps, the rounding of a
    computed point.  Found by the fuzzer (walk+offset)."""
    # the fuzzer's 11-vertex polygon, cut down to the vertices that keep the failure
    ring = [
        [71066330.76221266, -71066330.08782011],
        [71066331.68696073, -71066330.26221254],
        [71066330.92969792, -71066330.26221254],
        [71066330.87220481, -71066330.12522256],
        [71066330.7622126, -71066330.61966804],
        [71066331.46262462, -71066330.76221243],
        [71066330.76221254, -71066330.76221254],
    ]
    poly = Polygon(ring)
    case = fd.FuzzCase(
        "walk+offset",
        np.array(ring),
        None,
        {"smooth": 0, "close_factor": 1.0, "gradation": 2.0},
        [poly],
    )
    fd.verify(case.call(), case, check=checked)


def test_crossing_points_closer_than_a_dot_products_ulp_ordered_exactly(checked):
    """Constraint lines through the origin: a nearly vertical line crosses two nearly
    collinear ones at points 3e-24 apart.  Ordering the cut points along the line by a
    dot product (whose ulp there is 5e-20) put them the wrong way round, the pieces
    crossed again after every round of noding, and generate raised
    CrossingSegmentsError naming constraint lines 1 and 0.  The points are now ordered
    by their coordinates.  Found by the fuzzer (constraints)."""
    poly = Polygon(
        [
            (-0.07021862439709335, 0.2916664958266203),
            (-0.27763851442294835, 0.1136523440542178),
            (-0.2545812678208489, -0.1587084688185517),
            (-0.0010009756642637793, -0.29999833007488486),
            (0.3, -7.347880794884119e-17),
        ]
    )
    lines = [
        LineString(
            [(-0.18362673833910703, 0.0), (0.0, 0.0), (-6.103515625e-05, -0.22903685508655236)]
        ),
        LineString([(-1e-12, 0.01), (0.0, -0.01595904312880836)]),
        LineString([(0.0, 0.0), (0.14995309559710446, 0.0), (0.0, 0.04)]),
        LineString([(-0.20199876099902425, 1e-12), (0.0, 0.0)]),
    ]
    points = [
        Point(-0.02791090438228072, 0.0),
        Point(-0.14331543830913562, 0.0),
        Point(-1e-12, -0.14331543830913562),
        Point(-6.050585107623707e-06, -0.022705061633780332),
        Point(-0.10099938049951213, 5e-13),
    ]
    gc = GeometryCollection([poly, *lines, *points])
    case = fd.FuzzCase("constraints", gc, 0.033075272202751325, {}, [poly], lines, points)
    fd.verify(case.call(), case, check=checked)


def test_needle_an_ulp_wide_keeps_its_tip_when_split(checked):
    """A quadrilateral at the 1e-6 scale with a needle whose sides are 1.5 ulps apart
    at its base.  Split for the size, every point of the slanted side rounds onto the
    other side's line, so the CDT split that side at them, the needle folded, and
    its tip vanished from the mesh ('input corner (2.852e-07, 1e-06) is not a mesh
    vertex'; the area, 1e-29 less, passed).  The kernel now reports segments split at
    vertices, and generate discretizes again without points that near another
    segment.  Found by the fuzzer (walk+small)."""
    # the needle of the fuzzer's 26-vertex polygon, closed by one more vertex
    y = 9.999999999999997e-07
    ring = [
        (3.365591503278354e-08, y),
        (2.8521983272121794e-07, y),
        (6.103515625e-11, 1e-06),
        (1e-7, 5e-7),
    ]
    poly = Polygon(ring)
    assert poly.is_valid
    case = fd.FuzzCase("walk+small", poly, 7.024103985267414e-08, {}, [poly])
    mesh = case.call()
    fd.verify(mesh, case, check=checked)
    assert "left out split points within rounding of other segments" in mesh.info["cleanup"]


def test_dict_segment_through_a_vertex_split_before_discretization(checked):
    """A dict whose segment 0 runs exactly through vertex 4 (the end of segment 4):
    split there before the size splits it, so the rounded split points cannot miss the
    vertex; the pieces keep segment 0's marker."""
    d = {
        "vertices": [[0, 0], [3, 1], [0, 2], [-1, 1], [1.5, 0.5], [1.0, 1.0]],
        "segments": [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5]],
        "segment_markers": [7, 8, 9, 10, 11],
    }
    mesh = checked(aftmesh.generate(d, 0.13), domain_area=4.0)
    assert any("split 1 segments at vertices" in c for c in mesh.info["cleanup"])
    P = np.asarray(mesh.points)
    S = np.asarray(mesh.segments)
    markers = np.asarray(mesh.segment_markers)
    assert [1.5, 0.5] in P.tolist()
    # pieces of segment 0: both ends on the line y = x / 3 (exact for these points)
    on0 = (3 * P[S[:, 0], 1] == P[S[:, 0], 0]) & (3 * P[S[:, 1], 1] == P[S[:, 1], 0])
    assert on0.any() and (markers[on0] == 7).all()


def test_hole_an_ulp_from_the_outer_ring_is_not_snapped_onto_it(checked):
    """A square at 1e7 with a diamond hole whose left corner is 1 ulp (1.86e-9) right
    of the square's left side.  Snapping every vertex within 2 ulps of a segment split
    that side at the hole's corner, closing the gap: with split_boundary=False the
    input edge was no longer a mesh segment.  Only free ends of lines (and lone points)
    are snapped now; a ring's corner stays where it is.  Found by the fuzzer
    (near-hole-to-edge+offset)."""
    hole = [
        (10000000.000000002, -9999999.0),
        (10000000.5, -9999999.05),
        (10000001.0, -9999999.0),
        (10000000.5, -9999998.95),
    ]
    poly = Polygon(
        [(1e7, -1e7), (10000002.0, -1e7), (10000002.0, -9999998.0), (1e7, -9999998.0)], [hole]
    )
    for split in (False, True):
        case = fd.FuzzCase(
            "near-hole-to-edge+offset", poly, 0.385, {"split_boundary": split}, [poly]
        )
        mesh = case.call()
        fd.verify(mesh, case, check=checked)
        assert not any("vertices lying on them" in c for c in mesh.info["cleanup"])


def test_vertex_within_rounding_of_a_piece_keeps_its_side(checked):
    """A needle at the unit scale: its tip at y = 1 - 2**-53, one side flat, the other
    rising to y = 1.  The flat side's far end (0.484, 1 - 2**-53) is 0.2 ulp below the
    rising side; the points splitting the rising side all round to y = 1 - 2**-53 or
    1, so the piece from the tip to the first of them ran exactly through that end,
    the needle folded and its tip was lost ('input corner (0.369, 0.9999999999999999)
    is not a mesh vertex').  Split points are now left out until every vertex that
    near a segment is on the same side of its pieces as of the segment (exact
    orientation).  Found by the fuzzer (walk)."""
    e = 0.9999999999999999
    ring = [
        (0.3691182857977418, e),
        (0.8963404525622876, 1.0),
        (0.5, 0.3),
        (0.48404463285669996, e),
    ]
    poly = Polygon(ring)
    assert poly.is_valid
    case = fd.FuzzCase("walk", poly, 0.053612085881384566, {}, [poly])
    mesh = case.call()
    fd.verify(mesh, case, check=checked)


def test_triangle_one_ulp_squared_far_from_origin_is_meshed(checked):
    """A triangle with corners (0, 0), (0, 2), (1, 1) in ulps of 6.4e7 (area 1 ulp²,
    5.6e-17): no double lies strictly inside it, so the rounded centroid used to
    classify the CDT's piece against the polygon fell outside and generate said 'the
    domain encloses no area'.  A probe that is not strictly inside its triangle (exact
    test) is replaced by the exact rational centroid, classified by an exact even-odd
    test.  Found by the fuzzer (extreme+offset)."""
    x0 = 64206807.7535527
    u = float(np.spacing(x0))
    y0 = -x0 - u
    ring = [(x0, y0), (x0 + u, y0 + u), (x0, y0 + 2 * u)]
    poly = Polygon(ring)
    assert poly.is_valid and poly.area > 0
    for split in (True, False):
        mesh = checked(
            aftmesh.generate(poly, split_boundary=split), domain_area=poly.area, area_rtol=1e-12
        )
        assert len(mesh.triangles) == 1
    # the same through a region list (the region index comes from the same test)
    mesh = checked(aftmesh.generate([poly]), domain_area=poly.area, area_rtol=1e-12)
    assert np.asarray(mesh.regions).tolist() == [0]


def test_region_two_ulps_wide_labelled_and_checked_exactly(checked):
    """Regions side by side, the middle one a strip 2 ulps wide (0.9499999999999998 to
    0.95).  Its triangles' rounded centroids land on the strip's edges, so the oracle's
    point-in-polygon test called them outside their region although they were inside
    (checked exactly).  The oracle now decides such triangles by the exact centroid
    (winding number), and aftmesh classifies such pieces the same way.  Found by the
    fuzzer (touch-regions, with swaps=False)."""
    x = 0.9499999999999998
    regions = [box(0.0, 0.0, x, 0.5), box(x, 0.0, 0.95, 0.5), box(0.95, 0.0, 1.0, 0.5)]
    for opts in ({}, {"swaps": False, "gradation": 1.05}):
        case = fd.FuzzCase("touch-regions", regions, 0.1, opts, regions)
        mesh = case.call()
        fd.verify(mesh, case, check=checked)
        assert (np.asarray(mesh.regions) == 1).sum() > 0
    # the oracle's exact test is not a rubber stamp
    tri = np.array([[0.95, 0.1], [0.96, 0.1], [0.95, 0.11]])
    assert fd._exact_winding_inside(regions[2], tri)
    assert not fd._exact_winding_inside(regions[1], tri)


def test_two_lines_ending_at_one_point_within_rounding_of_an_edge(checked):
    """Two constraint lines ending at the same point, computed on a boundary edge and
    1e-18 off it.  Snapping only vertices with one segment left this end (two
    segments) off the edge; the edge's rounded split points then crossed the lines
    (CrossingSegmentsError naming constraint line 0 and the exterior ring).  Any
    vertex that is on no polygon ring is snapped now.  Found by the fuzzer
    (constraints)."""
    poly = Polygon(
        [
            (0.016514367915341048, 0.04719402136242211),
            (-0.026080074013174682, -0.04265946248451018),
            (0.9276368212657233, -2.272054927868587e-16),
        ]
    )
    end = (0.012254923722489475, 0.03820867297772888)
    lines = [LineString([(0.032557692705115215, 0.0), end]), LineString([(0.0, 0.0), end])]
    points = [
        Point(0.022406308213802344, 0.01910433648886444),
        Point(0.006127461861244738, 0.01910433648886444),
    ]
    case = fd.FuzzCase(
        "constraints",
        GeometryCollection([poly, *lines, *points]),
        0.03831761088376678,
        {},
        [poly],
        lines,
        points,
    )
    mesh = case.call()
    fd.verify(mesh, case, check=checked)
    assert end in set(map(tuple, np.asarray(mesh.points).tolist()))


def test_boundary_edge_lengths_hold_next_to_the_boundary():
    """A boundary edge's length is the size at its ends and holds out to
    BOUNDARY_REACH lengths before growing at the gradation rate.  Growing from the
    vertex itself made the first layer on a graded boundary larger than its edges
    (the naca0012 benchmark's mean radius ratio fell from 0.962 to 0.940).  The field
    is a background triangulation, not a grid, so a tiny edge keeps its own size
    instead of being floored at a fraction of a grid cell."""
    from aftmesh.sizing import BOUNDARY_REACH, make_size_field

    bounds = ((0.0, 0.0), (100.0, 100.0))
    f = make_size_field(1.0, bounds, np.array([[50.1, 50.1]]), np.array([0.5]), gradation=1.3)
    assert f(50.1, 50.1) == pytest.approx(0.5, rel=1e-12)
    assert f(50.1 + 0.9 * BOUNDARY_REACH * 0.5, 50.1) == pytest.approx(0.5, rel=1e-12)
    d = BOUNDARY_REACH * 0.5 + 1.0
    assert f(50.1 + d, 50.1) == pytest.approx(0.5 + 0.3 * 1.0, rel=1e-9)
    tiny = make_size_field(1.0, bounds, np.array([[50.1, 50.1]]), np.array([1e-6]))
    assert tiny(50.1, 50.1) == pytest.approx(1e-6, rel=1e-9)
    assert tiny(52.1, 50.1) == pytest.approx(1e-6 + 0.3 * (2.0 - BOUNDARY_REACH * 1e-6), rel=1e-9)
    assert tiny(90.0, 90.0) == 1.0  # the user's size far away


def test_refine_split_points_stay_within_ulps_of_their_segment(checked):
    """A needle 7.8e-6 wide, 5e7 from the origin: the min-angle pass splits its long
    sides, and a split that would invert a sliver next to it is moved off the
    segment.  The move was eps * |x| (one to two ulps) on top of the point's own
    rounding, 3 ulps in all here; it is one ulp now, and the segment points lie within
    fuzz_domains.SEGMENT_POINT_ULPS of their edge.  Found by the fuzzer
    (sliver-needle+offset)."""
    x0, y0 = 51089502.98058855, -51089502.98058855
    poly = Polygon([(x0, y0), (x0 + 1.0, y0), (x0, -51089502.98058077)])
    case = fd.FuzzCase("sliver-needle", poly, None, {"close_factor": 0.0}, [poly])
    assert fd.run_case(case, check=checked) is not None


def test_greedy_mesh_of_nearly_cocircular_points_is_the_exact_cdt(checked):
    """Points on the unit circle to within rounding (a spiky ring): Triangle's CDT of
    them is not Delaunay at one quad (its incircle test misjudges four points that
    nearly share a circle), so the fuzzer's oracle called aftmesh's mesh wrong.  The
    oracle now settles such a disagreement in rational arithmetic; aftmesh's mesh
    passes the rational empty-circle test on every edge.  Found by the fuzzer
    (sliver-spikes/dict, greedy)."""
    # fmt: off
    V = [[-2.8284271247461907, -2.82842712474619], [-2.5591946833575663, 3.1341095773687676e-16],
         [-0.9999500004166653, -0.00999983333416633], [-0.9999500004166653, 0.009999833334166574],
         [-0.7141423761034396, -0.7000004761807905], [-0.7071067811865475, 0.7071067811865476],
         [-0.7000004761807908, -0.7141423761034393], [-1.8369701987210297e-16, -1.0],
         [6.123233995736766e-17, 1.0], [0.7000004761807905, -0.7141423761034396],
         [0.7000004761807905, 0.7141423761034396], [0.7141423761034392, -0.7000004761807909],
         [0.7141423761034396, 0.7000004761807905], [1.0, 0.0],
         [1.4142206334409066, -1.4142206334409073], [2.6877409528765566, 2.687740952876556]]
    S = [[13, 12], [12, 15], [15, 10], [10, 8], [8, 5], [5, 3], [3, 1], [1, 2], [2, 4], [4, 0],
         [0, 6], [6, 7], [7, 9], [9, 14], [14, 11], [11, 13]]
    # fmt: on
    mesh = aftmesh.generate({"vertices": V, "segments": S}, 0.5, split_boundary=False, greedy=True)
    checked(mesh)
    P = np.asarray(mesh.points)
    seg = {tuple(sorted(s)) for s in np.asarray(mesh.segments).tolist()}
    assert fd._illegal_edges(P, [tuple(t) for t in np.asarray(mesh.triangles).tolist()], seg) == 0
    fd.check_cdt_with_triangle(mesh, np.zeros((0, 2)))  # the oracle accepts it now


def test_line_end_computed_on_an_edge_a_few_ulps_outside_is_snapped_onto_it(checked):
    """A constraint line ending on a polygon edge at a computed point around 5e-6,
    2.36 ulps of the largest coordinate outside the polygon: a + t (b - a) rounds by up
    to about 3.5 ulps, but the snapping tolerance was 2, so the line was refused as
    leaving the domain.  It is snapped onto the edge now.  Found by the fuzzer
    (constraints+small)."""
    poly = Polygon(
        [
            (-1.8202184095666599e-6, 5.514600170561331e-6),
            (-5.032937617938958e-6, 1.8048175266998867e-6),
            (9.837984051326983e-7, -5.7947869726118785e-6),
            (5.762306397102825e-6, -1.4113580169836582e-21),
        ]
    )
    end = (-1.7649031765065016e-7, -4.329252276664988e-6)
    line = LineString([(4.851175334192639e-6, 0.0), end])
    assert not poly.covers(Point(end))  # outside by rounding
    domain = GeometryCollection([poly, line])
    case = fd.FuzzCase("constraints+small", domain, 4e-7, {}, [poly], [line])
    mesh = case.call()
    fd.verify(mesh, case, check=checked)
    assert list(end) in np.asarray(mesh.points).tolist()


def test_constraint_line_of_one_repeated_point_is_kept_as_a_fixed_vertex(checked):
    # fuzz seed 212: a LineString whose vertices all coincide was dropped whole, so
    # its point was not a mesh vertex; it is a fixed point, as a Point would be
    x, y = 48506649.29468939, -48506649.29468939
    tri = Polygon(
        [
            (48506648.41596968, -48506648.81735128),
            (48506649.13490771, -48506649.92717763),
            (48506649.42393836, y),
        ]
    )
    for size in (0.1, lambda px, py: np.full(len(px), 0.1)):
        mesh = checked(
            aftmesh.generate(GeometryCollection([tri, LineString([(x, y), (x, y)])]), size)
        )
        assert ((mesh.points[:, 0] == x) & (mesh.points[:, 1] == y)).any()
    square = GeometryCollection([box(0, 0, 1, 1), LineString([(0.3, 0.4)] * 3)])
    mesh = checked(aftmesh.generate(square, 0.1, greedy=True))
    assert ((mesh.points == [0.3, 0.4]).all(axis=1)).sum() == 1


def test_min_angle_pass_keeps_the_domain_whole_after_noding_crossing_pieces(checked):
    # fuzz seed 222: a line grazing a boundary edge made boundary_cdt node the pieces,
    # which renumbered the vertices lexicographically; the minimum-angle pass then
    # took the first ones for the input vertices, split boundary pieces on the lines
    # of other chains, and gave away 0.8 % of the domain
    y0, y1, x1, x2 = 0.20000000000000004, 0.4000000000000001, 2.068353984205743, 4.136707968411486
    ring = [(0, y0), (0, y1), (0, 0.6000000000000001), (x1, 0.6000000000000001), (x1, y1)]
    ring += [(x2, y1), (6.205061952617228, y1), (6.205061952617228, y0), (x2, y0), (x2, 0)]
    ring += [(x1, 0), (0, 0)]
    lines = [
        LineString(
            [(2.401596330390581, 0.10835915201244486), (1.175997796114257, 0.04727925864079247)]
        ),
        LineString([(x1, 0.2), (5.980936868827133, y0)]),
        LineString([(2.00001, 0.4287575736450084), (0, y1)]),
    ]
    domain = GeometryCollection(
        [Polygon(ring), *lines, Point(2.928216741637258, 0.2549136305127231)]
    )
    mesh = checked(aftmesh.generate(domain, 0.24936012138533437))
    assert any("crossings" in note for note in mesh.info["cleanup"])
    assert abs(mesh.area() - Polygon(ring).area) < 1e-12


def test_segment_split_keeps_the_cdt_between_nearly_collinear_points_of_one_chain(checked):
    """A constraint line 7.5e-15 from another over 3e-6 (coordinates near 1e-6): the
    min-angle pass splits it again and again, and the split points, rounded up to an
    ulp off the line, made slivers whose edge at the new point failed the empty-circle
    test.  Lawson's insertion flips test only the edges facing the new point; the
    edges at it are tested now too.  Found by the fuzzer (constraints+small)."""
    ring = [
        (2.5910246302000074e-6, 1.646572899304797e-6),
        (1.6281484909304535e-6, 4.836130504359068e-6),
        (-2.110703157653677e-6, 6.649209892636615e-6),
        (-2.0591335165924648e-6, 1.8256028736028756e-6),
        (-4.611495708304436e-6, 2.1848301408779364e-6),
        (-6.0041495652948995e-6, -1.5934392953838959e-6),
        (-2.894638863493558e-6, -2.9621640980803116e-6),
        (-9.83702605511402e-7, -3.352038617283015e-6),
        (1.6580736235952286e-7, -5.597045641707061e-6),
        (2.139856919934493e-6, -2.4232861272243103e-6),
        (6.9200968017165956e-6, 1.059762640343866e-20),
    ]
    poly = Polygon(ring)
    lines = [
        LineString([(0, 0), (0, 0), (0, -4.720718738089232e-6)]),
        LineString(
            [(0, 0), (0, 4.0715236794831314e-6), (7.593101415021886e-15, -2.9585940539651016e-6)]
            + [(0, 0)]
        ),
    ]
    points = [
        Point(2.910843968896003e-6, 0),
        Point(0, -2.360359369044616e-6),
        Point(3.1955232542910544e-15, 1.1129296255180303e-6),
    ]
    domain = GeometryCollection([poly, *lines, *points])
    case = fd.FuzzCase("constraints+small", domain, None, {"max_triangles": 2000}, [poly], lines)
    mesh = fd.run_case(case, check=checked)
    assert mesh is not None and mesh.info["min_angle"]["stopped_by"] == "max_triangles"


def test_pieces_of_a_line_a_lone_point_was_snapped_onto_stay_within_the_oracle(checked):
    """Constraint lines from the centre of a heptagon moved by 4e7, and a lone point 6e-8
    above the centre: 2.98023222e-8 from the slanted line, just inside noding's snapping
    tolerance (4 ulps, 2.98023224e-8), so the slanted line is split there and its first
    piece runs 4 ulps off the input edge.  The points the size and the minimum-angle
    pass put on that piece are up to 4.5 ulps off ('mesh segment point ... is 3.33e-08
    away from every input edge'), which the oracle's 4 ulps refused although the
    snapping rule allows it.  Found by the long hypothesis profile (constraints+offset)."""
    poly = Polygon(
        [
            (40000000.766044445, -39999999.35721239),
            (40000000.17364818, -39999999.01519225),
            (39999999.5, -39999999.1339746),
            (39999999.060307376, -39999999.65797985),
            (39999999.060307376, -40000000.34202015),
            (39999999.5, -40000000.8660254),
            (40000001.0, -40000000.0),
        ]
    )
    end = (40000000.46984631, -39999999.18620232)
    lines = [
        LineString([(4e7, -4e7), (4e7, -39999999.5)]),
        LineString([(4e7, -4e7), end]),
        LineString([(4e7, -4e7), end]),
    ]
    points = [
        Point(4e7, -4e7),
        Point(4e7, -39999999.99999994),
        Point(4e7, -39999999.75),
        Point(40000000.234923154, -39999999.59310116),
    ]
    domain = GeometryCollection([poly, *lines, *points])
    case = fd.FuzzCase("constraints+offset", domain, None, {}, [poly], lines, points)
    assert fd.run_case(case, check=checked) is not None


@pytest.mark.parametrize("value", [np.array([]), np.array([1.0]), "yes", 3])
def test_progress_that_is_not_a_flag_or_a_callable_is_refused_by_name(value):
    """The long hypothesis profile's test_garbage_option found progress=np.array([])
    escaping as numpy's "truth value of an empty array is ambiguous" from the
    progress bar's test, instead of an aftmesh error naming the option."""
    with pytest.raises(InvalidOptionError, match="progress must be"):
        aftmesh.generate(box(0, 0, 1, 1), 0.1, progress=value)


def test_oracle_leaves_out_a_hole_seed_that_rounds_onto_the_domain(checked):
    """Fuzz seed 3802 (extreme+offset): a triangular hole one ulp wide at 3.7e7,
    whose representative point rounds onto the domain's boundary.  Given to Triangle
    as a hole seed, it ate the whole domain (one triangle left), and the oracle then
    reported every mesh triangle as missing from Triangle's CDT.  The mesh was right
    (all its triangles are in Triangle's CDT without holes); the seed is left out."""
    outer = [
        (37498683.763412155, -37498683.763412155),
        (37498683.76341492, -37498683.763412155),
        (37498683.76341492, -37498683.763411656),
        (37498683.763412155, -37498683.763411656),
    ]
    hole = [
        (37498683.763413265, -37498683.76341179),
        (37498683.76341326, -37498683.76341179),
        (37498683.763413265, -37498683.7634118),
    ]
    poly = Polygon(outer, [hole])
    for p in fd._void_points([poly]):
        assert fd._strictly_outside([poly], p)
    case = fd.FuzzCase("extreme+offset", poly, 6.358823779174462e-07, {"close_factor": 0.0}, [poly])
    fd.verify(case.call(), case, check=checked)


@pytest.mark.parametrize("close_factor", [0.84, 1.0, 1.9])
def test_large_close_factor_still_meshes_at_the_size(checked, close_factor):
    """From close_factor ~0.83 (1 / LATTICE_PROXIMITY) up, the proximity reach took in
    a lattice's own neighbours: R was refused nearly everywhere and the front closed
    on existing vertices, so the unit square at size 0.02 got 840 triangles (RR 0.84)
    instead of about 5,700.  The reach now stays below R's side."""
    default = aftmesh.generate(SQ, 0.02)
    mesh = checked(aftmesh.generate(SQ, 0.02, close_factor=close_factor), domain_area=1.0)
    assert len(mesh.triangles) > 0.9 * len(default.triangles)
    assert mesh.quality()["radius_ratio_mean"] > 0.99


def test_min_angle_pass_leaves_a_region_one_ulp_wide_without_splitting_its_sides(checked):
    """Fuzz seed 4701 (touch-regions): a region 0.5 long and one ulp wide between two
    others.  Each point the pass put on one side of it encroached the other side's
    piece across the gap, and the two sides split each other until the insertion cap
    (205,515 triangles at size 0.1, 1.9 million in the fuzz case).  Its triangles are
    thinner than the pass's resolution: they are left, and reported unresolved."""
    x = 0.05
    xu = np.nextafter(x, 1.0)
    polys = [box(0, 0, 1, 0.5), box(0, 0.5, x, 1), box(x, 0.5, xu, 1), box(xu, 0.5, 1, 1)]
    mesh = checked(fd.isolated(aftmesh.generate, polys, 0.1, timeout=60.0), domain_area=1.0)
    report = mesh.info["min_angle"]
    assert report["stopped_by"] is None
    assert report["segment_splits"] < 1000
    assert not report["reached"] and report["unresolved_triangles"] > 0
    assert len(mesh.triangles) < 20000
    strip = mesh.points[mesh.triangles[mesh.regions == 2]]
    assert len(strip) > 0 and strip[..., 0].min() == x and strip[..., 0].max() == xu
