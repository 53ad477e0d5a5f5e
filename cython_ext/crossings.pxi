# Whether two segments of an input cross at a point inside both: the check of a dict or
# .poly input (noding.refuse_crossings) before anything is split, and the proof that
# ends noding.node_crossings's rounds once no two segments cross.  Most inputs have no
# crossing, and proving that needs no triangulation: two segments that cross share a
# cell of nearby.pxi's grid (the crossing point is inside both boxes, and a box is
# registered in every cell it overlaps), so each cell's pairs are tested, by exact
# orient2d.  Only when a crossing is found does the caller build the CDT that names it
# (or noding.node_crossings split it).
#
# "Cross" is aftmesh.cdt's: the four orientations are all non-zero and opposite in
# pairs.  Segments that share an end, touch at a vertex, run through a vertex or
# overlap on one line do not cross (the CDT splits them there).
#
# Uses: nearby.pxi (_Grid, _grid_build); predicates.pxi (orient2d).
from libc.stdint cimport int64_t
from libc.stdlib cimport free

# Pair tests allowed per segment before giving up (the caller then builds the CDT, which
# decides at its own cost): a grid cell crowded with segments, such as a fan of many
# segments from one vertex, would otherwise make the test quadratic.
cdef int64_t CROSSING_PAIRS_PER_SEGMENT = 64


cdef inline bint _segments_cross(const double* xy, const int64_t* seg, int64_t k,
                                 int64_t j) noexcept nogil:
    cdef const double* a = &xy[2 * seg[2 * k]]
    cdef const double* b = &xy[2 * seg[2 * k + 1]]
    cdef const double* c = &xy[2 * seg[2 * j]]
    cdef const double* d = &xy[2 * seg[2 * j + 1]]
    cdef int o1, o2
    if (max(a[0], b[0]) < min(c[0], d[0]) or max(c[0], d[0]) < min(a[0], b[0])
            or max(a[1], b[1]) < min(c[1], d[1]) or max(c[1], d[1]) < min(a[1], b[1])):
        return False
    o1 = orient2d(a, b, c)
    o2 = orient2d(a, b, d)
    if o1 == 0 or o2 == 0 or o1 == o2:
        return False
    o1 = orient2d(c, d, a)
    o2 = orient2d(c, d, b)
    return o1 != 0 and o2 != 0 and o1 != o2


cdef int _cells_cross(const _Grid* G, const double* xy, const int64_t* seg,
                      int64_t cap) noexcept nogil:
    """any_crossing's search over the cells of G: 1, 0, or -1 past cap pair tests."""
    cdef Py_ssize_t c, i, j
    cdef int64_t tests = 0
    for c in range(G.g * G.g):
        for i in range(G.start[c], G.start[c + 1]):
            for j in range(i + 1, G.start[c + 1]):
                tests += 1
                if tests > cap:
                    return -1
                if _segments_cross(xy, seg, G.item[i], G.item[j]):
                    return 1
    return 0


cdef int any_crossing(const double* xy, Py_ssize_t n, const int64_t* seg,
                      Py_ssize_t m) noexcept nogil:
    """1 if two segments cross (see the top of this file), 0 if none do, -1 when the
    test gave up (out of memory, or more than CROSSING_PAIRS_PER_SEGMENT pair tests
    per segment)."""
    cdef _Grid G
    cdef int res = -1
    if m < 2:
        return 0
    G.start = NULL
    G.item = NULL
    if _grid_build(xy, n, seg, m, 0.0, &G) == 0:
        res = _cells_cross(&G, xy, seg, CROSSING_PAIRS_PER_SEGMENT * m)
    free(G.start)
    free(G.item)
    return res
