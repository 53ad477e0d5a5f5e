# Per-call input work on small arrays, where numpy's cost per call would exceed the
# work itself: ring clean-up and the checks of coordinates and segment indices
# (src/aftmesh/inputs.py, pslg.py).  The Python side words the errors.
#
# Uses: libc only; no triangulation, no predicates.
from libc.math cimport fabs, isfinite
from libc.stdint cimport int64_t

# Bits of coordinate_flags / segment_flags.
cdef enum:
    COORD_NOT_FINITE = 1
    COORD_TOO_LARGE = 2
    COORD_TOO_SMALL = 4
    SEG_OUT_OF_RANGE = 1
    SEG_ZERO_LENGTH = 2


cdef Py_ssize_t ring_chains_into(const double* xy, const int64_t* ring_of, Py_ssize_t n,
                                 double* mid, int64_t* ring, double* pts, int64_t* edge,
                                 int64_t* seg, int64_t* removed) noexcept nogil:
    """Rings given as closed coordinate runs (xy[2i], xy[2i+1]) of ring ring_of[i],
    each run ending with a copy of its first vertex, ring numbers ascending.  Input
    edge o goes from open vertex o to the next one of its ring (the last one back to
    the first): mid[o] is its midpoint, ring[o] its ring.  A vertex equal to the next
    is dropped (a run of repeats keeps its last copy) and counted in removed[ring];
    the others are written to pts with their outgoing input edge in edge, and seg
    joins each to the next kept vertex of its ring.  Returns how many were kept."""
    cdef Py_ssize_t s = 0, e, i, j, o = 0, k = 0, first
    cdef int64_t r
    while s < n:
        r = ring_of[s]
        e = s
        while e + 1 < n and ring_of[e + 1] == r:
            e += 1
        first = k
        for i in range(s, e):  # e is the closing copy of s
            j = i + 1 if i + 1 < e else s
            mid[2 * o] = 0.5 * (xy[2 * i] + xy[2 * j])
            mid[2 * o + 1] = 0.5 * (xy[2 * i + 1] + xy[2 * j + 1])
            ring[o] = r
            if xy[2 * i] != xy[2 * j] or xy[2 * i + 1] != xy[2 * j + 1]:
                pts[2 * k] = xy[2 * i]
                pts[2 * k + 1] = xy[2 * i + 1]
                edge[k] = o
                seg[2 * k] = k
                seg[2 * k + 1] = k + 1
                k += 1
            else:
                removed[r] += 1
            o += 1
        if k > first:
            seg[2 * k - 1] = first
        s = e + 1
    return k


cdef int coordinate_flags(const double* xy, Py_ssize_t n, double lo,
                          double hi) noexcept nogil:
    """Which problems the n values have: COORD_NOT_FINITE, COORD_TOO_LARGE (magnitude
    above hi, infinities included), COORD_TOO_SMALL (nonzero magnitude below lo)."""
    cdef Py_ssize_t i
    cdef double a
    cdef int flags = 0
    for i in range(n):
        a = fabs(xy[i])
        if not isfinite(a):
            flags |= COORD_NOT_FINITE
        if a > hi:
            flags |= COORD_TOO_LARGE
        if a < lo and a > 0:
            flags |= COORD_TOO_SMALL
    return flags


cdef int segment_flags(const int64_t* seg, Py_ssize_t m, Py_ssize_t n,
                       const double* xy) noexcept nogil:
    """Which problems the m segments (seg[2k], seg[2k+1]) on the n points xy have:
    SEG_OUT_OF_RANGE (an index outside 0..n-1), SEG_ZERO_LENGTH (both ends the same
    index or at equal coordinates)."""
    cdef Py_ssize_t k
    cdef int64_t a, b
    cdef int flags = 0
    for k in range(m):
        a = seg[2 * k]
        b = seg[2 * k + 1]
        if a < 0 or b < 0 or a >= n or b >= n:
            flags |= SEG_OUT_OF_RANGE
        elif a == b or (xy[2 * a] == xy[2 * b] and xy[2 * a + 1] == xy[2 * b + 1]):
            flags |= SEG_ZERO_LENGTH
    return flags
