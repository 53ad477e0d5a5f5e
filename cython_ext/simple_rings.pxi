# Whether a polygon's rings are a valid polygon (or a multipolygon's, a valid
# multipolygon), proved without GEOS: every ring simple (at least three vertices, no two
# of its edges meeting but consecutive ones at their common vertex, and those not
# folding back), no two rings meeting anywhere, every hole inside its exterior ring and
# outside its polygon's other holes, and a polygon inside another's exterior only within
# one of its holes.  Rings that meet nowhere leave each interior connected, so such a
# polygon is valid in the OGC sense shapely and GEOS use; what this cannot prove (rings
# touching at a point, which can be valid too, or a search past its caps) is left to
# GEOS, which then also names what is wrong.
#
# Two closed segments that meet overlap in x and in y, so a sweep along the longer side
# of the points' box tests each segment, by exact orient2d, against the segments whose
# range along it overlaps its own and whose box meets its box: the ones the sweep line
# stabs, a few on the rings people draw.  A hole's place is the crossing number of a
# ray from its first vertex, by exact orient2d and exact comparisons of y: with the
# rings apart, the vertex lies on no edge, so the count is never ambiguous.
#
# Uses: inputs.pxi (box_of); predicates.pxi (orient2d).
from libc.stdint cimport int64_t
from libc.stdlib cimport malloc, free

# Segment pairs tested per segment before leaving the proof to GEOS: the sweep line
# stabs a few segments of a drawn ring, but a comb of many parallel teeth would make
# the sweep quadratic.
cdef int64_t PROOF_TESTS_PER_SEGMENT = 32
# The placement tests (rings times segments) allowed before leaving the proof to GEOS:
# quadratic in the rings, so a polygon with thousands of holes (or a multipolygon of
# thousands of parts) is not looked at ring by ring (GEOS's own index handles it).
cdef int64_t RING_TESTS_MAX = 250_000


cdef inline bint _on_span(const double* a, const double* b, const double* c) noexcept nogil:
    # c, known to be on the line ab, lies within the closed box of a and b
    return (min(a[0], b[0]) <= c[0] <= max(a[0], b[0])
            and min(a[1], b[1]) <= c[1] <= max(a[1], b[1]))


cdef bint _segments_meet(const double* a, const double* b, const double* c,
                         const double* d) noexcept nogil:
    """Whether the closed segments ab and cd have a point in common (exact)."""
    cdef int o1, o2, o3, o4
    if (max(a[0], b[0]) < min(c[0], d[0]) or max(c[0], d[0]) < min(a[0], b[0])
            or max(a[1], b[1]) < min(c[1], d[1]) or max(c[1], d[1]) < min(a[1], b[1])):
        return False
    o1 = orient2d(a, b, c)
    o2 = orient2d(a, b, d)
    o3 = orient2d(c, d, a)
    o4 = orient2d(c, d, b)
    if o1 != o2 and o3 != o4 and o1 * o2 <= 0 and o3 * o4 <= 0:
        return True             # they cross, or an end of one is inside the other
    return ((o1 == 0 and _on_span(a, b, c)) or (o2 == 0 and _on_span(a, b, d))
            or (o3 == 0 and _on_span(c, d, a)) or (o4 == 0 and _on_span(c, d, b)))


cdef inline bint _folds_back(const double* a, const double* b, const double* c) noexcept nogil:
    # consecutive edges ab, bc overlap beyond b: c on the line, on a's side of b
    if orient2d(a, b, c) != 0:
        return False
    if a[0] != b[0]:
        return (a[0] < b[0]) == (c[0] < b[0]) or c[0] == b[0]
    return (a[1] < b[1]) == (c[1] < b[1]) or c[1] == b[1]


cdef int _inside_ring(const double* xy, const int64_t* seg, Py_ssize_t s0, Py_ssize_t s1,
                      const double* p) noexcept nogil:
    """Whether p is inside the ring of segments s0..s1 - 1: the parity of the edges
    crossing the ray from p towards +x (an edge counts when one end lies above p's y
    and the other not).  1 inside, 0 outside, -1 when p is on an edge (the rings
    met after all: nothing is proved)."""
    cdef Py_ssize_t k
    cdef const double* a
    cdef const double* b
    cdef int inside = 0, o
    for k in range(s0, s1):
        a = &xy[2 * seg[2 * k]]
        b = &xy[2 * seg[2 * k + 1]]
        if (a[1] > p[1]) != (b[1] > p[1]):
            o = orient2d(a, b, p)
            if o == 0:
                return -1
            # p left of the edge taken upwards: the crossing is to p's right
            if (o > 0) == (b[1] > a[1]):
                inside ^= 1
    return inside


cdef int _ring_starts(const int64_t* seg, const int64_t* edge, const int64_t* ring,
                      Py_ssize_t m, Py_ssize_t n_rings, Py_ssize_t* start) noexcept nogil:
    """start[r] .. start[r + 1]: ring r's segments (segment k's ring: ring[edge[k]]),
    which must be consecutive, in ring order, closed, and at least three.  1, or 0
    when they are not."""
    cdef Py_ssize_t k, r = 0
    start[0] = 0
    for k in range(m):
        if ring[edge[k]] != r:
            if ring[edge[k]] != r + 1:
                return 0
            r += 1
            start[r] = k
    if r != n_rings - 1:
        return 0
    start[n_rings] = m
    for r in range(n_rings):
        if start[r + 1] - start[r] < 3:
            return 0
        for k in range(start[r], start[r + 1]):
            if seg[2 * k] == seg[2 * k + 1]:
                return 0
            if seg[2 * k + 1] != (seg[2 * k + 2] if k + 1 < start[r + 1]
                                  else seg[2 * start[r]]):
                return 0
    return 1


cdef inline Py_ssize_t _slab(double x, double base, double scale, Py_ssize_t last) noexcept nogil:
    # the sweep's slab of coordinate x: a monotone function of x (a rounded
    # subtraction, a product with a positive number, a truncation, a clamp), so that
    # a range ending in an earlier slab than another begins ends before it
    cdef double t = (x - base) * scale
    if not t > 0.0:
        return 0
    if t >= last:
        return last
    return <Py_ssize_t> t


cdef int _no_contacts(const double* xy, Py_ssize_t n, const int64_t* seg,
                      Py_ssize_t m) noexcept nogil:
    """1 when no two segments meet but consecutive ones of a ring at their shared end
    (which _rings_fold_free judges), 0 when two do or the sweep gives up past
    PROOF_TESTS_PER_SEGMENT tests per segment, -1 when out of memory.  The sweep goes
    along the box's longer side slab by slab (m slabs, segments in the slab their
    range begins in, a counting sort); a segment leaves the active ones once the
    slab its range ends in is behind."""
    cdef Py_ssize_t i, j, t, k, q, n_active = 0, axis, slab
    cdef int64_t tests = 0, cap = PROOF_TESTS_PER_SEGMENT * m
    cdef int res = 1
    cdef double box[4]
    cdef double scale
    cdef double* bb = <double*> malloc(4 * m * sizeof(double))
    cdef Py_ssize_t* work = <Py_ssize_t*> malloc((5 * m + 1) * sizeof(Py_ssize_t))
    cdef Py_ssize_t* first
    cdef Py_ssize_t* order
    cdef Py_ssize_t* begins
    cdef Py_ssize_t* ends
    cdef Py_ssize_t* active
    if bb == NULL or work == NULL:
        free(bb)
        free(work)
        return -1
    first = work                # m + 1 slab starts into order
    order = &work[m + 1]
    ends = &work[2 * m + 1]     # the slab each segment's range ends in
    active = &work[3 * m + 1]
    begins = &work[4 * m + 1]   # the slab it begins in
    box_of(xy, n, box)
    axis = 0 if box[2] - box[0] >= box[3] - box[1] else 1
    scale = m / (box[2 + axis] - box[axis]) if box[2 + axis] > box[axis] else 0.0
    for k in range(m):          # bb[4k..4k+3]: low and high along the axis, across it
        for j in range(2):
            bb[4 * k + 2 * j] = min(xy[2 * seg[2 * k] + (axis ^ j)],
                                    xy[2 * seg[2 * k + 1] + (axis ^ j)])
            bb[4 * k + 2 * j + 1] = max(xy[2 * seg[2 * k] + (axis ^ j)],
                                        xy[2 * seg[2 * k + 1] + (axis ^ j)])
    for i in range(m + 1):
        first[i] = 0
    for k in range(m):
        begins[k] = _slab(bb[4 * k], box[axis], scale, m - 1)
        ends[k] = _slab(bb[4 * k + 1], box[axis], scale, m - 1)
        first[begins[k] + 1] += 1
    for i in range(m):
        first[i + 1] += first[i]
    for k in range(m):
        order[first[begins[k]]] = k
        first[begins[k]] += 1
    slab = 0
    for i in range(m):
        k = order[i]
        while first[slab] <= i:     # after the placing pass, first[s] is slab s's end
            slab += 1
        j = 0
        for t in range(n_active):
            q = active[t]
            if ends[q] < slab:
                continue            # ends before every segment still to come begins
            active[j] = q
            j += 1
            tests += 1
            if (bb[4 * q + 3] < bb[4 * k + 2] or bb[4 * k + 3] < bb[4 * q + 2]
                    or bb[4 * q + 1] < bb[4 * k] or bb[4 * k + 1] < bb[4 * q]):
                continue            # apart across the axis, or along it in one slab
            if (seg[2 * k] == seg[2 * q + 1] or seg[2 * k + 1] == seg[2 * q]
                    or seg[2 * k] == seg[2 * q] or seg[2 * k + 1] == seg[2 * q + 1]):
                continue            # consecutive: a shared vertex index
            if _segments_meet(&xy[2 * seg[2 * k]], &xy[2 * seg[2 * k + 1]],
                              &xy[2 * seg[2 * q]], &xy[2 * seg[2 * q + 1]]):
                res = 0
                break
        if res == 0 or tests > cap:
            res = 0
            break
        n_active = j
        active[n_active] = k
        n_active += 1
    free(bb)
    free(work)
    return res


cdef bint _rings_fold_free(const double* xy, const int64_t* seg, const Py_ssize_t* start,
                           Py_ssize_t n_rings) noexcept nogil:
    cdef Py_ssize_t r, k, nxt_k
    for r in range(n_rings):
        for k in range(start[r], start[r + 1]):
            nxt_k = k + 1 if k + 1 < start[r + 1] else start[r]
            if _folds_back(&xy[2 * seg[2 * k]], &xy[2 * seg[2 * k + 1]],
                           &xy[2 * seg[2 * nxt_k + 1]]):
                return False
    return True


cdef int _inside_any_hole(const double* xy, const int64_t* seg, const Py_ssize_t* start,
                          Py_ssize_t h0, Py_ssize_t h1, Py_ssize_t skip,
                          const double* p) noexcept nogil:
    # p inside one of the rings h0..h1 - 1 but `skip`: 1, 0, or -1 (on an edge)
    cdef Py_ssize_t q
    cdef int inside
    for q in range(h0, h1):
        if q != skip:
            inside = _inside_ring(xy, seg, start[q], start[q + 1], p)
            if inside != 0:
                return inside
    return 0


cdef bint _rings_placed(const double* xy, const int64_t* seg, const Py_ssize_t* start,
                        const int64_t* first_ring, Py_ssize_t n_polys) noexcept nogil:
    """Polygon k owns rings first_ring[k] (its exterior) to first_ring[k + 1] - 1 (its
    holes).  Every hole inside its exterior and outside its polygon's other holes, and
    every exterior inside another polygon's exterior only within one of its holes
    (the interiors then do not overlap), each judged at the ring's first vertex (the
    rings meet nowhere, so a ring is wholly inside or outside another)."""
    cdef Py_ssize_t k, j, r, shell
    cdef const double* p
    cdef int inside
    for k in range(n_polys):
        shell = first_ring[k]
        for r in range(shell + 1, first_ring[k + 1]):
            p = &xy[2 * seg[2 * start[r]]]
            if _inside_ring(xy, seg, start[shell], start[shell + 1], p) != 1:
                return False
            if _inside_any_hole(xy, seg, start, shell + 1, first_ring[k + 1], r, p) != 0:
                return False
        p = &xy[2 * seg[2 * start[shell]]]
        for j in range(n_polys):
            if j == k:
                continue
            inside = _inside_ring(xy, seg, start[first_ring[j]], start[first_ring[j] + 1], p)
            if inside == 0:
                continue
            if inside < 0 or _inside_any_hole(xy, seg, start, first_ring[j] + 1,
                                              first_ring[j + 1], -1, p) != 1:
                return False
    return True


cdef int rings_valid(const double* xy, Py_ssize_t n, const int64_t* seg, const int64_t* edge,
                     const int64_t* ring, Py_ssize_t m, const int64_t* first_ring,
                     Py_ssize_t n_polys) noexcept nogil:
    """1 when the rings (ring_chains_into's n points, m segments, the input edge of
    each and the ring of each input edge) are proved the valid polygon, or the valid
    multipolygon, whose polygon k owns rings first_ring[k] (its exterior) to
    first_ring[k + 1] - 1 (see the top of this file); 0 when not proved, -1 when out
    of memory."""
    cdef Py_ssize_t* start
    cdef Py_ssize_t n_rings, k
    cdef int res
    if n_polys < 1 or m < 3 or first_ring[0] != 0:
        return 0
    for k in range(n_polys):
        if first_ring[k + 1] <= first_ring[k]:
            return 0
    n_rings = first_ring[n_polys]
    if n_rings > 1 and (n_rings - 1) * m > RING_TESTS_MAX:
        return 0
    start = <Py_ssize_t*> malloc((n_rings + 1) * sizeof(Py_ssize_t))
    if start == NULL:
        return -1
    res = _ring_starts(seg, edge, ring, m, n_rings, start)
    if res == 1 and not _rings_fold_free(xy, seg, start, n_rings):
        res = 0
    if res == 1:
        res = _no_contacts(xy, n, seg, m)
    if res == 1 and not _rings_placed(xy, seg, start, first_ring, n_polys):
        res = 0
    free(start)
    return res
