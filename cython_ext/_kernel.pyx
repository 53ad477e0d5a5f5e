# cython: language_level=3
"""aftmesh's compiled kernel.

Three layers (see ARCHITECTURE.md): the Python package validates input and builds the
result; this file is the thin ``def`` layer on typed memoryviews; the included parts
hold the ``nogil`` kernels:

* predicates.pxi     exact orient2d / incircle: filter, adaptive stage, exact fallback
* triangulation.pxi  half-edge storage, flips, point location, point insertion
* cdt.pxi            constrained edges (Cline & Renka), with segment provenance
* domain.pxi         flood fills: carving, regions, the pieces segments separate
* export.pxi         the domain's triangles as compact arrays
* sizing.pxi         the compiled size field (background triangulation), gradation limit
* ordering.pxi       Hilbert curve keys for the insertion order
* front.pxi          Basic_aft's subtasks on the CDT and the compiled loop
* smoothing.pxi      smoothing after the front closes, with Delaunay flips
* optimize.pxi       one smoothing move: the best candidate place of a vertex
* refine.pxi         the minimum-angle pass (Delaunay refinement)
* inputs.pxi         ring clean-up, coordinate and segment checks of the input
* discretize.pxi     input segments split by the integral of 1/size
* background.pxi     a size field's background triangulation and gradation, at once
* pipeline.pxi       generate's common case, from the size field to the mesh, in one call

and the declarations they share: halfedge.pxd (the triangulation struct, its
convention, the enums and one-line helpers), sizing.pxd (SizeField) and aft.pxd
(the state of the Basic_aft loop).

Every kernel routine returns a status code (0 or a count on success, a negative ERR_*
from halfedge.pxd on failure); the methods here turn codes into exceptions.
"""
from halfedge cimport *
from aft cimport Aft
from cpython.buffer cimport PyBUF_C_CONTIGUOUS, PyBuffer_Release, PyObject_GetBuffer
from cpython.ref cimport Py_XDECREF, PyObject
from libc.stdlib cimport malloc, free, realloc
from cython.view cimport array as cvarray

import math
import threading
from time import perf_counter

import numpy as np

cdef extern from *:
    # set by setup.py: 1 in the debug build (AFTMESH_DEBUG=1), else 0
    int AFTMESH_DEBUG_BUILD "AFTMESH_DEBUG"

DEBUG = bool(AFTMESH_DEBUG_BUILD)
# Python runs signal handlers in its main thread only (see Aft.signals_here)
_MAIN_THREAD = threading.main_thread().ident

include "predicates.pxi"
include "triangulation.pxi"
include "cdt.pxi"
include "domain.pxi"
include "export.pxi"
include "sizing.pxi"
include "ordering.pxi"
include "front.pxi"
include "lattice.pxi"
include "scaffold.pxi"
include "smoothing.pxi"
include "optimize.pxi"
include "valence.pxi"
include "refine.pxi"
include "chains.pxi"
include "sliding.pxi"
include "inputs.pxi"
include "nearby.pxi"
include "crossings.pxi"
include "simple_rings.pxi"
include "discretize.pxi"
include "background.pxi"
include "resolve.pxi"


class KernelError(RuntimeError):
    """An internal invariant of the kernel broke (a bug in aftmesh, not in the input)."""


class CrossingError(ValueError):
    """A constrained edge would cross another one; ``edge`` and ``blocker`` give the
    vertex pairs (kernel vertex indices) of the new edge and of the edge it hit, and
    ``blocker_segment`` the id of the input segment the hit edge is a piece of (-1:
    not an input segment)."""

    def __init__(self, msg, edge, blocker, blocker_segment=-1):
        super().__init__(msg)
        self.edge = edge
        self.blocker = blocker
        self.blocker_segment = blocker_segment


class CollinearError(ValueError):
    """All points lie on one line, so they have no triangulation."""


cdef int _reraise_pending(Aft* A) except -1:
    """Raise again the exception a signal handler raised inside a nogil loop."""
    cdef PyObject* t = A.exc_type
    cdef PyObject* v = A.exc_value
    cdef PyObject* tb = A.exc_tb
    A.exc_type = NULL
    A.exc_value = NULL
    A.exc_tb = NULL
    if t == NULL:
        return 0
    PyErr_Restore(t, v, tb)     # steals the three references
    return -1


cdef object _raise_for(Tri* T, int code):
    if code >= 0:
        return
    if code == ERR_NOMEM:
        raise MemoryError("aftmesh kernel: out of memory")
    if code == ERR_CROSSING:
        raise CrossingError(
            f"edge ({T.err_a}, {T.err_b}) crosses constrained edge ({T.err_u}, {T.err_v})",
            (T.err_a, T.err_b), (T.err_u, T.err_v), T.err_seg)
    if code == ERR_COLLINEAR:
        raise CollinearError("all input points are collinear: there is no triangle")
    if code == ERR_INTERRUPTED:
        raise KeyboardInterrupt()
    raise KernelError(f"aftmesh kernel: internal invariant broken (code {code})")


# Raw data pointers of arrays known to be C-contiguous and of that dtype (the
# kernel's own outputs, or arrays made so by the caller); NULL when empty, where the
# routines never read them.
cdef void* _buffer_of(object arr) except? NULL:
    cdef Py_buffer view
    cdef void* out
    PyObject_GetBuffer(arr, &view, PyBUF_C_CONTIGUOUS)
    out = view.buf if view.len else NULL
    PyBuffer_Release(&view)  # arr keeps the memory
    return out


cdef inline int32_t* _i32v(object arr) except? NULL:
    return <int32_t*> _buffer_of(arr)


cdef inline uint8_t* _u8v(object arr) except? NULL:
    return <uint8_t*> _buffer_of(arr)


cdef inline double* _f64v(object arr) except? NULL:
    return <double*> _buffer_of(arr)


# The named enums of halfedge.pxd, for src/aftmesh/_states.py (tests/test_states.py
# checks that the IntEnums there hold these values).
TRIANGLE_STATE_VALUES = dict(FREE=T_FREE, EXTERIOR=T_EXTERIOR, UNMESHED=T_UNMESHED,
                             MESHED=T_MESHED)
ORDER_VALUES = dict(SHORTEST=ORDER_SHORTEST, LONGEST=ORDER_LONGEST, OLDEST=ORDER_OLDEST)
LOCATION_VALUES = dict(IN_TRIANGLE=LOC_IN_TRIANGLE, ON_EDGE=LOC_ON_EDGE,
                       ON_VERTEX=LOC_ON_VERTEX, OUTSIDE=LOC_OUTSIDE)
EDGE_FLAG_VALUES = dict(SEGMENT=E_SEGMENT, FIXED=E_FIXED)

# Kernel routines on fewer items than this run with the GIL held: they take a few
# microseconds, less than a GIL hand-off costs when another thread waits for it (it is
# woken for nothing, or takes the GIL in the middle of this thread's Python work).
cdef enum:
    NOGIL_MIN_ITEMS = 1024

# Coordinates (besides 0) for which orient2d and incircle are exact (predicates.pxi).
EXACT_COORDINATE_RANGE = (EXACT_MIN_COORDINATE, EXACT_MAX_COORDINATE)


cdef void _add_vertices(Tri* T, const double* xy, Py_ssize_t n) noexcept nogil:
    """Append the n points as vertices (room for them was reserved by tri_init)."""
    cdef Py_ssize_t i
    for i in range(n):
        add_vertex(T, xy[2 * i], xy[2 * i + 1])


cdef inline void _release(void** array) noexcept:
    """Free a kernel array and leave NULL in its place, for tri_free and _empty later."""
    free(array[0])
    array[0] = NULL


cdef object _adopt_i32(int32_t** array, Py_ssize_t rows, Py_ssize_t cols):
    """A numpy int32 array of `rows` rows of `cols` (cols 1: one dimension) on the
    kernel's own block, its first rows * cols entries: the block is shrunk to that,
    freed with the last array on it, and NULL is left in its place.  The output then
    reuses memory the kernel has already written instead of faulting in fresh pages
    (a tenth of the time of a 9-million-triangle run went to zeroing those)."""
    cdef void* q
    cdef cvarray a
    cdef object shape = [rows] if cols == 1 else [rows, cols]
    if rows == 0:
        _release(<void**> array)
        return np.empty(tuple(shape), dtype=np.int32)
    q = realloc(array[0], rows * cols * sizeof(int32_t))
    if q == NULL:
        q = array[0]                # keep the larger block: only memory is lost
    array[0] = NULL
    a = cvarray(shape=tuple(shape), itemsize=sizeof(int32_t), format="i", mode="c",
                allocate_buffer=False)
    a.data = <char*> q
    a.callback_free_data = free
    return np.asarray(a)


cdef int _insert_pslg(Tri* T, const int64_t* rounds, const int32_t* seg, int m,
                      bint from_hull, int32_t* merged, int* n_merged, int* through,
                      int* failed) noexcept nogil:
    """Triangulation.insert_pslg's work on T's T.nv vertices (the segments' indices
    checked by the caller): merged[i] the vertex input vertex i became; counts the
    merged vertices, the segments split at vertices on them, and the segment that
    failed (-1: none).  Returns the first error or >= 0."""
    cdef int n = T.nv, i, res = 0
    failed[0] = -1
    for i in range(n):
        merged[i] = i
    res = brio_insert(T, T.xy, n, rounds, merged) if n else 0
    for i in range(n):
        n_merged[0] += merged[i] != i
    for i in range(m):
        if res < 0:
            break
        res = insert_segment(T, merged[seg[2 * i]], merged[seg[2 * i + 1]], E_SEGMENT, i)
        if res < 0:
            failed[0] = i
        else:
            through[0] += res
    if res >= 0:
        res = carve_domain(T, NULL, 0, from_hull)
    return res


cdef void _refine_setup(Refine* R, double min_angle, int n_corners, bint split_segments):
    """A Refine for the minimum-angle pass at `min_angle` degrees (see refine.pxi)."""
    cdef double c = math.cos(math.radians(min_angle))
    memset(R, 0, sizeof(Refine))
    R.c2_bad = c * c * (1.0 - REFINE_ANGLE_MARGIN)
    R.c2_small = c * c * (1.0 + REFINE_ANGLE_MARGIN)
    R.offcentre = OFFCENTRE_FACTOR * 0.5 * math.sqrt((1.0 + c) / (1.0 - c))
    R.split_segments = split_segments
    R.n_corner = n_corners


cdef dict _refine_counts(Refine* R):
    """Triangulation.refine's counts of a finished pass."""
    return dict(inserted=R.inserted, segment_splits=R.splits, interior=R.interior,
                dropped=R.dropped, excepted_triangles=R.excepted,
                unresolved_triangles=R.unresolved, insertion_cap=R.max_insert,
                stopped_by={STOP_NONE: None, STOP_MAX_TRIANGLES: "max_triangles",
                            STOP_CAP: "insertion_cap"}[R.stop])


cdef class Triangulation:
    """A triangulation of a point set with constrained edges, held in flat arrays.

    Vertex k of the kernel is row k of the points given to the constructor; points
    added later (Basic_aft's new vertices) get the following indices.
    """
    cdef Tri T
    cdef Aft A
    cdef int vis_edge           # the (edge, R) that check_visible last answered for
    cdef double vis_R[2]
    cdef object progress        # keeps alive the callable A.progress points to

    def __cinit__(self, const double[:, ::1] points, int nt_hint=0):
        cdef int n = points.shape[0]
        if points.shape[1] != 2:
            raise ValueError("points must have shape (n, 2)")
        if tri_init(&self.T, n + 16, max(nt_hint, 2 * n + 16)) or aft_init(&self.A):
            raise MemoryError()
        self.vis_edge = NONE
        if n >= NOGIL_MIN_ITEMS:
            with nogil:
                _add_vertices(&self.T, &points[0, 0], n)
        elif n:
            _add_vertices(&self.T, &points[0, 0], n)

    def __dealloc__(self):
        # an exception kept from a signal handler but never raised: drop it
        Py_XDECREF(self.A.exc_type)
        Py_XDECREF(self.A.exc_value)
        Py_XDECREF(self.A.exc_tb)
        aft_free(&self.A)
        tri_free(&self.T)

    @property
    def n_vertices(self):
        return self.T.nv

    def insert_points(self, const int32_t[::1] order):
        """Insert the vertices in `order` (a spatially coherent order makes the walks
        short).  Returns an int32 array `merged`: merged[v] == v for inserted vertices,
        or the index of the earlier vertex at exactly the same place."""
        cdef int n = self.T.nv, res = 0, i
        cdef int m = order.shape[0]
        merged_arr = np.arange(n, dtype=np.int32)
        if m == 0:
            return merged_arr
        for i in range(m):
            if not 0 <= order[i] < n:
                raise ValueError(f"order holds a vertex outside 0..{n - 1}")
        cdef int32_t* merged = _i32v(merged_arr)
        with nogil:
            res = insert_points(&self.T, &order[0], m, merged)
        _raise_for(&self.T, res)
        return merged_arr

    def insert_pslg(self, const int64_t[::1] rounds, const int32_t[:, ::1] segments,
                    bint from_hull):
        """insert_points in BRIO order (rounds: _order.round_keys of the vertices),
        then insert_segments on the segments (rows of input vertex indices, mapped to
        the vertices they were merged into), then carve from the hull (or only the
        ghosts), in one call without the GIL.  Returns (merged, number merged, number
        of segments split at vertices on them); raises as those methods do."""
        cdef Tri* T = &self.T
        cdef int n = T.nv, m = segments.shape[0], i, k, res = 0, failed = -1
        cdef int through = 0, n_merged = 0
        if T.nt:
            raise ValueError("insert_pslg starts the triangulation: it already has triangles")
        if rounds.shape[0] != n or segments.shape[1] != 2:
            raise ValueError("one round key per vertex and segments of two columns needed")
        for i in range(m):
            for k in range(2):
                if not 0 <= segments[i, k] < n:
                    raise ValueError(f"segments[{i}] = {list(segments[i])} refers to a "
                                     f"vertex outside 0..{n - 1}")
        merged_arr = np.empty(n, dtype=np.int32)
        cdef int32_t* merged = _i32v(merged_arr)
        with nogil:
            res = _insert_pslg(T, &rounds[0] if n else NULL, &segments[0, 0] if m else NULL,
                               m, from_hull, merged, &n_merged, &through, &failed)
        try:
            _raise_for(T, res)
        except CrossingError as err:
            err.index = failed
            raise
        return merged_arr, n_merged, through

    def add_points(self, const double[:, ::1] points, const int32_t[::1] near=None):
        """Append points as new vertices and insert them into the triangulation (which
        must have been started by insert_points).  near (optional, one vertex per
        point) starts each point's walk at a triangle of that vertex: a point close to
        it is then found in a few steps (where it lands does not depend on the walk).
        Returns their vertex indices, or the earlier vertex at exactly the same
        place."""
        cdef int m = points.shape[0], i, res = 0
        cdef bint hinted = near is not None
        if hinted and near.shape[0] != m:
            raise ValueError(f"near needs one vertex per point ({m}), got {near.shape[0]}")
        out_arr = np.empty(m, dtype=np.int32)
        cdef int32_t[::1] out = out_arr
        with nogil:
            for i in range(m):
                res = insert_point_near(&self.T, points[i, 0], points[i, 1],
                                        near[i] if hinted else NONE)
                if res < 0:
                    break
                out[i] = res
        _raise_for(&self.T, min(res, 0))
        return out_arr

    def finite_triangles(self):
        """Every live finite triangle, whatever its state: (tv (t, 3) of kernel vertex
        indices, counter-clockwise; nb (t, 3), the triangle across the edge opposite
        vertex k, -1 at the hull)."""
        return _finite_arrays(&self.T)

    def edge_keys(self, int64_t n):
        """The edges of finite_triangles' triangles, each once, as the sorted int64
        keys a n + b (a < b; n must exceed every vertex index)."""
        cdef int64_t m
        if n < self.T.nv:
            raise ValueError(f"edge keys need n >= {self.T.nv} (the vertex count), got {n}")
        keys_arr = np.empty(3 * max(self.T.nt, 1), dtype=np.int64)
        ring_arr = np.empty(max(self.T.nv, 1), dtype=np.int64)
        cdef int64_t[::1] keys = keys_arr, ring = ring_arr
        with nogil:
            m = finite_edge_keys(&self.T, n, &keys[0], &ring[0])
        return keys_arr[:m]

    def insert_segments(self, const int32_t[:, ::1] segments, int flag=E_SEGMENT,
                        int first_id=0):
        """Insert constrained edges (pairs of vertex indices).  With flag E_SEGMENT,
        row i is input segment first_id + i: every piece of it carries that id
        (arrays()["segment_ids"]); other flags carry -1.  Returns how many of them ran
        exactly through other vertices and were split there.  On a crossing, raises
        CrossingError with `index` set to the row that failed."""
        cdef int i, k, res = 0, failed = -1, through = 0
        cdef bint is_input = (flag & E_SEGMENT) != 0
        cdef int m = segments.shape[0]
        cdef Tri* T = &self.T
        for i in range(m):
            for k in range(2):
                if not 0 <= segments[i, k] < T.nv or T.vhe[segments[i, k]] < 0:
                    raise ValueError(f"segments[{i}] = {list(segments[i])} refers to a vertex "
                                     "that is not in the triangulation")
        with nogil:
            for i in range(m):
                res = insert_segment(T, segments[i, 0], segments[i, 1], <uint8_t> flag,
                                     first_id + i if is_input else -1)
                if res < 0:
                    failed = i
                    break
                through += res
        try:
            _raise_for(T, res)
        except CrossingError as err:
            err.index = failed
            raise
        return through

    def carve(self, const double[:, ::1] holes, bint from_hull=True):
        """Mark as exterior the triangles reachable without crossing a segment from the
        ghost triangles (if `from_hull`) and from each hole point."""
        cdef int res, n = holes.shape[0]
        with nogil:
            res = carve_domain(&self.T, &holes[0, 0] if n else NULL, n, from_hull)
        _raise_for(&self.T, res)

    def assign_regions(self, const double[:, ::1] seeds, const int32_t[::1] ids):
        """Give region id ids[k] to every domain triangle reachable from seeds[k]
        without crossing a segment (later seeds win)."""
        cdef int res, n = seeds.shape[0]
        if ids.shape[0] != n:
            raise ValueError("seeds and ids differ in length")
        with nogil:
            res = assign_regions(&self.T, &seeds[0, 0] if n else NULL,
                                 &ids[0] if n else NULL, n)
        _raise_for(&self.T, res)

    def components(self):
        """Split the domain triangles into the pieces that segments separate.

        Returns (comp, probe, corners): comp[t] is the piece of triangle slot t (-1 if
        t is not a domain triangle), probe[c] = (x, y) a point well inside piece c: the
        centroid of its triangle with the largest area, so that classifying probe[c]
        against the user's polygons classifies the whole piece, and corners[c] (3, 2)
        that triangle's corners (the rounded centroid of a triangle an ulp or two wide
        may not be inside it: the caller checks)."""
        cdef Tri* T = &self.T
        cdef int nc, c, k
        cdef double* q
        comp_arr = np.full(T.nt, -1, dtype=np.int32)
        best_arr = np.zeros(max(T.nt, 1), dtype=np.int32)
        cdef int32_t[::1] comp = comp_arr
        cdef int32_t[::1] best = best_arr
        if T.nt >= NOGIL_MIN_ITEMS:
            with nogil:
                nc = domain_components(T, &comp[0] if T.nt else NULL, &best[0])
        else:
            nc = domain_components(T, &comp[0] if T.nt else NULL, &best[0])
        _raise_for(T, nc)
        corners_arr = np.empty((nc, 3, 2), dtype=np.float64)
        probe_arr = np.empty((nc, 2), dtype=np.float64)
        cdef double[:, :, ::1] corners = corners_arr
        cdef double[:, ::1] probe = probe_arr
        for c in range(nc):
            for k in range(3):
                q = P(T, T.tv[3 * best[c] + k])
                corners[c, k, 0] = q[0]
                corners[c, k, 1] = q[1]
            probe[c, 0] = (corners[c, 0, 0] + corners[c, 1, 0] + corners[c, 2, 0]) / 3.0
            probe[c, 1] = (corners[c, 0, 1] + corners[c, 1, 1] + corners[c, 2, 1]) / 3.0
        return comp_arr, probe_arr, corners_arr

    def set_regions(self, const int32_t[::1] comp, const int32_t[::1] region_of_comp):
        """Give every domain triangle the region of its piece (see components());
        pieces whose region is -1 (holes, outside) become exterior."""
        cdef int n = comp.shape[0]
        if n and region_of_comp.shape[0] <= np.asarray(comp).max():
            raise ValueError("region_of_comp has no entry for some piece")
        set_regions(&self.T, &comp[0] if n else NULL, n,
                    &region_of_comp[0] if region_of_comp.shape[0] else NULL)

    def state_at(self, double x, double y):
        """State (T_EXTERIOR, T_UNMESHED, T_MESHED: aftmesh._states.TriangleState) of
        the triangle holding (x, y); T_EXTERIOR outside the hull; None when the point
        lies on a segment or on a vertex that a segment ends at (it then belongs to no
        single region)."""
        cdef double p[2]
        cdef int state
        p[0] = x
        p[1] = y
        state = seed_state(&self.T, p)
        _raise_for(&self.T, state)
        return None if state == SEED_ON_SEGMENT else state

    def state_counts(self):
        """Number of triangles in each state: (exterior incl. ghosts, unmeshed, meshed)."""
        cdef int t, ext = 0, unm = 0, msh = 0
        for t in range(self.T.nt):
            if self.T.tstate[t] == T_EXTERIOR:
                ext += 1
            elif self.T.tstate[t] == T_UNMESHED:
                unm += 1
            elif self.T.tstate[t] == T_MESHED:
                msh += 1
        return ext, unm, msh

    def validate(self):
        """Check the half-edge structure itself (twins, flags, orientation, vertex
        half-edges).  Returns a list of problems (empty when all is well)."""
        problems = []
        cdef Tri* T = &self.T
        cdef int t, k, e, f, v
        for t in range(T.nt):
            if T.tstate[t] == T_FREE:
                continue
            for k in range(3):
                e = 3 * t + k
                f = T.twin[e]
                if f < 0 or f >= 3 * T.nt:
                    problems.append(f"half-edge {e}: twin {f} out of range")
                    continue
                if T.twin[f] != e:
                    problems.append(f"half-edge {e}: twin of twin is {T.twin[f]}")
                if T.tv[f] != T.tv[nxt(e)] or T.tv[nxt(f)] != T.tv[e]:
                    problems.append(f"half-edge {e}: twin {f} has other end points")
                if T.eflag[f] != T.eflag[e]:
                    problems.append(f"half-edge {e}: flags differ from twin")
                if T.eseg[f] != T.eseg[e]:
                    problems.append(f"half-edge {e}: segment id differs from twin")
                if (T.eseg[e] >= 0) != ((T.eflag[e] & E_SEGMENT) != 0):
                    problems.append(f"half-edge {e}: segment id {T.eseg[e]} with flags "
                                    f"{T.eflag[e]}")
            if not is_ghost(T, t):
                if orient2d(P(T, T.tv[3 * t]), P(T, T.tv[3 * t + 1]), P(T, T.tv[3 * t + 2])) <= 0:
                    problems.append(f"triangle {t}: not counter-clockwise")
        for v in range(T.nv):
            e = T.vhe[v]
            if e >= 0 and (T.tstate[e // 3] == T_FREE or T.tv[e] != v):
                problems.append(f"vertex {v}: stale half-edge {e}")
        return problems

    def arrays(self, bint include_exterior=False, bint release=False):
        """The domain's triangles as compact numpy arrays.

        Returns a dict: points (n, 2), triangles (t, 3) counter-clockwise, neighbors
        (t, 3) with neighbors[i, k] across the edge opposite vertex k (-1: none),
        segments (s, 2) (constrained edges of the domain, each once), segment_ids (s,)
        the input segment each is a piece of (see insert_segments; -1: none), regions
        (t,), vertex_map (nv,) kernel vertex -> output vertex (-1: not in the output).
        The scratch arrays are C buffers: numpy's cost per array would exceed the
        work on a small mesh.

        With `release`, each kernel array is freed once the outputs no longer need
        it, so the peak memory is not the kernel's and the outputs' together, and
        triangles, regions and neighbors are written in place over the kernel's own
        blocks (T.tv, T.tregion, T.twin), which the arrays then own; the
        triangulation is empty afterwards."""
        cdef Tri* T = &self.T
        cdef int ntri, nvo, ns, t
        cdef int32_t* vmap
        cdef uint8_t* keep = <uint8_t*> malloc(max(T.nt, 1) * sizeof(uint8_t))
        cdef int32_t* tri_index = <int32_t*> malloc(max(T.nt, 1) * sizeof(int32_t))
        if keep == NULL or tri_index == NULL:
            free(keep)
            free(tri_index)
            raise MemoryError()
        try:
            vmap_arr = np.empty(T.nv, dtype=np.int32)
            vmap = _i32v(vmap_arr)
            for t in range(T.nv):
                vmap[t] = -1
            for t in range(T.nt):
                tri_index[t] = -1
            ntri = mark_output(T, include_exterior, keep)
            # the segments first, in the kernel's numbering: with `release` the
            # triangles are then numbered in place, over T.tv
            ns = output_segments(T, keep, NULL, NULL)
            seg_arr = np.empty((ns, 2), dtype=np.int32)
            seg_ids = np.empty(ns, dtype=np.int32)
            if ns:
                output_segments(T, keep, _i32v(seg_arr), _i32v(seg_ids))
            if release:             # each array freed after the last step to read it
                nvo = number_output(T, keep, tri_index, vmap, T.tv, T.tregion)
                tris_arr = _adopt_i32(&T.tv, ntri, 3)
                regions_arr = _adopt_i32(&T.tregion, ntri, 1)
                _release(<void**> &T.tstate)
                _release(<void**> &T.vhe)
                _release(<void**> &T.eflag)
                _release(<void**> &T.eseg)
            else:
                tris_arr = np.empty((ntri, 3), dtype=np.int32)
                regions_arr = np.empty(ntri, dtype=np.int32)
                nvo = number_output(T, keep, tri_index, vmap, _i32v(tris_arr),
                                    _i32v(regions_arr))
            if ns:
                renumber(_i32v(seg_arr), 2 * ns, vmap)
            points_arr = np.empty((nvo, 2), dtype=np.float64)
            output_points(T, vmap, _f64v(points_arr))
            if release:
                _release(<void**> &T.xy)
                output_neighbors(T, keep, tri_index, T.twin)
                nbr_arr = _adopt_i32(&T.twin, ntri, 3)
            else:
                nbr_arr = np.empty((ntri, 3), dtype=np.int32)
                output_neighbors(T, keep, tri_index, _i32v(nbr_arr))
        finally:
            free(keep)
            free(tri_index)
            if release:
                self._empty()
        return dict(points=points_arr, triangles=tris_arr, neighbors=nbr_arr,
                    segments=seg_arr, segment_ids=seg_ids,
                    regions=regions_arr, vertex_map=vmap_arr)

    cdef void _empty(self):
        """Free the triangulation and leave an empty one (no vertices, no triangles)
        in its place, so that any later call finds consistent state."""
        tri_free(&self.T)
        if tri_init(&self.T, 0, 0):
            tri_free(&self.T)       # all NULL, all counts 0: still consistent

    def raw(self):
        """Copies of the raw kernel arrays (for tests and debugging)."""
        cdef Tri* T = &self.T
        n3 = 3 * T.nt
        return dict(
            xy=np.asarray(<double[:2 * T.nv]> T.xy).reshape(-1, 2).copy(),
            tv=np.asarray(<int32_t[:n3]> T.tv).copy(),
            twin=np.asarray(<int32_t[:n3]> T.twin).copy(),
            eflag=np.asarray(<uint8_t[:n3]> T.eflag).copy(),
            eseg=np.asarray(<int32_t[:n3]> T.eseg).copy(),
            tstate=np.asarray(<uint8_t[:T.nt]> T.tstate).copy(),
            tregion=np.asarray(<int32_t[:T.nt]> T.tregion).copy(),
            vhe=np.asarray(<int32_t[:T.nv]> T.vhe).copy())

    # ------------------------------------------------------------ Basic_aft

    cdef void adopt_size_field(self, SizeField* S) noexcept:
        """Take S's arrays as the size field (S is left empty), its walks starting
        afresh as set_size_field's do."""
        size_field_free(&self.A.size)
        self.A.size = S[0]
        memset(S, 0, sizeof(SizeField))
        free(self.A.size.vhint)     # S's look-ups' vertex hints, if it had any
        self.A.size.hint = 0
        self.A.size.vhint = NULL
        self.A.size.vhint_cap = 0

    def set_size_field(self, double constant, const double[:, ::1] xy,
                       const double[::1] w, const double[::1] g, const int32_t[:, ::1] tv,
                       const int32_t[:, ::1] nb, double rate, double reach):
        """The size field (sizing.pxi): a constant when tv has no rows, else sizes w
        (interpolated) and g (cones of slope rate, flat to reach g) at the background
        vertices xy, on the triangles tv with neighbours nb.  The arrays are copied;
        the values must be positive (inf in w: no user size), as the Python layer
        checks."""
        cdef SizeField view
        _borrow_field(&view, constant, xy, w, g, tv, nb, rate, reach)
        if size_field_set(&self.A.size, constant, view.nv, view.nt, view.xy, view.w, view.g,
                          view.tv, view.nb, rate, reach):
            raise MemoryError()

    def size_at(self, double x, double y):
        return size_at(&self.A.size, x, y)

    def set_options(self, *, int order=ORDER_SHORTEST, long long max_triangles=-1,
                    double min_area=0.0, double close_factor=0.5, bint swaps=True,
                    bint greedy=False, bint scaffold=False):
        """scaffold: the compiled loop plants the scaffold first (scaffold.pxi)."""
        self.A.order = order
        self.A.max_triangles = max_triangles
        self.A.min_area = min_area
        self.A.close_factor = close_factor
        self.A.swaps = swaps
        self.A.greedy = greedy
        self.A.scaffold_on = scaffold

    def convert_to_frontal_edge_set(self):
        _raise_for(&self.T, convert_to_frontal_edge_set(&self.A, &self.T))

    def get_next_edge(self):
        """The built-in Get_next_edge (queue order); -1 when the front is empty."""
        return get_next_edge(&self.A, &self.T)

    def front_edges(self):
        """All current front half-edges (int32 array)."""
        cdef int t, k
        out = []
        for t in range(self.T.nt):
            if self.T.tstate[t] == T_UNMESHED:
                for k in range(3):
                    if blocking(&self.T, 3 * t + k):
                        out.append(3 * t + k)
        return np.array(out, dtype=np.int32)

    def push_front_edge(self, int e):
        """Queue a front edge (for Python Get_next_edge strategies that
        manage their own order this is not needed)."""
        self._check_edge(e)
        _raise_for(&self.T, queue_push(&self.A, &self.T, e))

    def edge(self, int e):
        """(origin, destination) vertex indices of half-edge e."""
        self._check_edge(e)
        return self.T.tv[e], self.T.tv[nxt(e)]

    def is_front(self, int e):
        self._check_edge(e)
        return bool(is_front(&self.T, e))

    def vertex(self, int v):
        if not 0 <= v < self.T.nv:
            raise IndexError(v)
        return self.T.xy[2 * v], self.T.xy[2 * v + 1]

    def compute_new_candidate(self, int e):
        """The built-in Compute_new_candidate: (x, y, h) of R and the local size."""
        cdef double R[2]
        cdef double h
        self._check_front(e)
        compute_new_candidate(&self.A, &self.T, e, R, &h)
        return R[0], R[1], h

    def candidate_off_lattice(self):
        """(x, y) of the point the last compute_new_candidate computed before it moved
        R onto the lattice of converging rows (cython_ext/lattice.pxi); None when it
        did not move R."""
        if not self.A.lat_moved:
            return None
        return self.A.lat_plain[0], self.A.lat_plain[1]

    def compute_existing_candidate(self, int e):
        self._check_front(e)
        return compute_existing_candidate(&self.T, e)

    def new_is_preferred(self, int e, double rx, double ry, int S, double h):
        cdef double R[2]
        R[0] = rx
        R[1] = ry
        self._check_front(e)
        return bool(new_is_preferred(&self.A, &self.T, e, R, S, h))

    def mesh_size_constraint(self, int e, double rx, double ry):
        cdef double R[2]
        R[0] = rx
        R[1] = ry
        self._check_front(e)
        return bool(mesh_size_constraint(&self.A, &self.T, e, R))

    def check_visible(self, int e, double rx, double ry):
        """Figure 8.  Returns (visible, left, right): the crossed edges as (origin,
        destination) pairs."""
        cdef double R[2]
        R[0] = rx
        R[1] = ry
        self._check_front(e)
        res = check_visible(&self.A, &self.T, e, R)
        _raise_for(&self.T, res)
        left = [(self.T.tv[x], self.T.tv[nxt(x)]) for x in self.A.left[:self.A.nleft]]
        right = [(self.T.tv[x], self.T.tv[nxt(x)]) for x in self.A.right[:self.A.nright]]
        self.vis_edge = e if res == 1 else NONE
        self.vis_R[0] = rx
        self.vis_R[1] = ry
        return res == 1, left, right

    def is_crowded(self, int e, double rx, double ry, double h):
        """New_is_preferred's proximity rule, for the R that check_visible(e, rx, ry)
        just found visible."""
        cdef double R[2]
        R[0] = rx
        R[1] = ry
        if self.vis_edge != e or self.vis_R[0] != rx or self.vis_R[1] != ry:
            raise ValueError("is_crowded needs a check_visible of the same edge and R "
                             "that answered visible, just before")
        res = is_crowded(&self.A, &self.T, R, h)
        _raise_for(&self.T, res)
        return res == 1

    def update_internal(self, int e, double rx, double ry):
        """Insert R and the edges F, G; returns T(E, R) for add_triangle.  Must follow a
        check_visible(e, rx, ry) that answered visible."""
        cdef double R[2]
        R[0] = rx
        R[1] = ry
        self._check_front(e)
        if self.vis_edge != e or self.vis_R[0] != rx or self.vis_R[1] != ry:
            raise ValueError("update_internal needs a check_visible of the same edge and R "
                             "that answered visible, just before")
        self.vis_edge = NONE
        t = update_internal(&self.A, &self.T, e, R)
        _raise_for(&self.T, t)
        return t

    def update_boundary(self, int e):
        self._check_front(e)
        self.vis_edge = NONE
        return update_boundary(&self.A, &self.T, e)

    def add_triangle(self, int t):
        if not 0 <= t < self.T.nt or self.T.tstate[t] != T_UNMESHED:
            raise ValueError(f"triangle {t} is not an unmeshed triangle")
        self.A.n_steps += 1
        _raise_for(&self.T, add_triangle(&self.A, &self.T, t))

    cdef void _note_thread(self):
        self.A.signals_here = threading.get_ident() == _MAIN_THREAD

    def run(self, progress=None):
        """The compiled Basic_aft loop with the built-in subtasks (GIL released).
        `progress`, if given, is called now and then with the meshed fraction of the
        area (exceptions it raises are ignored)."""
        cdef int res
        self.progress = progress
        self.A.progress = <void*> progress if progress is not None else NULL
        self._note_thread()
        try:
            with nogil:
                res = basic_aft_loop(&self.A, &self.T)
        finally:
            self.A.progress = NULL
            self.progress = None
        _reraise_pending(&self.A)
        _raise_for(&self.T, res)
        if DEBUG:
            problems = self.validate()
            if problems:
                raise KernelError("after Basic_aft: " + "; ".join(problems[:5]))

    def smooth(self, int first_movable, int passes, bint valence=True, int n_corners=-1):
        """Smooth the vertices first_movable.. (those Basic_aft created) for `passes`
        rounds, each followed by Delaunay flips, with the valence flips after the
        first and the valence splits before the first and after the last
        (smoothing.pxi; valence=False: neither); the points n_corners..first_movable
        that split an input segment slide along it (-1: none do; n_corners is the
        number of input vertices).  The splits' points are new vertices (counters()'s
        valence_splits).  Returns the number of moves."""
        cdef int res
        self._note_thread()
        with nogil:
            res = smooth(&self.A, &self.T, first_movable, passes, valence, n_corners)
        _reraise_pending(&self.A)
        _raise_for(&self.T, res)
        return res

    def refine(self, double min_angle, int n_corners, bint split_segments=True,
               int smooth_rounds=0, int first_movable=-1, bint slide=True):
        """The minimum-angle pass (refine.pxi): Delaunay refinement of the meshed
        triangles with an angle below `min_angle` degrees.  Vertices below `n_corners`
        are input vertices (ends of input segments).  With smooth_rounds > 0 (the
        smoothing rounds asked for), the vertices around the ones it added settle by
        a few smoothing rounds (Basic_aft's, first_movable on, and the pass's interior
        ones move; with `slide`, the points inside a chain slide) and the pass runs
        again (refine.pxi's refine_settled).  Respects max_triangles of set_options.
        Returns a dict of counts (of both runs)."""
        cdef Refine R
        cdef int res
        if smooth_rounds > 0 and not 0 <= first_movable <= self.T.nv:
            raise ValueError(f"first_movable must be in 0..{self.T.nv}, got {first_movable}")
        _refine_setup(&R, min_angle, n_corners, split_segments)
        self._note_thread()
        try:
            with nogil:
                res = refine_settled(&R, &self.A, &self.T, first_movable, slide,
                                     smooth_rounds)
        finally:
            refine_free(&R)
        _reraise_pending(&self.A)
        _raise_for(&self.T, res)
        if DEBUG:
            problems = self.validate()
            if problems:
                raise KernelError("after refine: " + "; ".join(problems[:5]))
        return _refine_counts(&R)

    def counters(self):
        return dict(meshed=self.A.n_meshed, unmeshed=self.A.n_unmeshed,
                    new_vertices=self.A.n_new, steps=self.A.n_steps,
                    forced_edges=self.A.n_forced, valence_splits=self.A.n_split,
                    scaffold=self.A.n_scaffold_planted,
                    scaffold_kept=self.A.n_scaffold_kept)

    def _check_edge(self, int e):
        if not 0 <= e < 3 * self.T.nt or self.T.tstate[e // 3] == T_FREE:
            raise ValueError(f"{e} is not a half-edge of the triangulation")

    def _check_front(self, int e):
        self._check_edge(e)
        if not is_front(&self.T, e):
            raise ValueError(f"half-edge {e} is not a front edge")


def hilbert_keys(const double[:, ::1] xy, int bits=16):
    """Index of each point along a Hilbert curve of 2**bits cells a side laid over the
    points' bounding square (int64)."""
    cdef Py_ssize_t n = xy.shape[0]
    out_arr = np.zeros(n, dtype=np.int64)
    cdef int64_t[::1] out = out_arr
    if not 1 <= bits <= 31:
        raise ValueError(f"bits must be in 1..31, got {bits}")
    if n:
        with nogil:
            hilbert_keys_into(&xy[0, 0], n, bits, &out[0])
    return out_arr


def orient2d_many(const double[:, ::1] points, const int32_t[:, ::1] tri):
    """Exact orientation sign of each row (a, b, c) of `tri` (int8 array)."""
    cdef Py_ssize_t n = tri.shape[0], i
    out_arr = np.empty(n, dtype=np.int8)
    cdef int8_t[::1] out = out_arr
    with nogil:
        for i in range(n):
            out[i] = orient2d(&points[tri[i, 0], 0], &points[tri[i, 1], 0], &points[tri[i, 2], 0])
    return out_arr


def incircle_many(const double[:, ::1] points, const int32_t[:, ::1] quad):
    """Exact incircle sign of each row (a, b, c, d) of `quad` (int8 array)."""
    cdef Py_ssize_t n = quad.shape[0], i
    out_arr = np.empty(n, dtype=np.int8)
    cdef int8_t[::1] out = out_arr
    with nogil:
        for i in range(n):
            out[i] = incircle(&points[quad[i, 0], 0], &points[quad[i, 1], 0],
                              &points[quad[i, 2], 0], &points[quad[i, 3], 0])
    return out_arr


cdef void _borrow_field(SizeField* S, double constant, const double[:, ::1] xy,
                        const double[::1] w, const double[::1] g, const int32_t[:, ::1] tv,
                        const int32_t[:, ::1] nb, double rate, double reach) except *:
    """S reads the given arrays in place (size_at writes nothing but S's hints)."""
    S.constant = constant
    S.rate = rate
    S.reach = reach
    S.hint = 0
    S.vhint = NULL
    S.vhint_cap = 0
    S.nt = tv.shape[0]
    S.nv = xy.shape[0]
    if S.nt:
        if w.shape[0] != S.nv or g.shape[0] != S.nv or nb.shape[0] != S.nt:
            raise ValueError("size field arrays of mismatched lengths")
        S.xy = <double*> &xy[0, 0]
        S.w = <double*> &w[0]
        S.g = <double*> &g[0]
        S.tv = <int32_t*> &tv[0, 0]
        S.nb = <int32_t*> &nb[0, 0]


cdef void _field_of(SizeField* S, double constant, const double[:, ::1] xy,
                    const double[::1] w, const double[::1] g, const int32_t[:, ::1] tv,
                    const int32_t[:, ::1] nb, double rate, double reach) except *:
    """S: a copy of the given field with its derived arrays (size_at reads those), to
    be freed with size_field_free (safe to call even when this raised)."""
    cdef SizeField view
    memset(S, 0, sizeof(SizeField))
    _borrow_field(&view, constant, xy, w, g, tv, nb, rate, reach)
    if size_field_set(S, constant, view.nv, view.nt, view.xy, view.w, view.g, view.tv,
                      view.nb, rate, reach):
        raise MemoryError()


def size_field_eval(double constant, const double[:, ::1] xy, const double[::1] w,
                    const double[::1] g, const int32_t[:, ::1] tv, const int32_t[:, ::1] nb,
                    double rate, double reach, const double[::1] x, const double[::1] y):
    """The size field of Triangulation.set_size_field at the points (x[i], y[i])."""
    cdef SizeField S
    cdef Py_ssize_t i, n = x.shape[0]
    out_arr = np.empty(n, dtype=np.float64)
    cdef double[::1] out = out_arr
    if y.shape[0] != n:
        raise ValueError("x and y must have the same length")
    memset(&S, 0, sizeof(SizeField))
    try:
        _field_of(&S, constant, xy, w, g, tv, nb, rate, reach)
        with nogil:
            for i in range(n):
                out[i] = size_at(&S, x[i], y[i])
    finally:
        size_field_free(&S)
    return out_arr


def size_field_count(double constant, const double[:, ::1] xy, const double[::1] w,
                     const double[::1] g, const int32_t[:, ::1] tv, const int32_t[:, ::1] nb,
                     double rate, double reach, double min_rate, double unit_area):
    """(about how many triangles of area unit_area * h^2 the field asks for on its
    background, the background's area): see sizing.pxi's count_triangles_asked."""
    cdef SizeField S
    cdef double area = 0.0, count
    memset(&S, 0, sizeof(SizeField))
    try:
        _field_of(&S, constant, xy, w, g, tv, nb, rate, reach)
        with nogil:
            count = count_triangles_asked(&S, min_rate, unit_area, &area)
    finally:
        size_field_free(&S)
    return count, area


def limit_gradation_mesh(const double[:, ::1] xy, const int32_t[:, ::1] tv, double[::1] h,
                         double rate, double reach=0.0):
    """In place: lower h (one value per row of xy) so that h[v] <= h[u] + rate
    max(0, |uv| - reach h[u]) along every edge of the triangles tv: the size grows by
    at most `rate` per unit of length along any path of edges (after holding for
    reach times itself)."""
    cdef int nv = xy.shape[0], nt = tv.shape[0], t, k, res
    if h.shape[0] != nv:
        raise ValueError("h must have one value per vertex")
    if nt == 0 or nv == 0:
        return
    for t in range(nt):
        for k in range(3):
            if not 0 <= tv[t, k] < nv:
                raise ValueError(f"triangle {t} refers to a vertex outside 0..{nv - 1}")
    with nogil:
        res = limit_gradation_tris(nv, nt, &xy[0, 0], &tv[0, 0], &h[0], rate, reach)
    if res:
        raise MemoryError()


cdef object _finite_arrays(Tri* T):
    """(tv, nb) of the live finite triangles of T (see Triangulation.finite_triangles)."""
    cdef int n
    cdef int32_t* index = <int32_t*> malloc(max(T.nt, 1) * sizeof(int32_t))
    if index == NULL:
        raise MemoryError()
    try:
        n = finite_index(T, index)
        tv_arr = np.empty((n, 3), dtype=np.int32)
        nb_arr = np.empty((n, 3), dtype=np.int32)
        if n:
            finite_into(T, index, _i32v(tv_arr), _i32v(nb_arr))
    finally:
        free(index)
    return tv_arr, nb_arr


def background_field(const double[:, ::1] xy, const int64_t[::1] rounds, double[::1] g,
                     double rate):
    """The background of a size field without a callable (background.pxi): the
    Delaunay triangulation of the points xy inserted in BRIO order (rounds: the
    round keys of _order.brio_order), and, in place, g (one size per point)
    gradation-limited at `rate` over its edges and inf at the points merged into
    an equal one.  Returns (tv, nb, finite): the finite triangles as in
    Triangulation.finite_triangles, and whether g is finite at every used point."""
    cdef int n = xy.shape[0], i, res = 0, ok, nt
    cdef int32_t* tv
    cdef int32_t* merged
    cdef Tri T
    if xy.shape[1] != 2 or rounds.shape[0] != n or g.shape[0] != n:
        raise ValueError("xy, rounds and g must have one row per point")
    if n < 3:
        raise ValueError("a background needs at least 3 points")
    if tri_init(&T, n + 16, 2 * n + 16):
        raise MemoryError()
    try:
        with nogil:
            for i in range(n):
                res = add_vertex(&T, xy[i, 0], xy[i, 1])
                if res < 0:
                    break
            if res >= 0:
                merged = <int32_t*> malloc(n * sizeof(int32_t))
                res = brio_insert(&T, &xy[0, 0], n, &rounds[0], merged) if merged else ERR_NOMEM
                free(merged)
        _raise_for(&T, res)
        tv_arr, nb_arr = _finite_arrays(&T)
        nt = len(tv_arr)
        tv = _i32v(tv_arr)
        with nogil:
            res = limit_gradation_tris(n, nt, &xy[0, 0], tv, &g[0], rate, 0.0)
            ok = unused_to_inf(n, nt, tv, &g[0]) if res == 0 else res
        if res or ok < 0:
            raise MemoryError()
    finally:
        tri_free(&T)
    return tv_arr, nb_arr, ok == 1


def ring_chains(const double[:, ::1] xy, const int64_t[::1] ring_of, Py_ssize_t n_rings):
    """Rings as closed coordinate runs (shapely's get_coordinates with return_index)
    -> (vertices (k, 2), segments (k, 2) int64, input edge of each vertex (k,),
    midpoint (e, 2) and ring (e,) of each input edge, repeats removed per ring); see
    ring_chains_into in inputs.pxi."""
    cdef Py_ssize_t n = xy.shape[0], k
    if ring_of.shape[0] != n:
        raise ValueError("xy and ring_of differ in length")
    # every ring has a coordinate, so the open vertices number exactly n - n_rings
    cdef bint ok = (ring_of[0] == 0 and ring_of[n - 1] == n_rings - 1) if n else n_rings == 0
    for k in range(1, n):
        ok = ok and 0 <= ring_of[k] - ring_of[k - 1] <= 1
    if not ok:
        raise ValueError("ring numbers must run from 0 to n_rings - 1 in steps of 0 or 1")
    cdef Py_ssize_t n_open = n - n_rings
    mid_arr = np.empty((n_open, 2), dtype=np.float64)
    ring_arr = np.empty(n_open, dtype=np.int64)
    pts_arr = np.empty((n_open, 2), dtype=np.float64)
    edge_arr = np.empty(n_open, dtype=np.int64)
    seg_arr = np.empty((n_open, 2), dtype=np.int64)
    removed_arr = np.zeros(n_rings, dtype=np.int64)
    cdef double[:, ::1] mid = mid_arr, pts = pts_arr
    cdef int64_t[::1] ring = ring_arr, edge = edge_arr, removed = removed_arr
    cdef int64_t[:, ::1] seg = seg_arr
    k = 0
    if n_open >= NOGIL_MIN_ITEMS:
        with nogil:
            k = ring_chains_into(&xy[0, 0], &ring_of[0], n, &mid[0, 0], &ring[0],
                                 &pts[0, 0], &edge[0], &seg[0, 0], &removed[0])
    elif n_open:
        k = ring_chains_into(&xy[0, 0], &ring_of[0], n, &mid[0, 0], &ring[0],
                             &pts[0, 0], &edge[0], &seg[0, 0], &removed[0])
    return pts_arr[:k], seg_arr[:k], edge_arr[:k], mid_arr, ring_arr, removed_arr


def rings_proved_valid(const double[:, ::1] pts, const int64_t[:, ::1] seg,
                       const int64_t[::1] edge, const int64_t[::1] ring,
                       const int64_t[::1] first_ring):
    """Whether ring_chains' output (points, segments, input edge of each segment, ring
    of each input edge) is proved a valid polygon or multipolygon, polygon k owning
    rings first_ring[k] (its exterior) to first_ring[k + 1] - 1: rings simple, meeting
    at most at common vertices where none crosses another and a polygon's own
    touches close no cycle, holes inside their exterior and outside each other, a
    polygon inside another only within a hole (see simple_rings.pxi).  False means
    not proved, not invalid."""
    cdef Py_ssize_t n = pts.shape[0], m = seg.shape[0], k
    cdef Py_ssize_t n_polys = first_ring.shape[0] - 1
    cdef int res
    if seg.shape[1] != 2 or pts.shape[1] != 2 or edge.shape[0] != m:
        raise ValueError("points and segments must have two columns, edges one per segment")
    for k in range(m):
        if not (0 <= seg[k, 0] < n and 0 <= seg[k, 1] < n
                and 0 <= edge[k] < ring.shape[0]):
            raise ValueError(f"segment {k} points outside the points or the edges")
    if m == 0 or n_polys < 1:
        return False
    if m >= NOGIL_MIN_ITEMS:
        with nogil:
            res = rings_valid(&pts[0, 0], n, &seg[0, 0], &edge[0], &ring[0], m,
                              &first_ring[0], n_polys)
    else:
        res = rings_valid(&pts[0, 0], n, &seg[0, 0], &edge[0], &ring[0], m,
                          &first_ring[0], n_polys)
    if res < 0:
        raise MemoryError("proving the rings valid")
    return res == 1


def coordinate_problems(const double[:, ::1] xy, double lo, double hi):
    """Bits: 1 a non-finite coordinate, 2 one of magnitude above hi, 4 one nonzero of
    magnitude below lo (see coordinate_flags in inputs.pxi)."""
    if xy.shape[0] == 0:
        return 0
    return coordinate_flags(&xy[0, 0], xy.shape[0] * xy.shape[1], lo, hi)


def segment_problems(const int64_t[:, ::1] seg, const double[:, ::1] xy):
    """Bits: 1 an index outside the points, 2 a segment of zero length (see
    segment_flags in inputs.pxi)."""
    if seg.shape[1] != 2 or xy.shape[1] != 2:
        raise ValueError("segments and points must have two columns")
    if seg.shape[0] == 0:
        return 0
    return segment_flags(&seg[0, 0], seg.shape[0], xy.shape[0],
                         &xy[0, 0] if xy.shape[0] else NULL)


def unique_points(const double[:, ::1] xy):
    """(first, inverse): the distinct points of xy in lexicographic order, first[j]
    the index of the first copy of distinct point j, inverse[i] the distinct point of
    xy[i] (both int64); None when a coordinate is not finite or equal points differ
    in their bits (0.0 and -0.0).  See unique_points_into in inputs.pxi."""
    cdef Py_ssize_t n = xy.shape[0], k
    if xy.shape[1] != 2:
        raise ValueError("points must have shape (n, 2)")
    first_arr = np.empty(n, dtype=np.int64)
    work_arr = np.empty(n, dtype=np.int64)
    inverse_arr = np.empty(n, dtype=np.int64)
    cdef int64_t[::1] first = first_arr, work = work_arr, inverse = inverse_arr
    if n == 0:
        return first_arr, inverse_arr
    if n >= NOGIL_MIN_ITEMS:
        with nogil:
            k = unique_points_into(&xy[0, 0], n, &first[0], &work[0], &inverse[0])
    else:
        k = unique_points_into(&xy[0, 0], n, &first[0], &work[0], &inverse[0])
    return None if k < 0 else (first_arr[:k], inverse_arr)


ctypedef fused _index_t:
    int32_t
    int64_t


cdef int _check_pslg(const double[:, ::1] xy, const _index_t[:, ::1] seg) except -1:
    """The argument checks of the kernel functions that take points and segments."""
    cdef Py_ssize_t n = xy.shape[0], k
    if xy.shape[1] != 2 or seg.shape[1] != 2:
        raise ValueError("points and segments must have two columns")
    for k in range(seg.shape[0]):
        if not (0 <= seg[k, 0] < n and 0 <= seg[k, 1] < n):
            raise ValueError(f"segment {k} refers to a vertex outside 0..{n - 1}")
    return 0


def rings_proper(const double[:, ::1] xy, const int64_t[:, ::1] seg):
    """Whether no vertex lies on the interior of a segment, no segment is repeated and
    none has equal ends (see rings_are_proper in inputs.pxi; every pair is looked at,
    so the caller keeps it to small inputs)."""
    cdef Py_ssize_t n = xy.shape[0], m = seg.shape[0]
    _check_pslg(xy, seg)
    if m == 0:
        return True
    return rings_are_proper(&xy[0, 0], n, &seg[0, 0], m) == 1


def segments_cross(const double[:, ::1] xy, const int64_t[:, ::1] seg):
    """1 if two segments cross at a point inside both, 0 if none do, -1 when the grid
    test gave up (see crossings.pxi): a proof of no crossing without a CDT."""
    cdef Py_ssize_t n = xy.shape[0], m = seg.shape[0]
    cdef int res
    _check_pslg(xy, seg)
    if m == 0:
        return 0            # no segment to point into
    with nogil:
        res = any_crossing(&xy[0, 0], n, &seg[0, 0], m)
    return res


def vertices_near_segments_pairs(const double[:, ::1] xy, const int64_t[:, ::1] seg,
                                 double reach):
    """(vertex, segment) index arrays (int64) of the vertices, other than a segment's
    own ends, within reach of a segment, and some a little farther (see nearby.pxi):
    the candidates noding.split_at_vertices judges."""
    cdef Py_ssize_t n = xy.shape[0], m = seg.shape[0], count
    cdef int64_t* pairs = NULL
    _check_pslg(xy, seg)
    if not reach >= 0.0:
        raise ValueError(f"reach must be >= 0, got {reach!r}")
    if n == 0 or m == 0:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    if n + m >= NOGIL_MIN_ITEMS:
        with nogil:
            count = vertices_near_segments(&xy[0, 0], n, &seg[0, 0], m, reach, &pairs)
    else:
        count = vertices_near_segments(&xy[0, 0], n, &seg[0, 0], m, reach, &pairs)
    if count < 0:
        raise MemoryError()
    try:
        out = np.empty((count, 2), dtype=np.int64)
        if count:
            memcpy(<int64_t*> _buffer_of(out), pairs, 2 * count * sizeof(int64_t))
    finally:
        free(pairs)
    return out[:, 0], out[:, 1]


def shortest_edges(const double[:, ::1] xy, const int32_t[:, ::1] seg,
                   bint kept_whole=False):
    """The length of the shortest segment at each point (inf at a point on none).
    kept_whole: the size each point asks for when the segments are not split (see
    kept_edge_sizes_into: the geometric mean where two meet at a wide angle)."""
    cdef Py_ssize_t n = xy.shape[0], m = seg.shape[0]
    _check_pslg(xy, seg)
    out_arr = np.empty(n, dtype=np.float64)
    cdef double[::1] out = out_arr
    if n and edge_sizes_into(&xy[0, 0], n, &seg[0, 0] if m else NULL, m, &out[0],
                             kept_whole):
        raise MemoryError()
    return out_arr


def take_or_none(const int32_t[::1] table, const int32_t[::1] index):
    """table[index] (int32), -1 where index is -1 (see take_into in inputs.pxi)."""
    cdef Py_ssize_t m = index.shape[0]
    out_arr = np.empty(m, dtype=np.int32)
    if m and take_into(&table[0] if table.shape[0] else NULL, table.shape[0], &index[0], m,
                       _i32v(out_arr)):
        raise IndexError("an index is outside -1..len(table) - 1")
    return out_arr


def bounding_box(const double[:, ::1] xy):
    """((xmin, ymin), (xmax, ymax)) of the points (finite, at least one) as floats."""
    cdef double box[4]
    if xy.shape[0] == 0 or xy.shape[1] != 2:
        raise ValueError("bounding_box needs an (n, 2) array with n > 0")
    box_of(&xy[0, 0], xy.shape[0], box)
    return (box[0], box[1]), (box[2], box[3])


def resolve_rounds(Triangulation tri, const double[::1] u, object sample, object rounds_of,
                   int64_t budget, int max_rounds, double tolerance, double span,
                   double coarsest, double thin):
    """sizing.py's _resolve_callable, every round in one call (resolve.pxi): the edges
    of tri not yet sampled, sample(mid) (the callable's checked sizes at their (k, 2)
    midpoints, one call a round), the midpoints to insert and their insertion in BRIO
    order (rounds_of(n): the round keys of n points), until a round finds nothing to
    sample or to insert, the samples would pass `budget`, or after max_rounds rounds.
    u: the size at each vertex of tri.  Returns (points, u) of every vertex of tri
    after the rounds.  The GIL is released around each round's kernel steps on a
    large background."""
    cdef Tri* T = &tri.T
    cdef Resolve R
    cdef int64_t k, n_keep, calls = 0
    cdef int _r
    cdef bint big
    cdef double* mid
    cdef const double* um
    cdef const int64_t* keys
    if u.shape[0] != T.nv:
        raise ValueError(f"u needs one size per vertex ({T.nv}), got {u.shape[0]}")
    memset(&R, 0, sizeof(Resolve))
    R.n = T.nv + budget
    R.tolerance, R.span, R.coarsest, R.thin = tolerance, span, coarsest, thin
    try:
        if _grow(<void**> &R.u, (T.nv + 1) * sizeof(double)):
            raise MemoryError()
        if T.nv:
            memcpy(R.u, &u[0], T.nv * sizeof(double))
        for _r in range(max_rounds):
            big = T.nt >= NOGIL_MIN_ITEMS
            if big:
                with nogil:
                    k = resolve_unsampled(T, &R)
            else:
                k = resolve_unsampled(T, &R)
            _raise_for(T, <int> min(k, 0))
            if k == 0 or calls + k > budget:
                break
            mid_arr = np.empty((k, 2), dtype=np.float64)
            mid = _f64v(mid_arr)
            edge_geometry(T.xy, R.out, k, R.n, R.ends, mid, R.length)
            um_arr = np.ascontiguousarray(sample(mid_arr), dtype=np.float64)
            if um_arr.shape != (k,):
                raise ValueError(f"sample gave shape {um_arr.shape} for {k} midpoints")
            um = _f64v(um_arr)
            calls += k
            # the round keys of the midpoints kept are a prefix of those of all k
            # (_order.round_keys), so the rest of the round needs no Python
            rounds_arr = np.ascontiguousarray(rounds_of(k), dtype=np.int64)
            if rounds_arr.shape != (k,):
                raise ValueError(f"rounds_of gave shape {rounds_arr.shape} for {k} points")
            keys = <const int64_t*> _buffer_of(rounds_arr)
            if big:
                with nogil:
                    n_keep = resolve_finish(T, &R, k, mid, um, keys)
            else:
                n_keep = resolve_finish(T, &R, k, mid, um, keys)
            _raise_for(T, <int> min(n_keep, 0))
            if n_keep == 0:
                break
        points_arr = np.empty((T.nv, 2), dtype=np.float64)
        u_arr = np.empty(T.nv, dtype=np.float64)
        if T.nv:
            memcpy(_f64v(points_arr), T.xy, 2 * T.nv * sizeof(double))
            memcpy(_f64v(u_arr), R.u, T.nv * sizeof(double))
    finally:
        resolve_free(&R)
    return points_arr, u_arr


def brio_keys_order(const double[:, ::1] xy, const int64_t[::1] rounds,
                    int bits=BRIO_HILBERT_BITS):
    """The stable argsort (int32) of rounds | hilbert_keys(xy, bits): the BRIO order
    of _order.brio_order in one call."""
    cdef Py_ssize_t n = xy.shape[0]
    if rounds.shape[0] != n:
        raise ValueError("xy and rounds differ in length")
    if not 1 <= bits <= 31:
        raise ValueError(f"bits must be in 1..31, got {bits}")
    keys_arr = np.empty(n, dtype=np.int64)
    order_arr = np.empty(n, dtype=np.int64)
    work_arr = np.empty(n, dtype=np.int64)
    out_arr = np.empty(n, dtype=np.int32)
    cdef int64_t[::1] keys = keys_arr, order = order_arr, work = work_arr
    cdef int32_t[::1] out = out_arr
    if n == 0:
        return out_arr
    if n >= NOGIL_MIN_ITEMS:
        with nogil:
            brio_order_into(&xy[0, 0], &rounds[0], n, bits, &keys[0], &order[0], &work[0],
                            &out[0])
    else:
        brio_order_into(&xy[0, 0], &rounds[0], n, bits, &keys[0], &order[0], &work[0],
                        &out[0])
    return out_arr


cdef int _check_discretize(const double[:, ::1] vertices, const int32_t[:, ::1] segments,
                           int max_samples) except -1:
    cdef Py_ssize_t i, k
    if max_samples < DISCRETIZE_MIN_SAMPLES:
        raise ValueError(f"max_samples must be at least {DISCRETIZE_MIN_SAMPLES}")
    for i in range(segments.shape[0]):
        for k in range(2):
            if not 0 <= segments[i, k] < vertices.shape[0]:
                raise ValueError(f"segments[{i}] refers to a vertex outside the points")
    return 0


cdef int _store_init(SampleStore* K, Py_ssize_t m) noexcept:
    """An empty SampleStore for m segments; -1 when out of memory (free it anyway)."""
    K.buf = NULL
    K.used = K.cap = 0
    K.at = <int64_t*> malloc(max(m, 1) * sizeof(int64_t))
    return -1 if K.at == NULL else 0


cdef double _count_pieces(SizeField* S, const double* v, const int32_t* seg, Py_ssize_t m,
                          int max_samples, double* cum, int64_t* pieces, Py_ssize_t* n_pts,
                          SampleStore* K, bint release) except? -1.0:
    """discretize_counts, without the GIL if `release`; MemoryError when it runs out."""
    cdef double total
    if release:
        with nogil:
            total = discretize_counts(S, v, seg, m, max_samples, cum, pieces, n_pts, K)
    else:
        total = discretize_counts(S, v, seg, m, max_samples, cum, pieces, n_pts, K)
    if total < 0.0:
        raise MemoryError()
    return total


def discretize_segments(double constant, const double[:, ::1] xy, const double[::1] w,
                        const double[::1] g, const int32_t[:, ::1] tv,
                        const int32_t[:, ::1] nb, double rate, double reach,
                        const double[:, ::1] vertices, const int32_t[:, ::1] segments,
                        int max_samples, double max_pieces):
    """The split points of each segment by the size field of set_size_field
    (discretize.pxi): returns (pieces (m,) int64, points (k, 2), row (k,) the segment
    of each point), the points segment by segment, in order along each; or
    (total, None, None) when the pieces would number more than max_pieces."""
    cdef SizeField S
    cdef Py_ssize_t m = segments.shape[0], n_pts = 0
    cdef double total = 0.0
    _check_discretize(vertices, segments, max_samples)
    cum_arr = np.empty(max_samples, dtype=np.float64)
    pieces_arr = np.empty(m, dtype=np.int64)
    cdef double[::1] cum = cum_arr
    cdef int64_t[::1] pieces = pieces_arr
    cdef SampleStore K
    cdef double* pts
    cdef int64_t* row
    memset(&S, 0, sizeof(SizeField))     # freed in the end, whatever raised
    try:
        if _store_init(&K, m):
            raise MemoryError()
        _field_of(&S, constant, xy, w, g, tv, nb, rate, reach)
        if m:
            total = _count_pieces(&S, &vertices[0, 0], &segments[0, 0], m, max_samples,
                                  &cum[0], &pieces[0], &n_pts, &K, True)
        if not total <= max_pieces:
            return total, None, None
        pts_arr = np.empty((n_pts, 2), dtype=np.float64)
        row_arr = np.empty(n_pts, dtype=np.int64)
        pts = _f64v(pts_arr)
        row = <int64_t*> _f64v(row_arr)
        if n_pts:
            with nogil:
                discretize_points(&vertices[0, 0], &segments[0, 0], m, &pieces[0], pts, row, &K)
    finally:
        sample_store_free(&K)
        size_field_free(&S)
    return pieces_arr, pts_arr, row_arr


def discretize_boundary(double constant, const double[:, ::1] xy, const double[::1] w,
                        const double[::1] g, const int32_t[:, ::1] tv,
                        const int32_t[:, ::1] nb, double rate, double reach,
                        const double[:, ::1] vertices, const int32_t[:, ::1] segments,
                        const int32_t[::1] source, int max_samples, double max_pieces):
    """discretize_segments, then the new PSLG at once: (vertices, segments, source)
    with the unsplit segments first, then each split segment as the chain through its
    split points (new vertices appended in that order); a split point that rounds
    onto the one before it or onto the segment's end is dropped (a piece of zero
    length would be fatal).  (total, None, None) as discretize_segments."""
    cdef SizeField S
    memset(&S, 0, sizeof(SizeField))     # freed in the end, whatever raised
    try:
        _field_of(&S, constant, xy, w, g, tv, nb, rate, reach)
        return _discretize_on(&S, vertices, segments, source, max_samples, max_pieces)
    finally:
        size_field_free(&S)


cdef object _discretize_on(SizeField* S, const double[:, ::1] vertices,
                           const int32_t[:, ::1] segments, const int32_t[::1] source,
                           int max_samples, double max_pieces):
    """discretize_boundary on the field S (its walks start from S.hint)."""
    cdef Py_ssize_t m = segments.shape[0], nv = vertices.shape[0], n_pts = 0, kept = 0
    cdef double total = 0.0
    cdef double* pts
    cdef uint8_t* keep
    cdef bint release
    _check_discretize(vertices, segments, max_samples)
    if source.shape[0] != m:
        raise ValueError("segments and source differ in length")
    cdef double* cum = <double*> malloc(max_samples * sizeof(double))
    cdef int64_t* pieces = <int64_t*> malloc(max(m, 1) * sizeof(int64_t))
    cdef SampleStore K
    try:
        if _store_init(&K, m) or cum == NULL or pieces == NULL:
            raise MemoryError()
        # a background makes every sample a walk; with a constant, small inputs are
        # a few microseconds (see NOGIL_MIN_ITEMS)
        release = S.nt > 0 or m >= NOGIL_MIN_ITEMS
        if m:
            total = _count_pieces(S, &vertices[0, 0], &segments[0, 0], m, max_samples, cum,
                                  pieces, &n_pts, &K, release)
        if not total <= max_pieces:
            return total, None, None
        pts_arr = np.empty((n_pts, 2), dtype=np.float64)
        keep_arr = np.empty(n_pts, dtype=np.uint8)
        pts = _f64v(pts_arr)
        keep = _u8v(keep_arr)
        if n_pts and release:
            with nogil:
                discretize_points(&vertices[0, 0], &segments[0, 0], m, pieces, pts, NULL, &K)
                kept = chain_keep(&vertices[0, 0], &segments[0, 0], m, pieces, pts, keep)
        elif n_pts:
            discretize_points(&vertices[0, 0], &segments[0, 0], m, pieces, pts, NULL, &K)
            kept = chain_keep(&vertices[0, 0], &segments[0, 0], m, pieces, pts, keep)
        # each split segment: one piece more than its kept points
        v_out = np.empty((nv + kept, 2), dtype=np.float64)
        s_out = np.empty((m + kept, 2), dtype=np.int32)
        e_out = np.empty(m + kept, dtype=np.int32)
        if m:
            chain_write(&vertices[0, 0], nv, &segments[0, 0], &source[0], m, pieces, pts,
                        keep, _f64v(v_out), _i32v(s_out), _i32v(e_out))
    finally:
        free(cum)
        free(pieces)
        sample_store_free(&K)
    return v_out, s_out, e_out


# generate's common case uses the def layer above: included last
include "pipeline.pxi"
