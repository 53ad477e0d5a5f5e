# Which vertices lie near which segments: the candidate search of noding.py's
# split_at_vertices (a ring touching another at a vertex, a constraint line ending on a
# boundary), by a uniform grid over the points' bounding box (crossings.pxi tests the
# pairs of segments in each of its cells too).
#
# The grid has about as many cells as there are segments, so its cost follows the
# input, never the box's extent; each segment is registered in the cells its box
# (widened by the reach) overlaps, and a vertex looks only at the segments of its own
# cell.  A cell index is a monotone function of the coordinate (a rounded subtraction,
# a product with a positive number, a truncation), so a vertex inside a segment's
# widened box is always in one of the cells that box was registered in: no pair is
# missed by rounding.  Candidates are then judged by noding.py (exact orientation,
# the interior test, the snapping rules), so this search only has to be a superset of
# "within reach of the segment".
#
# Uses: libc; box_of from inputs.pxi.
from libc.math cimport fabs, sqrt
from libc.stdint cimport int64_t
from libc.stdlib cimport malloc, free, realloc

# Registrations (segment, cell) allowed per item before the grid is made coarser: long
# diagonal segments cover many cells, and a coarser grid bounds the memory and time.
cdef int NEARBY_REGISTRATIONS_PER_ITEM = 8
# A candidate's distance to the segment's line may exceed the reach by this factor:
# the test is in floating point, and noding.py decides exactly afterwards.
cdef double NEARBY_SLACK = 2.0


cdef inline Py_ssize_t _cell(double x, double x0, double scale, Py_ssize_t g) noexcept nogil:
    cdef double t = (x - x0) * scale
    if not t >= 0.0:             # below the box, or NaN
        return 0
    if t >= g:
        return g - 1
    return <Py_ssize_t> t


cdef struct _Grid:
    Py_ssize_t g                 # cells per side
    double x0, y0, sx, sy        # cell of x: (x - x0) * sx, truncated
    Py_ssize_t* start            # g * g + 1 offsets into item
    int64_t* item                # segment indices, cell by cell


cdef void _seg_box(const double* xy, const int64_t* seg, Py_ssize_t k, double reach,
                   double* box) noexcept nogil:
    cdef const double* a = &xy[2 * seg[2 * k]]
    cdef const double* b = &xy[2 * seg[2 * k + 1]]
    box[0] = min(a[0], b[0]) - reach
    box[1] = min(a[1], b[1]) - reach
    box[2] = max(a[0], b[0]) + reach
    box[3] = max(a[1], b[1]) + reach


cdef Py_ssize_t _registrations(const double* xy, const int64_t* seg, Py_ssize_t m,
                               double reach, _Grid* G) noexcept nogil:
    """How many (segment, cell) pairs the segments' widened boxes make on grid G."""
    cdef Py_ssize_t k, total = 0
    cdef double box[4]
    for k in range(m):
        _seg_box(xy, seg, k, reach, box)
        total += ((_cell(box[2], G.x0, G.sx, G.g) - _cell(box[0], G.x0, G.sx, G.g) + 1)
                  * (_cell(box[3], G.y0, G.sy, G.g) - _cell(box[1], G.y0, G.sy, G.g) + 1))
    return total


cdef int _grid_build(const double* xy, Py_ssize_t n, const int64_t* seg, Py_ssize_t m,
                     double reach, _Grid* G) noexcept nogil:
    """Register the segments' boxes, widened by reach, on a grid of about m cells (coarser while the
    registrations exceed NEARBY_REGISTRATIONS_PER_ITEM per point and segment).
    0, or -1 when out of memory."""
    cdef double box[4]
    cdef double pbox[4]
    cdef Py_ssize_t k, cx, cy, i, j, total, cap = NEARBY_REGISTRATIONS_PER_ITEM * (n + m)
    cdef Py_ssize_t* fill
    cdef int pass_
    box_of(xy, n, pbox)
    G.x0 = pbox[0]
    G.y0 = pbox[1]
    G.g = max(1, <Py_ssize_t> sqrt(<double> m))
    while True:
        G.sx = G.g / (pbox[2] - pbox[0]) if pbox[2] > pbox[0] else 0.0
        G.sy = G.g / (pbox[3] - pbox[1]) if pbox[3] > pbox[1] else 0.0
        total = _registrations(xy, seg, m, reach, G)
        if total <= cap or G.g == 1:
            break
        G.g = (G.g + 1) // 2
    G.start = <Py_ssize_t*> malloc((G.g * G.g + 1) * sizeof(Py_ssize_t))
    G.item = <int64_t*> malloc((total if total > 0 else 1) * sizeof(int64_t))
    fill = <Py_ssize_t*> malloc((G.g * G.g + 1) * sizeof(Py_ssize_t))
    if G.start == NULL or G.item == NULL or fill == NULL:
        free(fill)
        return -1
    for i in range(G.g * G.g + 1):
        G.start[i] = 0
    for pass_ in range(2):          # count per cell, then place
        for k in range(m):
            _seg_box(xy, seg, k, reach, box)
            for cy in range(_cell(box[1], G.y0, G.sy, G.g), _cell(box[3], G.y0, G.sy, G.g) + 1):
                for cx in range(_cell(box[0], G.x0, G.sx, G.g),
                                _cell(box[2], G.x0, G.sx, G.g) + 1):
                    j = cy * G.g + cx
                    if pass_ == 0:
                        G.start[j + 1] += 1
                    else:
                        G.item[fill[j]] = k
                        fill[j] += 1
        if pass_ == 0:
            for i in range(G.g * G.g):
                G.start[i + 1] += G.start[i]
                fill[i] = G.start[i]
    free(fill)
    return 0


cdef inline bint _near_segment(const double* xy, const int64_t* seg, Py_ssize_t k,
                               Py_ssize_t v, double wide) noexcept nogil:
    """Vertex v (not an end of segment k) within `wide` of the segment's box and of
    its line, in floating point."""
    cdef const double* a = &xy[2 * seg[2 * k]]
    cdef const double* b = &xy[2 * seg[2 * k + 1]]
    cdef const double* p = &xy[2 * v]
    cdef double dx = b[0] - a[0], dy = b[1] - a[1], cross
    if v == seg[2 * k] or v == seg[2 * k + 1]:
        return False
    if (p[0] < min(a[0], b[0]) - wide or p[0] > max(a[0], b[0]) + wide
            or p[1] < min(a[1], b[1]) - wide or p[1] > max(a[1], b[1]) + wide):
        return False
    cross = dx * (p[1] - a[1]) - dy * (p[0] - a[0])
    return fabs(cross) <= wide * sqrt(dx * dx + dy * dy)


cdef Py_ssize_t vertices_near_segments(const double* xy, Py_ssize_t n, const int64_t* seg,
                                       Py_ssize_t m, double reach,
                                       int64_t** pairs) noexcept nogil:
    """The (vertex, segment) pairs with the vertex within NEARBY_SLACK * reach of the
    segment's box and line (_near_segment), a superset of the vertices within reach of
    the segment, vertex by vertex, into a malloc'ed array pairs[0] of 2 per pair
    (the caller frees it).  Returns the number of pairs, or -1 when out of memory."""
    cdef _Grid G
    cdef Py_ssize_t v, i, j, count = 0, cap = 16
    cdef double wide = NEARBY_SLACK * reach
    cdef int64_t* out = <int64_t*> malloc(2 * cap * sizeof(int64_t))
    cdef int64_t* grown
    G.start = NULL
    G.item = NULL
    pairs[0] = NULL
    if out == NULL or n == 0 or m == 0 or _grid_build(xy, n, seg, m, wide, &G):
        free(G.start)
        free(G.item)
        if out != NULL and (n == 0 or m == 0):
            pairs[0] = out
            return 0
        free(out)
        return -1
    for v in range(n):
        j = (_cell(xy[2 * v + 1], G.y0, G.sy, G.g) * G.g
             + _cell(xy[2 * v], G.x0, G.sx, G.g))
        for i in range(G.start[j], G.start[j + 1]):
            if not _near_segment(xy, seg, G.item[i], v, wide):
                continue
            if count == cap:
                cap *= 2
                grown = <int64_t*> realloc(out, 2 * cap * sizeof(int64_t))
                if grown == NULL:
                    free(out)
                    free(G.start)
                    free(G.item)
                    return -1
                out = grown
            out[2 * count] = v
            out[2 * count + 1] = G.item[i]
            count += 1
    free(G.start)
    free(G.item)
    pairs[0] = out
    return count
