# One round of sampling a size callable (src/aftmesh/sizing.py's _resolve_callable),
# without the call itself: which background edges to sample, and of those whose
# samples show the background too coarse, which midpoints to insert.  Python calls the
# callable once per round between the two; every other step of a round is here, so a
# round costs a few passes over flat arrays instead of some twenty numpy calls.
#
# Edges are int64 keys a n + b (a < b), sorted, as Triangulation.edge_keys gives them.
#
# Uses: nothing else of the kernel.
from libc.math cimport floor, log2, ldexp, fabs, sqrt
from libc.stdlib cimport qsort
from libc.stdint cimport int64_t


cdef int64_t keys_not_in(const int64_t* keys, int64_t m, const int64_t* passed, int64_t npass,
                         int64_t* out) noexcept nogil:
    """The sorted keys that are not in the sorted array passed, into out, in order;
    returns how many."""
    cdef int64_t i, j = 0, k = 0
    for i in range(m):
        while j < npass and passed[j] < keys[i]:
            j += 1
        if j < npass and passed[j] == keys[i]:
            continue
        out[k] = keys[i]
        k += 1
    return k


cdef void edge_geometry(const double* xy, const int64_t* keys, int64_t m, int64_t n,
                        int64_t* ends, double* mid, double* length) noexcept nogil:
    """Each edge's ends (a, b), midpoint 0.5 (a + b) and length |b - a|, rounded as
    numpy's 0.5 * (a + b) and linalg.norm(b - a, axis=1) round them."""
    cdef int64_t i, a, b
    cdef double dx, dy
    for i in range(m):
        a = keys[i] // n
        b = keys[i] % n
        ends[2 * i] = a
        ends[2 * i + 1] = b
        mid[2 * i] = 0.5 * (xy[2 * a] + xy[2 * b])
        mid[2 * i + 1] = 0.5 * (xy[2 * a + 1] + xy[2 * b + 1])
        dx = xy[2 * b] - xy[2 * a]
        dy = xy[2 * b + 1] - xy[2 * a + 1]
        length[i] = sqrt(dx * dx + dy * dy)


cdef int64_t merge_sorted(const int64_t* a, int64_t na, const int64_t* b, int64_t nb,
                          int64_t* out) noexcept nogil:
    """The sorted union of two sorted arrays without common entries; returns its
    length (na + nb)."""
    cdef int64_t i = 0, j = 0, k = 0
    while i < na and j < nb:
        if a[i] <= b[j]:
            out[k] = a[i]
            i += 1
        else:
            out[k] = b[j]
            j += 1
        k += 1
    while i < na:
        out[k] = a[i]
        i += 1
        k += 1
    while j < nb:
        out[k] = b[j]
        j += 1
        k += 1
    return k


cdef struct CellKey:
    # a midpoint's thinning cell: its length's octave, then the cell's column and row
    double level, ix, iy
    int64_t index       # the midpoint's place in at (increasing): first wins a tie


cdef int _cell_order(const void* p, const void* q) noexcept nogil:
    cdef const CellKey* a = <const CellKey*> p
    cdef const CellKey* b = <const CellKey*> q
    if a.level != b.level:
        return -1 if a.level < b.level else 1
    if a.ix != b.ix:
        return -1 if a.ix < b.ix else 1
    if a.iy != b.iy:
        return -1 if a.iy < b.iy else 1
    return -1 if a.index < b.index else (1 if a.index > b.index else 0)


cdef int64_t one_per_cell(const double* mid, const double* length, const int64_t* at,
                          int64_t m, double thin, CellKey* cells, int64_t* out) noexcept nogil:
    """Of the midpoints at[0..m) (increasing), the first in each square cell of side
    thin 2**k, k = floor(log2(length)), among those of the same k; the cells are
    counted from the smallest coordinates of the m midpoints.  The kept indices go to
    out (m entries, not at) in increasing order; returns how many.  cells holds m
    entries."""
    cdef int64_t i, j, kept = 0
    cdef double lowx, lowy, cell
    if m == 0:
        return 0
    lowx = mid[2 * at[0]]
    lowy = mid[2 * at[0] + 1]
    for i in range(1, m):
        lowx = mid[2 * at[i]] if mid[2 * at[i]] < lowx else lowx
        lowy = mid[2 * at[i] + 1] if mid[2 * at[i] + 1] < lowy else lowy
    for i in range(m):
        j = at[i]
        cells[i].level = floor(log2(length[j]))
        cell = thin * ldexp(1.0, <int> cells[i].level)
        cells[i].ix = floor((mid[2 * j] - lowx) / cell)
        cells[i].iy = floor((mid[2 * j + 1] - lowy) / cell)
        cells[i].index = i
    qsort(cells, m, sizeof(CellKey), _cell_order)
    # out[i] first flags whether at[i] leads its cell, then the flagged are packed in
    # place, in at's order (no second sort)
    for i in range(m):
        out[i] = 0
    for i in range(m):
        if (i == 0 or cells[i].level != cells[i - 1].level or cells[i].ix != cells[i - 1].ix
                or cells[i].iy != cells[i - 1].iy):
            out[cells[i].index] = 1
    for i in range(m):
        if out[i]:
            out[kept] = at[i]
            kept += 1
    return kept


cdef bint too_coarse(double ua, double ub, double um, double length, double tolerance,
                     double span, double coarsest) noexcept nogil:
    """An edge to split: interpolating between its ends' sizes misses the sample at its
    midpoint by more than tolerance while it is longer than span sizes, or it is
    longer than coarsest sizes (sizing.py's RESOLVE_* say why)."""
    cdef bint miss = fabs(0.5 * (ua + ub) - um) > tolerance * um
    return (miss and length > span * um) or length > coarsest * um
