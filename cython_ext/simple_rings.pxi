# Whether a polygon's rings are a valid polygon (or a multipolygon's, a valid
# multipolygon), proved without GEOS: every ring simple (at least three vertices, no two
# of its edges meeting but consecutive ones at their common vertex, and those not
# folding back), two rings meeting at most at common vertices (a touch: a point that is
# a vertex of both, where neither crosses the other and no edge of one runs along an
# edge of the other), the touches between a polygon's own rings forming no cycle (a
# hole touching the exterior twice, or a chain of holes touching from the exterior
# back to it, would cut the interior in two), every hole inside its exterior ring and
# outside its polygon's other holes, and a polygon inside another's exterior only
# within one of its holes.  Such a polygon is valid in the OGC sense shapely and GEOS
# use; what this cannot prove (a vertex on another ring's edge, a ring touching
# itself, a search past its caps) is left to GEOS, which then also names what is wrong.
#
# Two closed segments that meet overlap in x and in y, so a sweep along the longer side
# of the points' box tests each segment, by exact orient2d, against the segments whose
# range along it overlaps its own and whose box meets its box: the ones the sweep line
# stabs, a few on a few rings.  Across many rings it stabs many, so there the segments
# that meet are found as pairs sharing a cell of a grid of about one cell a segment
# (nearby.pxi; their common point is in both boxes).  At a touch, a ring
# does not cross another when both of its edges there leave into the same one of the
# two angles the other's edges make (exact orient2d).  A ring's place is the crossing
# number of a ray from one of its vertices that touches nothing, counted for every
# ring at once over the segments of the ray's horizontal band (by exact orient2d and
# exact comparisons of y): that vertex lies on no other ring, so no count is
# ambiguous, and a ring that meets another only at touches where it does not cross
# it lies wholly on one side.  When every vertex of a ring touches another ring, the
# ray starts at a touched vertex, and each ring through it is placed by the angle the
# first ring's edges leave into there (its inside or outside, by its exact
# orientation).
#
# Uses: inputs.pxi (box_of); predicates.pxi (orient2d); nearby.pxi (_Grid, _grid_build,
# _cell); background.pxi (int64_order).
from libc.stdint cimport int64_t, uint8_t
from libc.stdlib cimport malloc, realloc, free, qsort

# Segment pairs tested per segment before leaving the proof to GEOS: the sweep line, or
# a grid cell, meets a few segments of the rings people draw, but a comb of many
# parallel teeth, or a fan of edges from one vertex, would make the search quadratic.
cdef int64_t PROOF_TESTS_PER_SEGMENT = 32
# Rings up to which the contacts are searched by a sweep (a line across the rings
# stabs a few segments of each), beyond by a grid (whose cells hold a few segments
# however many rings there are, but which costs more to build).
cdef Py_ssize_t SWEEP_MAX_RINGS = 16
# The placement's work allowed per segment (the segments tested against the rays of
# the rings' vertices) before leaving the proof to GEOS: a few per segment on the
# rings people draw, but a thousand holes stacked along one horizontal line would
# each test the others' segments.  Tall thin parts side by side put many segments in
# every band: poly2tri-sketchup's 63 tiles need more than 64 a segment, and are
# proved in 0.2 ms with 256.
cdef int64_t PLACEMENT_TESTS_PER_SEGMENT = 256
# Entries per segment allowed in the placement's bands before they are made coarser:
# long edges across many bands (tall thin parts) would otherwise fill many each.
cdef int64_t BAND_ENTRIES_PER_SEGMENT = 8


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


cdef struct Touches:
    # The touches the search found: pairs of vertices of two rings at one point (a
    # pair once for each pair of their edges, so up to four times).
    int64_t* pair
    Py_ssize_t n, cap


cdef inline bint _same_point(const double* xy, int64_t i, int64_t j) noexcept nogil:
    return xy[2 * i] == xy[2 * j] and xy[2 * i + 1] == xy[2 * j + 1]


cdef int _touch(const double* xy, const int64_t* seg, const int64_t* seg_ring,
                Py_ssize_t k, Py_ssize_t q, Touches* found) noexcept nogil:
    """Segments k and q, known to meet: 1 when they are of different rings and meet
    only at an end of both, a point (found gets the two vertices there), 0 when they
    meet otherwise, -1 when out of memory."""
    cdef int64_t i = -1, j = -1, a = -1, b = -1
    cdef int shared = 0, ai, bj
    cdef int64_t* grown
    if seg_ring[k] == seg_ring[q]:
        return 0
    for ai in range(2):
        for bj in range(2):
            if _same_point(xy, seg[2 * k + ai], seg[2 * q + bj]):
                shared += 1
                i = seg[2 * k + ai]
                j = seg[2 * q + bj]
                a = seg[2 * k + 1 - ai]
                b = seg[2 * q + 1 - bj]
    if shared != 1:
        return 0        # an end on the other's inside, or a crossing, or one edge twice
    if _runs_along(&xy[2 * i], &xy[2 * a], &xy[2 * b]):
        return 0
    if found.n == found.cap:
        found.cap = 2 * found.cap + 16
        grown = <int64_t*> realloc(found.pair, 2 * found.cap * sizeof(int64_t))
        if grown == NULL:
            return -1
        found.pair = grown
    found.pair[2 * found.n] = i
    found.pair[2 * found.n + 1] = j
    found.n += 1
    return 1


cdef inline bint _runs_along(const double* p, const double* a, const double* b) noexcept nogil:
    # the edges p -> a and p -> b leave p in one direction (they overlap)
    if orient2d(p, a, b) != 0:
        return False
    if p[0] != a[0]:
        return (a[0] < p[0]) == (b[0] < p[0])
    return (a[1] < p[1]) == (b[1] < p[1])


cdef int _no_contacts(const double* xy, Py_ssize_t n, const int64_t* seg,
                      const int64_t* seg_ring, Py_ssize_t n_rings, Py_ssize_t m,
                      Touches* found) noexcept nogil:
    """1 when no two segments meet but consecutive ones of a ring at their shared end
    (which _rings_fold_free judges) and two rings' edges at a common vertex (_touch:
    found gets them), 0 when two meet otherwise or the search gives up past
    PROOF_TESTS_PER_SEGMENT pair tests per segment, -1 when out of memory.  A line
    across a few rings stabs a few of their segments, so a sweep tests each segment
    against a few; across many rings it stabs many, and a grid's cells hold fewer."""
    if n_rings <= SWEEP_MAX_RINGS:
        return _swept_contacts(xy, n, seg, seg_ring, m, found)
    return _gridded_contacts(xy, n, seg, seg_ring, m, found)


cdef int _swept_contacts(const double* xy, Py_ssize_t n, const int64_t* seg,
                         const int64_t* seg_ring, Py_ssize_t m, Touches* found) noexcept nogil:
    """_no_contacts by a sweep along the box's longer side, slab by slab (m slabs,
    segments in the slab their range begins in, a counting sort): a segment is tested
    against the active ones, and leaves them once the slab its range ends in is
    behind.  A slab is nearby.pxi's _cell, monotone in the coordinate, so a range
    ending in an earlier slab than another begins ends before it."""
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
        begins[k] = _cell(bb[4 * k], box[axis], scale, m)
        ends[k] = _cell(bb[4 * k + 1], box[axis], scale, m)
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
                res = _touch(xy, seg, seg_ring, k, q, found)
                if res != 1:
                    break
        if res != 1 or tests > cap:
            res = res if res < 0 else 0
            break
        n_active = j
        active[n_active] = k
        n_active += 1
    free(bb)
    free(work)
    return res


cdef int _gridded_contacts(const double* xy, Py_ssize_t n, const int64_t* seg,
                           const int64_t* seg_ring, Py_ssize_t m, Touches* found) noexcept nogil:
    """_no_contacts by nearby.pxi's grid: two segments that meet share a cell (their
    common point is in both boxes, and a box is registered in every cell it
    overlaps), so each cell's pairs are tested."""
    cdef _Grid G
    cdef Py_ssize_t c, i, j
    cdef int64_t k, q, tests = 0, cap = PROOF_TESTS_PER_SEGMENT * m
    cdef int res = 1
    G.start = NULL
    G.item = NULL
    if _grid_build(xy, n, seg, m, 0.0, &G) != 0:
        res = -1
    c = 0
    while res == 1 and c < G.g * G.g:
        for i in range(G.start[c], G.start[c + 1]):
            k = G.item[i]
            for j in range(i + 1, G.start[c + 1]):
                q = G.item[j]
                tests += 1
                if (seg[2 * k] == seg[2 * q + 1] or seg[2 * k + 1] == seg[2 * q]
                        or seg[2 * k] == seg[2 * q] or seg[2 * k + 1] == seg[2 * q + 1]):
                    continue        # consecutive: a shared vertex index
                if _segments_meet(&xy[2 * seg[2 * k]], &xy[2 * seg[2 * k + 1]],
                                  &xy[2 * seg[2 * q]], &xy[2 * seg[2 * q + 1]]):
                    res = _touch(xy, seg, seg_ring, k, q, found)
                    if res != 1:
                        break
            if res != 1 or tests > cap:
                break
        if tests > cap:
            res = 0
        c += 1
    free(G.start)
    free(G.item)
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


cdef int _in_angle(const double* p, const double* a1, const double* a0,
                   const double* c) noexcept nogil:
    """Whether c lies inside the angle swept counter-clockwise from the ray p -> a1 to
    the ray p -> a0 (a ring's two edges at p, not folding back): 1 inside, 0 outside,
    -1 on one of the rays (then an edge p -> c runs along that edge)."""
    cdef int turn = orient2d(p, a1, a0), o1 = orient2d(p, a1, c), o0 = orient2d(p, a0, c)
    if (o1 == 0 and not _opposite(p, a1, c)) or (o0 == 0 and not _opposite(p, a0, c)):
        return -1
    if turn > 0:
        return o1 > 0 and o0 < 0
    if turn < 0:
        return o1 > 0 or o0 < 0
    return o1 > 0               # a straight angle: the half-plane left of p -> a1


cdef inline bint _opposite(const double* p, const double* a, const double* c) noexcept nogil:
    # c, on the line pa, lies on the other side of p than a
    return not _runs_along(p, a, c)


cdef bint _touches_cross_free(const double* xy, const Touches* found, const int64_t* nextv,
                              const int64_t* prevv) noexcept nogil:
    """At every touch (i of one ring, j of another), each ring's two edges leave into
    one of the two angles the other's edges make."""
    cdef Py_ssize_t t, side
    cdef int64_t u, w
    cdef int s1, s0
    for t in range(found.n):
        for side in range(2):
            u = found.pair[2 * t + side]
            w = found.pair[2 * t + 1 - side]
            s1 = _in_angle(&xy[2 * u], &xy[2 * nextv[u]], &xy[2 * prevv[u]], &xy[2 * nextv[w]])
            s0 = _in_angle(&xy[2 * u], &xy[2 * nextv[u]], &xy[2 * prevv[u]], &xy[2 * prevv[w]])
            if s1 < 0 or s0 < 0 or s1 != s0:
                return False
    return True


cdef int64_t _root(int64_t* parent, int64_t i) noexcept nogil:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


cdef int _touches_acyclic(const Touches* found, const int64_t* vring,
                          const int64_t* ring_poly, Py_ssize_t n,
                          Py_ssize_t n_rings) noexcept nogil:
    """1 when the touches between rings of one polygon form no cycle: the graph of
    rings and touch points (a point joined to each ring through it) is a forest.  The
    vertices at one point are grouped (through the pairs), then each polygon's rings
    at that point are joined to the first of them: joining two rings already joined
    closes a cycle.  0 when they do, -1 when out of memory."""
    cdef Py_ssize_t t, k, a, b, s0, n_touched = 0
    cdef int64_t v, ra, rb
    cdef int res = 1
    cdef int64_t* vparent = <int64_t*> malloc(n * sizeof(int64_t))
    cdef int64_t* rparent = <int64_t*> malloc(n_rings * sizeof(int64_t))
    cdef int64_t* key = <int64_t*> malloc(2 * found.n * sizeof(int64_t))
    if vparent == NULL or rparent == NULL or key == NULL:
        res = -1
    else:
        for k in range(n):
            vparent[k] = k
        for k in range(n_rings):
            rparent[k] = k
        for t in range(found.n):
            ra = _root(vparent, found.pair[2 * t])
            rb = _root(vparent, found.pair[2 * t + 1])
            if ra != rb:
                vparent[rb] = ra
        # the touched vertices by group (its root), each once
        for t in range(2 * found.n):
            v = found.pair[t]
            key[t] = _root(vparent, v) * n + v
        qsort(key, 2 * found.n, sizeof(int64_t), int64_order)
        for t in range(2 * found.n):
            if t == 0 or key[t] != key[t - 1]:
                key[n_touched] = key[t]
                n_touched += 1
        s0 = 0
        for a in range(n_touched):
            if key[a] // n != key[s0] // n:
                s0 = a              # a new group starts
            for b in range(s0, a):
                if ring_poly[vring[key[b] % n]] == ring_poly[vring[key[a] % n]]:
                    ra = _root(rparent, vring[key[b] % n])
                    rb = _root(rparent, vring[key[a] % n])
                    if ra == rb:
                        res = 0
                    rparent[rb] = ra
                    break
            if res == 0:
                break
    free(vparent)
    free(rparent)
    free(key)
    return res


cdef struct Bands:
    # The segments by horizontal band of the points' box (nb bands): band b's are
    # seg_of[first[b] .. first[b + 1]), every segment whose y range meets the band.
    Py_ssize_t* first
    Py_ssize_t* seg_of
    double base, scale
    Py_ssize_t nb


cdef inline void _band_range(const double* xy, const int64_t* seg, Py_ssize_t k,
                             const Bands* B, Py_ssize_t* lo, Py_ssize_t* hi) noexcept nogil:
    cdef double y0 = xy[2 * seg[2 * k] + 1], y1 = xy[2 * seg[2 * k + 1] + 1]
    lo[0] = _cell(min(y0, y1), B.base, B.scale, B.nb)
    hi[0] = _cell(max(y0, y1), B.base, B.scale, B.nb)


cdef int _bands(const double* xy, Py_ssize_t n, const int64_t* seg, Py_ssize_t m,
                Bands* B) noexcept nogil:
    """Fill B: as many bands as segments, halved while the segments would fill more
    than BAND_ENTRIES_PER_SEGMENT entries each (long edges across many bands).  0, or
    -1 when out of memory."""
    cdef Py_ssize_t k, b, lo, hi
    cdef int64_t total
    cdef double box[4]
    box_of(xy, n, box)
    B.base = box[1]
    B.seg_of = NULL
    B.first = NULL
    B.nb = m
    while True:
        B.scale = B.nb / (box[3] - box[1]) if box[3] > box[1] else 0.0
        total = 0
        for k in range(m):
            _band_range(xy, seg, k, B, &lo, &hi)
            total += hi - lo + 1
        if total <= BAND_ENTRIES_PER_SEGMENT * m or B.nb == 1:
            break
        B.nb = (B.nb + 1) // 2
    B.first = <Py_ssize_t*> malloc((B.nb + 1) * sizeof(Py_ssize_t))
    B.seg_of = <Py_ssize_t*> malloc((total if total > 0 else 1) * sizeof(Py_ssize_t))
    if B.first == NULL or B.seg_of == NULL:
        return -1
    for b in range(B.nb + 1):
        B.first[b] = 0
    for k in range(m):
        _band_range(xy, seg, k, B, &lo, &hi)
        for b in range(lo, hi + 1):
            B.first[b + 1] += 1
    for b in range(B.nb):
        B.first[b + 1] += B.first[b]
    for k in range(m):
        _band_range(xy, seg, k, B, &lo, &hi)
        for b in range(lo, hi + 1):
            B.seg_of[B.first[b]] = k
            B.first[b] += 1
    for b in range(B.nb, 0, -1):    # the filling moved each start to the next band's
        B.first[b] = B.first[b - 1]
    B.first[0] = 0
    return 0


cdef enum:
    RING_ODD = 1        # _ray_parities: an odd number of crossings
    RING_LISTED = 2     # crossed at all (in odd_rings once)
    RING_THROUGH = 4    # through the ray's origin: placed by _touching_sides instead


cdef int _ray_parities(const double* xy, const int64_t* seg, const int64_t* seg_ring,
                       const Bands* B, int64_t r, const double* p, uint8_t* odd,
                       int64_t* odd_rings, Py_ssize_t* n_odd,
                       int64_t* tests) noexcept nogil:
    """odd[q] & RING_ODD = the parity of the crossings of the ray from p towards +x
    with ring q's segments, for every ring but r (p's own) and those marked
    RING_THROUGH; the rings crossed at all into odd_rings (n_odd of them, marked
    RING_LISTED).  An edge counts when one end lies above p's y and the other not, and
    p lies left of it taken upwards.  1, or 0 when p lies on an edge (nothing is
    proved)."""
    cdef Py_ssize_t b = _cell(p[1], B.base, B.scale, B.nb), t, k
    cdef const double* a
    cdef const double* c
    cdef int o
    n_odd[0] = 0
    tests[0] += B.first[b + 1] - B.first[b]
    for t in range(B.first[b], B.first[b + 1]):
        k = B.seg_of[t]
        if seg_ring[k] == r or odd[seg_ring[k]] & RING_THROUGH:
            continue
        a = &xy[2 * seg[2 * k]]
        c = &xy[2 * seg[2 * k + 1]]
        if (a[1] > p[1]) != (c[1] > p[1]):
            o = orient2d(a, c, p)
            if o == 0:
                return 0
            if (o > 0) == (c[1] > a[1]):
                if not odd[seg_ring[k]] & RING_LISTED:
                    odd_rings[n_odd[0]] = seg_ring[k]
                    n_odd[0] += 1
                odd[seg_ring[k]] ^= RING_ODD
                odd[seg_ring[k]] |= RING_LISTED
    return 1


cdef bint _ring_in_place(int64_t r, const int64_t* ring_poly, const int64_t* first_ring,
                         const uint8_t* odd, const int64_t* odd_rings, Py_ssize_t n_odd,
                         uint8_t* in_shell, uint8_t* in_hole) noexcept nogil:
    """From the parities at ring r's vertex: a hole inside its exterior and outside its
    polygon's other holes; an exterior inside another polygon's exterior only within
    one of its holes.  in_shell and in_hole (one per polygon, zero) are left zero."""
    cdef Py_ssize_t t
    cdef int64_t q, k = ring_poly[r], j
    cdef bint ok = True
    if r != first_ring[k]:
        if not odd[first_ring[k]] & RING_ODD:
            return False
        for t in range(n_odd):
            q = odd_rings[t]
            if odd[q] & RING_ODD and ring_poly[q] == k and q != first_ring[k]:
                return False
        return True
    for t in range(n_odd):
        q = odd_rings[t]
        if odd[q] & RING_ODD:
            j = ring_poly[q]
            if q == first_ring[j]:
                in_shell[j] = 1
            else:
                in_hole[j] = 1
    for t in range(n_odd):
        j = ring_poly[odd_rings[t]]
        if in_shell[j] and not in_hole[j]:
            ok = False
    for t in range(n_odd):
        j = ring_poly[odd_rings[t]]
        in_shell[j] = in_hole[j] = 0
    return ok


cdef struct RingLinks:
    # Each vertex's neighbours along its ring and its ring, and each ring's
    # orientation: what placing a ring at a touched vertex needs (NULL when no ring
    # touches another).
    int64_t* nextv
    int64_t* prevv
    int64_t* vring
    uint8_t* ccw


cdef void _touching_sides(const double* xy, const Touches* found, const RingLinks* L,
                          int64_t v, uint8_t mark, uint8_t* odd, int64_t* odd_rings,
                          Py_ssize_t* n_odd) noexcept nogil:
    """For every ring through v (a vertex of ring r that touches others there): with
    mark, mark it RING_THROUGH; without, set its parity at v to whether r lies inside
    it, r's edges at v leaving into its inside (the angle from its next vertex to its
    previous one counter-clockwise, for a counter-clockwise ring; the other angle for
    a clockwise one): r crosses no ring, so this holds for all of r."""
    cdef Py_ssize_t t, side
    cdef int64_t w, q
    cdef int inside
    for t in range(found.n):
        for side in range(2):
            if found.pair[2 * t + side] != v:
                continue
            w = found.pair[2 * t + 1 - side]
            q = L.vring[w]
            if mark:
                odd[q] |= mark
                continue
            inside = _in_angle(&xy[2 * v], &xy[2 * L.nextv[w]], &xy[2 * L.prevv[w]],
                               &xy[2 * L.nextv[v]])
            if not L.ccw[q]:
                inside = not inside
            if not odd[q] & RING_LISTED:
                odd_rings[n_odd[0]] = q
                n_odd[0] += 1
            odd[q] = (odd[q] & ~RING_ODD) | RING_LISTED | (RING_ODD if inside else 0)


cdef int _rings_placed(const double* xy, Py_ssize_t n, const int64_t* seg,
                       const int64_t* seg_ring, Py_ssize_t m, const int64_t* rep,
                       const RingLinks* L, const Touches* found, const int64_t* ring_poly,
                       const int64_t* first_ring, Py_ssize_t n_rings,
                       Py_ssize_t n_polys) noexcept nogil:
    """Every ring in its place (_ring_in_place), judged at its vertex rep[r], which
    lies on no other ring, or, when every vertex of r touches another ring, at ~rep[r]
    (the rings through it placed by _touching_sides, the others by the ray).  1, 0
    when not (or past PLACEMENT_TESTS_PER_SEGMENT work per segment), -1 when out of
    memory."""
    cdef Bands B
    cdef int64_t cap = PLACEMENT_TESTS_PER_SEGMENT * m, tests = 0, v
    cdef Py_ssize_t r, t, n_odd
    cdef int res
    cdef uint8_t* odd = <uint8_t*> calloc(n_rings + 2 * n_polys, 1)
    cdef int64_t* odd_rings = <int64_t*> malloc(n_rings * sizeof(int64_t))
    if odd == NULL or odd_rings == NULL:
        free(odd)
        free(odd_rings)
        return -1
    res = 1 if _bands(xy, n, seg, m, &B) == 0 else -1
    r = 0
    while res == 1 and r < n_rings:
        v = rep[r] if rep[r] >= 0 else ~rep[r]
        if rep[r] < 0:
            _touching_sides(xy, found, L, v, RING_THROUGH, odd, odd_rings, &n_odd)
            tests += 2 * found.n
        res = _ray_parities(xy, seg, seg_ring, &B, r, &xy[2 * v], odd, odd_rings,
                            &n_odd, &tests)
        if rep[r] < 0:
            _touching_sides(xy, found, L, v, 0, odd, odd_rings, &n_odd)
        if res == 1 and (tests > cap or not _ring_in_place(
                r, ring_poly, first_ring, odd, odd_rings, n_odd, &odd[n_rings],
                &odd[n_rings + n_polys])):
            res = 0
        for t in range(n_odd):      # every ring marked RING_THROUGH is listed too
            odd[odd_rings[t]] = 0
        r += 1
    free(B.first)
    free(B.seg_of)
    free(odd)
    free(odd_rings)
    return res


cdef int _representatives(const int64_t* seg, const Py_ssize_t* start, Py_ssize_t n_rings,
                          const Touches* found, Py_ssize_t n, int64_t* rep) noexcept nogil:
    """rep[r] = ring r's first vertex that touches no other ring, or ~ its first
    vertex when every vertex does; 1, or -1 when out of memory."""
    cdef Py_ssize_t t, r, k
    cdef uint8_t* touched = <uint8_t*> calloc(n if n > 0 else 1, 1)
    if touched == NULL:
        return -1
    for t in range(2 * found.n):
        touched[found.pair[t]] = 1
    for r in range(n_rings):
        rep[r] = -1
        for k in range(start[r], start[r + 1]):
            if not touched[seg[2 * k]]:
                rep[r] = seg[2 * k]
                break
        if rep[r] < 0:
            rep[r] = ~seg[2 * start[r]]
    free(touched)
    return 1


cdef int _ring_links(const double* xy, Py_ssize_t n, const int64_t* seg, Py_ssize_t m,
                     const int64_t* seg_ring, const Py_ssize_t* start, Py_ssize_t n_rings,
                     RingLinks* L) noexcept nogil:
    """Fill L (its arrays malloc'ed: the caller frees L.nextv and L.ccw).  A ring's
    orientation is the turn at its lowest vertex (least x, then least y), which is
    never flat: the ring is simple and does not fold back.  0, or -1 when out of
    memory."""
    cdef Py_ssize_t k, r
    cdef int64_t low, v
    L.nextv = <int64_t*> malloc(3 * n * sizeof(int64_t))
    L.ccw = <uint8_t*> malloc(n_rings if n_rings > 0 else 1)
    if L.nextv == NULL or L.ccw == NULL:
        return -1
    L.prevv = &L.nextv[n]
    L.vring = &L.nextv[2 * n]
    for k in range(m):
        L.nextv[seg[2 * k]] = seg[2 * k + 1]
        L.prevv[seg[2 * k + 1]] = seg[2 * k]
        L.vring[seg[2 * k]] = seg_ring[k]
    for r in range(n_rings):
        low = seg[2 * start[r]]
        for k in range(start[r], start[r + 1]):
            v = seg[2 * k]
            if xy[2 * v] < xy[2 * low] or (xy[2 * v] == xy[2 * low]
                                           and xy[2 * v + 1] < xy[2 * low + 1]):
                low = v
        L.ccw[r] = orient2d(&xy[2 * L.prevv[low]], &xy[2 * low], &xy[2 * L.nextv[low]]) > 0
    return 0


cdef int _touches_valid(const RingLinks* L, const double* xy, const int64_t* ring_poly,
                        Py_ssize_t n, Py_ssize_t n_rings, const Touches* found) noexcept nogil:
    """The touches _no_contacts found cross nothing and close no cycle; 1, 0, or -1
    when out of memory."""
    if not _touches_cross_free(xy, found, L.nextv, L.prevv):
        return 0
    return _touches_acyclic(found, L.vring, ring_poly, n, n_rings)


cdef int rings_valid(const double* xy, Py_ssize_t n, const int64_t* seg, const int64_t* edge,
                     const int64_t* ring, Py_ssize_t m, const int64_t* first_ring,
                     Py_ssize_t n_polys) noexcept nogil:
    """1 when the rings (ring_chains_into's n points, m segments, the input edge of
    each and the ring of each input edge) are proved the valid polygon, or the valid
    multipolygon, whose polygon k owns rings first_ring[k] (its exterior) to
    first_ring[k + 1] - 1 (see the top of this file); 0 when not proved, -1 when out
    of memory."""
    cdef Py_ssize_t* start = NULL
    cdef int64_t* per_ring = NULL      # rep (n_rings), ring_poly (n_rings), seg_ring (m)
    cdef Py_ssize_t n_rings, k, r
    cdef int res
    cdef Touches found
    cdef RingLinks links
    if n_polys < 1 or m < 3 or first_ring[0] != 0:
        return 0
    for k in range(n_polys):
        if first_ring[k + 1] <= first_ring[k]:
            return 0
    n_rings = first_ring[n_polys]
    found.pair = NULL
    found.n = found.cap = 0
    links.nextv = links.prevv = links.vring = NULL
    links.ccw = NULL
    start = <Py_ssize_t*> malloc((n_rings + 1) * sizeof(Py_ssize_t))
    per_ring = <int64_t*> malloc((2 * n_rings + m) * sizeof(int64_t))
    if start == NULL or per_ring == NULL:
        free(start)
        free(per_ring)
        return -1
    res = _ring_starts(seg, edge, ring, m, n_rings, start)
    if res == 1:
        for k in range(n_polys):
            for r in range(first_ring[k], first_ring[k + 1]):
                per_ring[n_rings + r] = k
        for r in range(n_rings):
            for k in range(start[r], start[r + 1]):
                per_ring[2 * n_rings + k] = r
        if not _rings_fold_free(xy, seg, start, n_rings):
            res = 0
    if res == 1:
        res = _no_contacts(xy, n, seg, &per_ring[2 * n_rings], n_rings, m, &found)
    if res == 1 and found.n:
        res = _ring_links(xy, n, seg, m, &per_ring[2 * n_rings], start, n_rings, &links)
        if res == 0:
            res = _touches_valid(&links, xy, &per_ring[n_rings], n, n_rings, &found)
    if res == 1:
        res = _representatives(seg, start, n_rings, &found, n, per_ring)
    if res == 1 and n_rings > 1:
        res = _rings_placed(xy, n, seg, &per_ring[2 * n_rings], m, per_ring, &links,
                            &found, &per_ring[n_rings], first_ring, n_rings, n_polys)
    free(start)
    free(per_ring)
    free(found.pair)
    free(links.nextv)
    free(links.ccw)
    return res
