# The background triangulation of a size field given by numbers (no callable): the
# Delaunay triangulation of the input vertices and the box's corners in BRIO order,
# its finite triangles, and the boundary's sizes spread over its edges at the
# gradation rate, for one call of the def layer (background_field) that holds the
# GIL only to make its arrays (src/aftmesh/sizing.py, make_size_field).  The pieces
# also serve Triangulation.finite_triangles, Triangulation.edge_keys,
# limit_gradation_mesh, and with brio_order_into the BRIO order of brio_keys_order and
# of resolve.pxi's midpoints.
#
# Uses: triangulation.pxi (Tri, tri_init, insert_points), ordering.pxi
# (hilbert_keys_into), inputs.pxi (stable_order), sizing.pxi (limit_gradation_graph).
from libc.stdlib cimport malloc, free, qsort
from libc.math cimport INFINITY, isfinite

cdef enum:
    # the Hilbert grid of _order.brio_order (hilbert_keys' default): 2**16 cells a side
    BRIO_HILBERT_BITS = 16
    # finite_edge_keys sorts a vertex's neighbours in place up to this many (most have
    # about six), and with qsort beyond (a box corner can have thousands)
    KEYS_INSERTION_SORT_MAX = 32


cdef int finite_index(Tri* T, int32_t* index) noexcept nogil:
    """index[t] = the number of live finite triangle slot t among them (-1 for the
    others); returns how many there are."""
    cdef int t, n = 0
    for t in range(T.nt):
        if T.tstate[t] != T_FREE and not is_ghost(T, t):
            index[t] = n
            n += 1
        else:
            index[t] = -1
    return n


cdef void finite_into(Tri* T, const int32_t* index, int32_t* tv, int32_t* nb) noexcept nogil:
    """tv[3i + k] = vertex k of finite triangle i (counter-clockwise); nb[3i + k] = the
    finite triangle across the edge opposite vertex k, -1 at the hull."""
    cdef int t, k
    for t in range(T.nt):
        if index[t] >= 0:
            for k in range(3):
                tv[3 * index[t] + k] = T.tv[3 * t + k]
                # the edge opposite vertex k is half-edge 3t + k + 1
                nb[3 * index[t] + k] = index[T.twin[3 * t + (k + 1) % 3] // 3]


cdef inline bint _finite_live(Tri* T, int t) noexcept nogil:
    return T.tstate[t] != T_FREE and not is_ghost(T, t)


cdef int64_t finite_edge_keys(Tri* T, int64_t n, int64_t* keys,
                              int64_t* ring) noexcept nogil:
    """keys[i] = a n + b (a < b) for each edge a-b of the live finite triangles, once
    and in increasing order (keys holds 3 T.nt; ring, scratch for one vertex's
    neighbours, holds T.nv); returns how many.  Vertex by vertex, the larger ends of
    its edges sorted: the order needs no sort of the whole list."""
    cdef int a, e0, e, b, cnt, i, j
    cdef int64_t x
    cdef int64_t m = 0
    for a in range(T.nv):
        e0 = T.vhe[a]
        if e0 < 0:
            continue
        cnt = 0
        e = e0
        while True:     # each half-edge leaving a, once
            b = T.tv[nxt(e)]
            if b > a and (_finite_live(T, e // 3) or _finite_live(T, T.twin[e] // 3)):
                ring[cnt] = b
                cnt += 1
            e = T.twin[prv(e)]
            if e == e0:
                break
        if cnt > KEYS_INSERTION_SORT_MAX:
            qsort(ring, cnt, sizeof(int64_t), int64_order)
        else:
            for i in range(1, cnt):
                x = ring[i]
                j = i - 1
                while j >= 0 and ring[j] > x:
                    ring[j + 1] = ring[j]
                    j -= 1
                ring[j + 1] = x
        for i in range(cnt):
            keys[m] = a * n + ring[i]
            m += 1
    return m


cdef int int64_order(const void* p, const void* q) noexcept nogil:
    # qsort's comparison of int64 values
    cdef int64_t a = (<const int64_t*> p)[0], b = (<const int64_t*> q)[0]
    return -1 if a < b else (1 if a > b else 0)


cdef int unused_to_inf(int n, int nt, const int32_t* tv, double* g) noexcept nogil:
    """g[v] = inf at the points in no triangle (merged into an equal one, never read);
    returns 1 when g is finite at all the others, else 0 (or ERR_NOMEM)."""
    cdef int i, ok = 1
    cdef char* used = <char*> malloc(max(n, 1))
    if used == NULL:
        return ERR_NOMEM
    for i in range(n):
        used[i] = 0
    for i in range(3 * nt):
        used[tv[i]] = 1
    for i in range(n):
        if not used[i]:
            g[i] = INFINITY
        elif not isfinite(g[i]):
            ok = 0
    free(used)
    return ok


cdef int limit_gradation_tris(int nv, int nt, const double* xy, const int32_t* tv,
                              double* h, double rate, double reach) noexcept nogil:
    """limit_gradation_graph over the edges of the triangles tv (each edge seen from
    both sides); 0 or ERR_NOMEM."""
    cdef int t, k, a, b, res
    cdef int32_t* start = <int32_t*> malloc((nv + 1) * sizeof(int32_t))
    cdef int32_t* adj = <int32_t*> malloc(max(6 * nt, 1) * sizeof(int32_t))
    cdef int32_t* fill = <int32_t*> malloc(max(nv, 1) * sizeof(int32_t))
    if start == NULL or adj == NULL or fill == NULL:
        free(start)
        free(adj)
        free(fill)
        return ERR_NOMEM
    for a in range(nv + 1):
        start[a] = 0
    for t in range(nt):
        for k in range(3):
            start[tv[3 * t + k] + 1] += 2
    for a in range(nv):
        start[a + 1] += start[a]
        fill[a] = start[a]
    for t in range(nt):
        for k in range(3):
            a = tv[3 * t + k]
            b = tv[3 * t + (k + 1) % 3]
            adj[fill[a]] = b
            fill[a] += 1
            adj[fill[b]] = a
            fill[b] += 1
    res = limit_gradation_graph(nv, start, adj, xy, h, rate, reach)
    free(start)
    free(adj)
    free(fill)
    return res


cdef void brio_order_into(const double* xy, const int64_t* rounds, Py_ssize_t n,
                          int bits, int64_t* keys, int64_t* order, int64_t* work,
                          int32_t* out) noexcept nogil:
    """The BRIO order of _order.brio_order into out (n indices): each point's round
    key (rounds) over its Hilbert key (bits per coordinate), stably sorted; keys,
    order and work are n each of scratch."""
    cdef Py_ssize_t i
    hilbert_keys_into(xy, n, bits, keys)
    for i in range(n):
        keys[i] |= rounds[i]
    stable_order(keys, _key_less, n, order, work)
    for i in range(n):
        out[i] = <int32_t> order[i]


cdef int brio_insert(Tri* T, const double* xy, int n, const int64_t* rounds,
                     int32_t* merged) noexcept nogil:
    """Insert the n vertices of T (rows of xy) in the BRIO order of _order.brio_order
    (rounds | Hilbert keys, stably sorted); merged as insert_points sets it (v, or
    the earlier vertex at the same place).  Returns insert_points' code."""
    cdef int i, res
    cdef int64_t* keys = <int64_t*> malloc(n * sizeof(int64_t))
    cdef int64_t* order = <int64_t*> malloc(n * sizeof(int64_t))
    cdef int64_t* work = <int64_t*> malloc(n * sizeof(int64_t))
    cdef int32_t* order32 = <int32_t*> malloc(n * sizeof(int32_t))
    if keys == NULL or order == NULL or work == NULL or order32 == NULL:
        res = ERR_NOMEM
    else:
        brio_order_into(xy, rounds, n, BRIO_HILBERT_BITS, keys, order, work, order32)
        for i in range(n):
            merged[i] = i
        res = insert_points(T, order32, n, merged)
    free(keys)
    free(order)
    free(work)
    free(order32)
    return res
