# Per-call input work on small arrays, where numpy's cost per call would exceed the
# work itself: ring clean-up, the checks of coordinates and segment indices, the
# distinct points of a vertex list and the proper-rings test of noding.py, the
# shortest input edge at each vertex, a stable argsort (src/aftmesh/inputs.py,
# noding.py, pslg.py, _order.py, _stages.py).  The Python side words the errors.
#
# Uses: libc, and orient2d from predicates.pxi (rings_are_proper); no triangulation.
from libc.math cimport INFINITY, fabs, isfinite, sqrt
from libc.stdlib cimport malloc, free
from libc.stdint cimport int32_t, int64_t, uint64_t

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


# ------------------------------------------------------------------ sorting
# A stable merge sort of indices 0..n-1 by a "less" rule on them: the same order as
# numpy's stable argsort / lexsort, without numpy's cost per call on small inputs.

ctypedef bint (*index_less)(const void* data, Py_ssize_t i, Py_ssize_t j) noexcept nogil


cdef bint _xy_less(const void* data, Py_ssize_t i, Py_ssize_t j) noexcept nogil:
    """Point i before point j lexicographically (x, then y), as np.lexsort((y, x))."""
    cdef const double* xy = <const double*> data
    if xy[2 * i] != xy[2 * j]:
        return xy[2 * i] < xy[2 * j]
    return xy[2 * i + 1] < xy[2 * j + 1]


cdef bint _key_less(const void* data, Py_ssize_t i, Py_ssize_t j) noexcept nogil:
    cdef const int64_t* key = <const int64_t*> data
    return key[i] < key[j]


cdef void stable_order(const void* data, index_less less, Py_ssize_t n,
                       int64_t* order, int64_t* work) noexcept nogil:
    """order = the indices 0..n-1 sorted stably by `less` (bottom-up merge sort;
    `work` holds n scratch entries)."""
    cdef Py_ssize_t i, width = 1, lo, mid, hi, a, b, k
    cdef int64_t* src = order
    cdef int64_t* dst = work
    cdef int64_t* tmp
    for i in range(n):
        order[i] = i
    while width < n:
        lo = 0
        while lo < n:
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            a, b, k = lo, mid, lo
            while a < mid and b < hi:
                # the right run's entry goes first only if strictly less: stable
                if less(data, src[b], src[a]):
                    dst[k] = src[b]
                    b += 1
                else:
                    dst[k] = src[a]
                    a += 1
                k += 1
            while a < mid:
                dst[k] = src[a]
                a += 1
                k += 1
            while b < hi:
                dst[k] = src[b]
                b += 1
                k += 1
            lo = hi
        tmp = src
        src = dst
        dst = tmp
        width *= 2
    if src != order:
        for i in range(n):
            order[i] = src[i]


cdef Py_ssize_t unique_points_into(const double* xy, Py_ssize_t n, int64_t* order,
                                   int64_t* work, int64_t* inverse) noexcept nogil:
    """The distinct points of xy in lexicographic order, as noding.unique_rows
    defines them: order[0..k) the first index of each run of equal points in the
    stable lexicographic order (k is returned), inverse[i] the run of point i.
    Returns -1 when a coordinate is not finite or two equal points differ in their
    bits (0.0 and -0.0): numpy's np.unique then decides."""
    cdef Py_ssize_t i, k = 0
    cdef int64_t p, q = 0
    cdef const uint64_t* bits = <const uint64_t*> xy
    for i in range(2 * n):
        if not isfinite(xy[i]):
            return -1
    stable_order(xy, _xy_less, n, order, work)
    for i in range(n):
        p = order[i]
        if i and xy[2 * p] == xy[2 * q] and xy[2 * p + 1] == xy[2 * q + 1]:
            if bits[2 * p] != bits[2 * q] or bits[2 * p + 1] != bits[2 * q + 1]:
                return -1
        else:
            order[k] = p
            k += 1
            q = p
        inverse[p] = k - 1
    return k


cdef int rings_are_proper(const double* xy, Py_ssize_t n, const int64_t* seg,
                          Py_ssize_t m) noexcept nogil:
    """1 when no vertex lies on the interior of a segment (exactly, by orient2d, and
    strictly between its ends by the dot products noding.split_at_vertices uses), no
    segment is given twice (either way round) and none joins a vertex to itself;
    0 otherwise.  Looks at every (vertex, segment) and (segment, segment) pair: for
    small inputs only."""
    cdef Py_ssize_t v, k, j
    cdef int64_t a, b
    cdef const double* pa
    cdef const double* pb
    cdef const double* pv
    for k in range(m):
        a = seg[2 * k]
        b = seg[2 * k + 1]
        if a == b:
            return 0
        for j in range(k + 1, m):
            if (seg[2 * j] == a and seg[2 * j + 1] == b) or (
                    seg[2 * j] == b and seg[2 * j + 1] == a):
                return 0
        pa = &xy[2 * a]
        pb = &xy[2 * b]
        for v in range(n):
            if v == a or v == b:
                continue
            pv = &xy[2 * v]
            if (pv[0] < min(pa[0], pb[0]) or pv[0] > max(pa[0], pb[0])
                    or pv[1] < min(pa[1], pb[1]) or pv[1] > max(pa[1], pb[1])):
                continue  # outside the segment's box: not on it
            if orient2d(pa, pb, pv) != 0:
                continue
            if ((pv[0] - pa[0]) * (pb[0] - pa[0]) + (pv[1] - pa[1]) * (pb[1] - pa[1]) > 0
                    and (pv[0] - pb[0]) * (pa[0] - pb[0])
                    + (pv[1] - pb[1]) * (pa[1] - pb[1]) > 0):
                return 0
    return 1


cdef inline double segment_length(const double* xy, int32_t a, int32_t b) noexcept nogil:
    """|xy[b] - xy[a]|, rounded as np.linalg.norm(..., axis=1) rounds it (hypot may
    differ by an ulp), and the same from either end (a difference only changes sign)."""
    return sqrt((xy[2 * b] - xy[2 * a]) * (xy[2 * b] - xy[2 * a])
                + (xy[2 * b + 1] - xy[2 * a + 1]) * (xy[2 * b + 1] - xy[2 * a + 1]))


cdef void shortest_edges_into(const double* xy, Py_ssize_t n, const int32_t* seg,
                              Py_ssize_t m, double* out) noexcept nogil:
    """out[v] = the length of the shortest segment at vertex v, inf if none."""
    cdef Py_ssize_t k, v
    cdef int32_t a, b
    cdef double d
    for v in range(n):
        out[v] = INFINITY
    for k in range(m):
        a = seg[2 * k]
        b = seg[2 * k + 1]
        d = segment_length(xy, a, b)
        if d < out[a]:
            out[a] = d
        if d < out[b]:
            out[b] = d


# With input edges kept whole (split_boundary=False) a long edge cannot be cut down to
# its short neighbour's size, so at a vertex joining the two the shortest edge's length
# asked the long edge's own triangle to sit in a field far finer than itself: its apex
# was pulled onto the fine layers (flat triangles along the long edge) inside rings of
# graded ones.  Where two edges meet wider than this, the vertex asks for the geometric
# mean of their lengths instead, each edge then off by the square root of their ratio;
# in a sharper corner the triangles are bounded by the short edge whatever is asked.
# (Real-world group kept whole: mean radius ratio 0.9430 -> 0.9445, an eighth fewer
# triangles; with edges split, the shortest stays better: 0.9626 against 0.9604.)
cdef double KEPT_MEAN_MIN_COS = 0.5    # cos 60 degrees


cdef void kept_edge_sizes_into(const double* xy, Py_ssize_t n, const int32_t* seg,
                               Py_ssize_t m, double* out, double* longest,
                               int32_t* ends) noexcept nogil:
    """out[v] = the size input vertex v asks for when its edges are kept whole: the
    shortest segment at v, but the geometric mean of the two where exactly two meet at
    an angle wider than KEPT_MEAN_MIN_COS says (inf at a point on none).  longest (n)
    and ends (3 n: the count of segments at v, then the far ends of the first two) are
    scratch."""
    cdef Py_ssize_t k, v
    cdef int32_t a, b, c
    cdef double d, ux, uy, wx, wy
    for v in range(n):
        out[v] = INFINITY
        longest[v] = 0.0
        ends[3 * v] = 0
    for k in range(2 * m):       # each segment from both ends
        a = seg[k]
        b = seg[k ^ 1]
        d = segment_length(xy, a, b)
        if d < out[a]:
            out[a] = d
        if d > longest[a]:
            longest[a] = d
        c = ends[3 * a]
        if c < 2:
            ends[3 * a + 1 + c] = b
        ends[3 * a] = c + 1
    for v in range(n):
        if ends[3 * v] != 2 or not out[v] > 0.0:
            continue
        a = ends[3 * v + 1]
        b = ends[3 * v + 2]
        ux = xy[2 * a] - xy[2 * v]
        uy = xy[2 * a + 1] - xy[2 * v + 1]
        wx = xy[2 * b] - xy[2 * v]
        wy = xy[2 * b + 1] - xy[2 * v + 1]
        # with two segments at v, the shortest and longest are their two lengths
        if ux * wx + uy * wy < KEPT_MEAN_MIN_COS * out[v] * longest[v]:
            out[v] = sqrt(out[v]) * sqrt(longest[v])


cdef int edge_sizes_into(const double* xy, Py_ssize_t n, const int32_t* seg,
                         Py_ssize_t m, double* out, bint kept_whole) noexcept nogil:
    """out[v] = the size input vertex v asks for: the shortest segment at v
    (shortest_edges_into), or with the segments kept whole kept_edge_sizes_into's
    (its scratch allocated here).  0, or -1 when out of memory."""
    cdef double* longest
    cdef int32_t* ends
    if not kept_whole:
        shortest_edges_into(xy, n, seg, m, out)
        return 0
    longest = <double*> malloc(n * sizeof(double))
    ends = <int32_t*> malloc(3 * n * sizeof(int32_t))
    if longest != NULL and ends != NULL:
        kept_edge_sizes_into(xy, n, seg, m, out, longest, ends)
    free(longest)
    free(ends)
    return 0 if longest != NULL and ends != NULL else -1


cdef int take_into(const int32_t* table, Py_ssize_t n, const int32_t* index, Py_ssize_t m,
                   int32_t* out) noexcept nogil:
    """out[i] = table[index[i]], -1 where index[i] is -1 (the kernel's and the domain's
    "none"); returns -1 if an index is outside -1..n-1 (nothing is read there), else 0."""
    cdef Py_ssize_t i
    for i in range(m):
        if index[i] == -1:
            out[i] = -1
        elif 0 <= index[i] < n:
            out[i] = table[index[i]]
        else:
            return -1
    return 0


cdef void box_of(const double* xy, Py_ssize_t n, double* box) noexcept nogil:
    """box = (xmin, ymin, xmax, ymax) of the n points (n > 0, finite)."""
    cdef Py_ssize_t i
    box[0] = box[2] = xy[0]
    box[1] = box[3] = xy[1]
    for i in range(1, n):
        box[0] = min(box[0], xy[2 * i])
        box[1] = min(box[1], xy[2 * i + 1])
        box[2] = max(box[2], xy[2 * i])
        box[3] = max(box[3], xy[2 * i + 1])
