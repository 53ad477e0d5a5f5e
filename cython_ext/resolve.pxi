# The rounds of sampling a size callable (src/aftmesh/sizing.py's _resolve_callable),
# without the call itself: which background edges to sample, and of those whose
# samples show the background too coarse, which midpoints to insert, and their
# insertion.  The callable is called once per round between the two halves
# (resolve_rounds, _kernel.pyx, calls back into Python for it); every other step of a
# round is here, so a round costs a few passes over flat arrays instead of some
# twenty numpy calls.
#
# Edges are int64 keys a n + b (a < b), sorted, as Triangulation.edge_keys gives them.
#
# Uses: for the rounds in one call (the end of this file), triangulation.pxi
# (insert_point_near, _grow), background.pxi (finite_edge_keys, brio_order_into,
# BRIO_HILBERT_BITS).
from libc.math cimport floor, log2, ldexp, fabs, sqrt
from libc.stdlib cimport qsort, malloc, free
from libc.stdint cimport int32_t, int64_t


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


# ---------------------------------------------------------------- the rounds in one call
# resolve_rounds (_kernel.pyx) runs every round of _resolve_callable with these three
# steps between the callable's calls: the edges not yet sampled, which of them are too
# coarse, and the insertion of the kept midpoints, each on buffers kept across rounds
# (Resolve), so a round costs no numpy call but the midpoints handed to the callable.

cdef struct Resolve:
    int64_t n           # the edge keys' base: more than any vertex index of the rounds
    int64_t npass       # passed[0:npass]: the sorted keys of the edges that passed
    int64_t* passed
    int64_t* keys       # the round's edge keys (3 T.nt), then scratch for the merge
    int64_t* ring       # one vertex's neighbours (T.nv)
    int64_t* out        # the edges to sample (k), their ends (2 k) and lengths (k)
    int64_t* ends
    double* length
    int64_t* bad        # the too coarse ones (k)
    int64_t* good       # the ones that passed, then the midpoints kept (k)
    CellKey* cells      # one_per_cell's (k)
    double* u           # the size at every vertex (T.nv)
    double tolerance    # too_coarse's thresholds and one_per_cell's cell (sizing.py's
    double span         # RESOLVE_*)
    double coarsest
    double thin


cdef void resolve_free(Resolve* R) noexcept nogil:
    free(R.passed)
    free(R.keys)
    free(R.ring)
    free(R.out)
    free(R.ends)
    free(R.length)
    free(R.bad)
    free(R.good)
    free(R.cells)
    free(R.u)


cdef int64_t resolve_unsampled(Tri* T, Resolve* R) noexcept nogil:
    """The edges of T's finite triangles not in R.passed into R.out (sorted), with
    room for their ends, lengths and verdicts; returns how many, or an error."""
    cdef int64_t m, k
    if (_grow(<void**> &R.keys, (3 * T.nt + 1) * sizeof(int64_t))
            or _grow(<void**> &R.ring, (T.nv + 1) * sizeof(int64_t))):
        return ERR_NOMEM
    m = finite_edge_keys(T, R.n, R.keys, R.ring)
    if _grow(<void**> &R.out, (m + 1) * sizeof(int64_t)):
        return ERR_NOMEM
    k = keys_not_in(R.keys, m, R.passed, R.npass, R.out)
    if (_grow(<void**> &R.ends, 2 * (k + 1) * sizeof(int64_t))
            or _grow(<void**> &R.length, (k + 1) * sizeof(double))
            or _grow(<void**> &R.bad, (k + 1) * sizeof(int64_t))
            or _grow(<void**> &R.good, (k + 1) * sizeof(int64_t))
            or _grow(<void**> &R.cells, (k + 1) * sizeof(CellKey))):
        return ERR_NOMEM
    return k


cdef int64_t resolve_coarse(Resolve* R, int64_t k, const double* mid,
                            const double* um) noexcept nogil:
    """The verdicts on the k sampled edges (too_coarse): the passed ones merged into
    R.passed, the midpoints to insert (one per thinning cell) into R.good (its
    passed keys merged by then), in increasing order; returns how many, or an
    error."""
    cdef int64_t i, n_bad = 0, n_good = 0
    cdef int64_t* merged
    for i in range(k):
        if too_coarse(R.u[R.ends[2 * i]], R.u[R.ends[2 * i + 1]], um[i], R.length[i],
                      R.tolerance, R.span, R.coarsest):
            R.bad[n_bad] = i
            n_bad += 1
        else:
            R.good[n_good] = R.out[i]
            n_good += 1
    # the merge goes to R.keys (this round's edge keys are no longer needed), which
    # then becomes R.passed
    if _grow(<void**> &R.keys, (R.npass + n_good + 1) * sizeof(int64_t)):
        return ERR_NOMEM
    R.npass = merge_sorted(R.passed, R.npass, R.good, n_good, R.keys)
    merged = R.keys
    R.keys = R.passed
    R.passed = merged
    return one_per_cell(mid, R.length, R.bad, n_bad, R.thin, R.cells, R.good)


cdef int64_t resolve_finish(Tri* T, Resolve* R, int64_t k, const double* mid,
                            const double* um, const int64_t* rounds) noexcept nogil:
    """The end of a round: resolve_coarse, then resolve_insert of the midpoints kept
    (rounds: the round keys of k points, of which the kept ones take the first);
    returns how many were inserted, or an error."""
    cdef int res
    cdef int64_t n_keep = resolve_coarse(R, k, mid, um)
    if n_keep <= 0:
        return n_keep
    res = resolve_insert(T, R, mid, um, n_keep, rounds)
    return res if res < 0 else n_keep


cdef int resolve_insert(Tri* T, Resolve* R, const double* mid, const double* um,
                        int64_t n_keep, const int64_t* rounds) noexcept nogil:
    """Insert the kept midpoints R.good[0:n_keep] in their BRIO order (rounds: the
    round keys of n_keep points), each walk started at a triangle of its edge's first
    end, as Triangulation.add_points does; their sizes join R.u."""
    cdef int64_t i, j
    cdef int res = 0, nv0 = T.nv
    cdef double* xy = <double*> malloc((2 * n_keep + 1) * sizeof(double))
    cdef int64_t* keys = <int64_t*> malloc((3 * n_keep + 1) * sizeof(int64_t))
    cdef int32_t* order = <int32_t*> malloc((n_keep + 1) * sizeof(int32_t))
    if (xy == NULL or keys == NULL or order == NULL
            or _grow(<void**> &R.u, (nv0 + n_keep) * sizeof(double))):
        res = ERR_NOMEM
    else:
        for i in range(n_keep):
            xy[2 * i] = mid[2 * R.good[i]]
            xy[2 * i + 1] = mid[2 * R.good[i] + 1]
        brio_order_into(xy, rounds, n_keep, BRIO_HILBERT_BITS, keys, &keys[n_keep],
                        &keys[2 * n_keep], order)
        for i in range(n_keep):
            j = R.good[order[i]]
            res = insert_point_near(T, mid[2 * j], mid[2 * j + 1], <int> R.ends[2 * j])
            if res < 0:
                break
            R.u[nv0 + i] = um[j]
    free(xy)
    free(keys)
    free(order)
    return res if res < 0 else 0
