# Half-edge triangulation: storage, flips, point location and point insertion.
# Conventions: halfedge.pxd.  Geometry is only ever read through the predicates.
#
# Uses: halfedge.pxd (Tri, enums, nxt_nb/prv_nb, P, is_ghost, blocking); predicates.pxi
# (orient2d, incircle, surely_acute).
from halfedge cimport *
from libc.stdlib cimport malloc, realloc, free
from libc.string cimport memset

cdef enum:
    SCRATCH_INITIAL_CAP = 256   # T.stack / T.buf, grown on demand
    # locate()'s stochastic walk gives up after WALK_CAP_BASE + WALK_CAP_PER_TRIANGLE
    # * nt steps (far beyond any real walk) and scans all triangles exactly instead
    WALK_CAP_BASE = 64
    WALK_CAP_PER_TRIANGLE = 4
# any non-zero xorshift seed works; fixed so that runs are reproducible
cdef uint32_t WALK_RNG_SEED = 2463534242u


# ---------------------------------------------------------------- storage

cdef int tri_init(Tri* T, int nv_cap, int nt_cap) noexcept nogil:
    memset(T, 0, sizeof(Tri))
    if nv_cap < 8:
        nv_cap = 8
    if nt_cap < 16:
        nt_cap = 16
    T.xy = <double*> malloc(2 * nv_cap * sizeof(double))
    T.vhe = <int32_t*> malloc(nv_cap * sizeof(int32_t))
    T.nv_cap = nv_cap
    T.tv = <int32_t*> malloc(3 * nt_cap * sizeof(int32_t))
    T.twin = <int32_t*> malloc(3 * nt_cap * sizeof(int32_t))
    T.eflag = <uint8_t*> malloc(3 * nt_cap * sizeof(uint8_t))
    T.eseg = <int32_t*> malloc(3 * nt_cap * sizeof(int32_t))
    T.tstate = <uint8_t*> malloc(nt_cap * sizeof(uint8_t))
    T.tregion = <int32_t*> malloc(nt_cap * sizeof(int32_t))
    T.nt_cap = nt_cap
    T.stack_cap = SCRATCH_INITIAL_CAP
    T.stack = <int32_t*> malloc(T.stack_cap * sizeof(int32_t))
    T.buf_cap = SCRATCH_INITIAL_CAP
    T.buf = <int32_t*> malloc(T.buf_cap * sizeof(int32_t))
    T.last = NONE
    T.rng = WALK_RNG_SEED
    if (T.xy == NULL or T.vhe == NULL or T.tv == NULL or T.twin == NULL or T.eflag == NULL
            or T.eseg == NULL or T.tstate == NULL or T.tregion == NULL or T.stack == NULL
            or T.buf == NULL):
        return ERR_NOMEM
    return 0


cdef void tri_free(Tri* T) noexcept nogil:
    free(T.xy)
    free(T.vhe)
    free(T.tv)
    free(T.twin)
    free(T.eflag)
    free(T.eseg)
    free(T.tstate)
    free(T.tregion)
    free(T.stack)
    free(T.buf)
    memset(T, 0, sizeof(Tri))


cdef int _grow(void** p, size_t new_bytes) noexcept nogil:
    cdef void* q = realloc(p[0], new_bytes)
    if q == NULL:
        return ERR_NOMEM
    p[0] = q
    return 0


cdef int reserve_vertices(Tri* T, int n) noexcept nogil:
    cdef int cap = T.nv_cap
    if n <= cap:
        return 0
    while cap < n:
        cap *= 2
    if (_grow(<void**> &T.xy, 2 * cap * sizeof(double)) or
            _grow(<void**> &T.vhe, cap * sizeof(int32_t))):
        return ERR_NOMEM
    T.nv_cap = cap
    return 0


cdef int reserve_triangles(Tri* T, int n) noexcept nogil:
    cdef int cap = T.nt_cap
    if n <= cap:
        return 0
    while cap < n:
        cap *= 2
    if (_grow(<void**> &T.tv, 3 * cap * sizeof(int32_t)) or
            _grow(<void**> &T.twin, 3 * cap * sizeof(int32_t)) or
            _grow(<void**> &T.eflag, 3 * cap * sizeof(uint8_t)) or
            _grow(<void**> &T.eseg, 3 * cap * sizeof(int32_t)) or
            _grow(<void**> &T.tstate, cap * sizeof(uint8_t)) or
            _grow(<void**> &T.tregion, cap * sizeof(int32_t))):
        return ERR_NOMEM
    T.nt_cap = cap
    return 0


cdef int reserve_stack(Tri* T, int n) noexcept nogil:
    cdef int cap = T.stack_cap
    if n <= cap:
        return 0
    while cap < n:
        cap *= 2
    if _grow(<void**> &T.stack, cap * sizeof(int32_t)):
        return ERR_NOMEM
    T.stack_cap = cap
    return 0


cdef int reserve_buf(Tri* T, int n) noexcept nogil:
    cdef int cap = T.buf_cap
    if n <= cap:
        return 0
    while cap < n:
        cap *= 2
    if _grow(<void**> &T.buf, cap * sizeof(int32_t)):
        return ERR_NOMEM
    T.buf_cap = cap
    return 0


cdef int add_vertex(Tri* T, double x, double y) noexcept nogil:
    """Append a vertex (not yet connected); returns its index or ERR_NOMEM."""
    if reserve_vertices(T, T.nv + 1):
        return ERR_NOMEM
    T.xy[2 * T.nv] = x
    T.xy[2 * T.nv + 1] = y
    T.vhe[T.nv] = NONE
    T.nv += 1
    return T.nv - 1


cdef int new_triangle(Tri* T) noexcept nogil:
    """A new triangle slot; returns its index or ERR_NOMEM."""
    if reserve_triangles(T, T.nt + 1):
        return ERR_NOMEM
    T.nt += 1
    return T.nt - 1


cdef inline void set_tri(Tri* T, int t, int a, int b, int c,
                         int ta, int tb, int tc, uint8_t fa, uint8_t fb, uint8_t fc,
                         int32_t sa, int32_t sb, int32_t sc,
                         uint8_t state, int32_t region) noexcept nogil:
    """Write triangle t = (a, b, c) with outer twins ta, tb, tc (NONE: set later by the
    triangle on the other side), edge flags fa, fb, fc and segment ids sa, sb, sc;
    links the twins back."""
    cdef int e = 3 * t
    T.tv[e] = a
    T.tv[e + 1] = b
    T.tv[e + 2] = c
    T.twin[e] = ta
    T.twin[e + 1] = tb
    T.twin[e + 2] = tc
    T.eflag[e] = fa
    T.eflag[e + 1] = fb
    T.eflag[e + 2] = fc
    T.eseg[e] = sa
    T.eseg[e + 1] = sb
    T.eseg[e + 2] = sc
    if ta >= 0:
        T.twin[ta] = e
        T.eflag[ta] = fa
        T.eseg[ta] = sa
    if tb >= 0:
        T.twin[tb] = e + 1
        T.eflag[tb] = fb
        T.eseg[tb] = sb
    if tc >= 0:
        T.twin[tc] = e + 2
        T.eflag[tc] = fc
        T.eseg[tc] = sc
    if a >= 0:
        T.vhe[a] = e
    if b >= 0:
        T.vhe[b] = e + 1
    if c >= 0:
        T.vhe[c] = e + 2
    T.tstate[t] = state
    T.tregion[t] = region


cdef inline uint32_t rand_next(Tri* T) noexcept nogil:
    cdef uint32_t x = T.rng
    x ^= x << 13
    x ^= x >> 17
    x ^= x << 5
    T.rng = x
    return x


# ---------------------------------------------------------------- flips

cdef void flip(Tri* T, int e) noexcept nogil:
    """Swap the diagonal of the quadrilateral around half-edge e.

    Before: t0 = (a, b, c) with e = a->b, t1 = (b, a, d) with twin f = b->a.
    After:  t0 = (c, a, d) and t1 = (d, b, c); the new diagonal is c-d (3*t0+2 / 3*t1+2).
    The caller has checked that the quadrilateral a, d, b, c is strictly convex.

    Writes only what a flip changes (it is the commonest rewrite: tens per inserted
    vertex in a large unmeshed region).  The four outer edges keep their flags and
    segment ids, which already sit on both twins; each triangle keeps its state and
    region; vhe ends as set_tri of (c, a, d) then (d, b, c) would leave it.
    """
    cdef int t0 = e // 3
    cdef int f = T.twin[e]
    cdef int t1 = f // 3
    cdef int e1 = nxt_nb(e), e2 = prv_nb(e), f1 = nxt_nb(f), f2 = prv_nb(f)
    cdef int a = T.tv[e], b = T.tv[e1], c = T.tv[e2], d = T.tv[f2]
    cdef int te1 = T.twin[e1], te2 = T.twin[e2], tf1 = T.twin[f1], tf2 = T.twin[f2]
    cdef uint8_t ge1 = T.eflag[e1], ge2 = T.eflag[e2], gf1 = T.eflag[f1], gf2 = T.eflag[f2]
    cdef int32_t ie1 = T.eseg[e1], ie2 = T.eseg[e2], if1 = T.eseg[f1], if2 = T.eseg[f2]
    cdef int g0 = 3 * t0, g1 = 3 * t1
    # t0 = (c, a, d): c->a was e2, a->d was f1, d->c the new diagonal
    T.tv[g0] = c
    T.tv[g0 + 1] = a
    T.tv[g0 + 2] = d
    # t1 = (d, b, c): d->b was f2, b->c was e1, c->d the new diagonal
    T.tv[g1] = d
    T.tv[g1 + 1] = b
    T.tv[g1 + 2] = c
    T.twin[g0] = te2
    T.twin[g0 + 1] = tf1
    T.twin[g1] = tf2
    T.twin[g1 + 1] = te1
    # the outer twins link back; a NONE one (none in a finished triangulation) is
    # skipped, as set_tri does, rather than written through
    if te2 >= 0:
        T.twin[te2] = g0
    if tf1 >= 0:
        T.twin[tf1] = g0 + 1
    if tf2 >= 0:
        T.twin[tf2] = g1
    if te1 >= 0:
        T.twin[te1] = g1 + 1
    T.twin[g0 + 2] = g1 + 2
    T.twin[g1 + 2] = g0 + 2
    T.eflag[g0] = ge2
    T.eflag[g0 + 1] = gf1
    T.eflag[g0 + 2] = 0
    T.eflag[g1] = gf2
    T.eflag[g1 + 1] = ge1
    T.eflag[g1 + 2] = 0
    T.eseg[g0] = ie2
    T.eseg[g0 + 1] = if1
    T.eseg[g0 + 2] = -1
    T.eseg[g1] = if2
    T.eseg[g1 + 1] = ie1
    T.eseg[g1 + 2] = -1
    if a >= 0:
        T.vhe[a] = g0 + 1
    if b >= 0:
        T.vhe[b] = g1 + 1
    if c >= 0:
        T.vhe[c] = g1 + 2
    if d >= 0:
        T.vhe[d] = g1


cdef inline int in_circle_ext(Tri* T, int a, int b, int c, int d) noexcept nogil:
    """Is d strictly inside the circumcircle of triangle (a, b, c)?  Ghost triangles
    count as the open half-plane beyond their finite edge, which is what makes Lawson
    flips also maintain the convex hull; a ghost d is never inside."""
    if d == GHOST:
        return 0
    if a == GHOST:
        return orient2d(P(T, b), P(T, c), P(T, d)) > 0
    if b == GHOST:
        return orient2d(P(T, c), P(T, a), P(T, d)) > 0
    if c == GHOST:
        return orient2d(P(T, a), P(T, b), P(T, d)) > 0
    return incircle(P(T, a), P(T, b), P(T, c), P(T, d)) > 0


cdef int lawson_after_insert(Tri* T, int nstack) noexcept nogil:
    """Restore the (constrained) Delaunay property around a new vertex p.

    T.stack[0:nstack] holds half-edges opposite p (p is the apex of each); an edge is
    flipped when it is not blocking and the far apex lies inside the circumcircle."""
    cdef int e, f, t0, t1, a, b, p, d
    while nstack > 0:
        nstack -= 1
        e = T.stack[nstack]
        if blocking(T, e):
            continue
        f = T.twin[e]
        a = T.tv[e]
        b = T.tv[nxt_nb(e)]
        p = T.tv[prv_nb(e)]
        d = T.tv[prv_nb(f)]
        if in_circle_ext(T, a, b, p, d):
            t0 = e // 3
            t1 = f // 3
            flip(T, e)
            # after the flip, p = c is the apex of 3*t0+1 (a->d) and of 3*t1 (d->b)
            if reserve_stack(T, nstack + 2):
                return ERR_NOMEM
            T.stack[nstack] = 3 * t0 + 1
            T.stack[nstack + 1] = 3 * t1
            nstack += 2
    return 0


cdef inline bint illegal_meshed_edge(Tri* T, int e) noexcept nogil:
    """legalize_meshed's test: e is an unconstrained edge between two meshed triangles
    and the far apex is strictly inside the circumcircle of e's triangle.  Most
    meshed triangles are acute, and when both angles facing e are surely acute the
    far apex is strictly outside, as incircle would find: its test is skipped."""
    cdef int f = T.twin[e]
    cdef double* pa
    cdef double* pb
    cdef double* pc
    cdef double* pd
    if T.tstate[tri_of(e)] != T_MESHED or T.tstate[tri_of(f)] != T_MESHED:
        return False
    if T.eflag[e] & (E_SEGMENT | E_FIXED):
        return False
    pa = P(T, T.tv[e])
    pb = P(T, T.tv[nxt_nb(e)])
    pc = P(T, T.tv[prv_nb(e)])
    pd = P(T, T.tv[prv_nb(f)])
    if surely_acute(pa, pb, pc) and surely_acute(pb, pa, pd):
        return False
    return incircle(pa, pb, pc, pd) > 0


# Called with each triangle a flip of legalize_meshed_with made, so that a caller can
# look at the new triangles (the minimum-angle pass queues the bad ones).
ctypedef int (*flip_hook)(void* ctx, Tri* T, int t) noexcept nogil


cdef int legalize_meshed(Tri* T, int nstack) noexcept nogil:
    """Lawson flips inside the meshed region (Add_triangle): flip every unconstrained
    edge between two meshed triangles whose far apex is inside the circumcircle, until
    none is left.  T.stack[0:nstack] holds the edges that may have become illegal."""
    return legalize_meshed_with(T, nstack, NULL, NULL)


cdef int legalize_meshed_with(Tri* T, int nstack, flip_hook hook, void* ctx) noexcept nogil:
    """legalize_meshed, calling hook(ctx, T, t) (when not NULL) on both triangles of
    each flip; a non-zero return of the hook stops it and is returned."""
    cdef int e, f, t0, t1, res
    while nstack > 0:
        nstack -= 1
        e = T.stack[nstack]
        if illegal_meshed_edge(T, e):
            f = T.twin[e]
            t0 = e // 3
            t1 = f // 3
            if T.vdirty != NULL:
                T.vdirty[T.tv[e]] = V_CHANGED
                T.vdirty[T.tv[nxt_nb(e)]] = V_CHANGED
                T.vdirty[T.tv[prv_nb(e)]] = V_CHANGED
                T.vdirty[T.tv[prv_nb(f)]] = V_CHANGED
            flip(T, e)
            if hook != NULL:
                res = hook(ctx, T, t0)
                if res == 0:
                    res = hook(ctx, T, t1)
                if res != 0:
                    return res
            if reserve_stack(T, nstack + 4):
                return ERR_NOMEM
            # the four outer edges of the new pair may now be illegal
            T.stack[nstack] = 3 * t0
            T.stack[nstack + 1] = 3 * t0 + 1
            T.stack[nstack + 2] = 3 * t1
            T.stack[nstack + 3] = 3 * t1 + 1
            nstack += 4
    return 0


# ---------------------------------------------------------------- point location

cdef int find_live_finite(Tri* T) noexcept nogil:
    cdef int t
    for t in range(T.nt):
        if T.tstate[t] != T_FREE and not is_ghost(T, t):
            return t
    return NONE


cdef int classify(Tri* T, int t, int* o3, int* where) noexcept nogil:
    """p is in closed triangle t with orientations o3 against its three edges (none
    negative): say whether it is inside, on an edge, or on a vertex."""
    cdef int k, nzero = 0, zk = 0
    for k in range(3):
        if o3[k] == 0:
            nzero += 1
            zk = k
    if nzero == 0:
        where[0] = t
        return LOC_IN_TRIANGLE
    if nzero == 1:
        where[0] = 3 * t + zk
        return LOC_ON_EDGE
    # two zero orientations: p is the vertex opposite the one non-zero edge
    for k in range(3):
        if o3[k] != 0:
            where[0] = T.tv[3 * t + (k + 2) % 3]
            return LOC_ON_VERTEX
    return ERR_INTERNAL


cdef int locate_scan(Tri* T, const double* p, int* where) noexcept nogil:
    """The safe fallback of locate(): test every triangle exactly."""
    cdef int t, k, e
    cdef int o3[3]
    for t in range(T.nt):
        if T.tstate[t] == T_FREE or is_ghost(T, t):
            continue
        for k in range(3):
            e = 3 * t + k
            o3[k] = orient2d(P(T, T.tv[e]), P(T, T.tv[nxt_nb(e)]), p)
            if o3[k] < 0:
                break
        else:
            return classify(T, t, o3, where)
    for t in range(T.nt):
        if T.tstate[t] == T_FREE or not is_ghost(T, t):
            continue
        for k in range(3):
            e = 3 * t + k
            if T.tv[e] != GHOST and T.tv[nxt_nb(e)] != GHOST:
                if orient2d(P(T, T.tv[e]), P(T, T.tv[nxt_nb(e)]), p) > 0:
                    where[0] = t
                    return LOC_OUTSIDE
    return ERR_INTERNAL


cdef int locate(Tri* T, const double* p, int start, int* where) noexcept nogil:
    """Find where point p lies, walking from triangle `start` (or T.last).

    Returns LOC_IN_TRIANGLE (where = triangle), LOC_ON_EDGE (where = half-edge),
    LOC_ON_VERTEX (where = vertex) or LOC_OUTSIDE (where = ghost triangle whose finite
    edge sees p strictly on its outer side).  The walk visits edges in a random order
    (so it cannot cycle forever on a constrained triangulation) and is capped; past the
    cap it falls back to an exact scan of all triangles."""
    cdef int t = start if start >= 0 else T.last
    cdef int steps = 0, cap = WALK_CAP_BASE + WALK_CAP_PER_TRIANGLE * T.nt
    cdef int k, i, e, r
    cdef int o3[3]
    if t < 0 or t >= T.nt or T.tstate[t] == T_FREE:
        t = find_live_finite(T)
        if t < 0:
            return ERR_INTERNAL
    if is_ghost(T, t):
        # step into the finite triangle behind the ghost's finite edge
        for k in range(3):
            e = 3 * t + k
            if T.tv[e] != GHOST and T.tv[nxt_nb(e)] != GHOST:
                if orient2d(P(T, T.tv[e]), P(T, T.tv[nxt_nb(e)]), p) > 0:
                    where[0] = t
                    return LOC_OUTSIDE
                t = T.twin[e] // 3
                break
    while steps < cap:
        steps += 1
        r = <int> (rand_next(T) % 3)
        for i in range(3):
            k = (r + i) % 3
            e = 3 * t + k
            o3[k] = orient2d(P(T, T.tv[e]), P(T, T.tv[nxt_nb(e)]), p)
            if o3[k] < 0:
                t = T.twin[e] // 3
                if is_ghost(T, t):
                    where[0] = t
                    T.last = e // 3
                    return LOC_OUTSIDE
                break
        else:
            T.last = t
            return classify(T, t, o3, where)
    return locate_scan(T, p, where)


# ---------------------------------------------------------------- point insertion

cdef int split_triangle(Tri* T, int t, int v) noexcept nogil:
    """Insert vertex v inside triangle t (a ghost triangle too: v beyond its finite
    edge); pushes the three edges opposite v onto T.stack.  Returns the stack size."""
    cdef int e = 3 * t
    cdef int a = T.tv[e], b = T.tv[e + 1], c = T.tv[e + 2]
    cdef int tw0 = T.twin[e], tw1 = T.twin[e + 1], tw2 = T.twin[e + 2]
    cdef uint8_t f0 = T.eflag[e], f1 = T.eflag[e + 1], f2 = T.eflag[e + 2]
    cdef int32_t i0 = T.eseg[e], i1 = T.eseg[e + 1], i2 = T.eseg[e + 2]
    cdef uint8_t s = T.tstate[t]
    cdef int32_t r = T.tregion[t]
    cdef int t1 = new_triangle(T)
    if t1 < 0:
        return ERR_NOMEM
    cdef int t2 = new_triangle(T)
    if t2 < 0:
        return ERR_NOMEM
    set_tri(T, t, a, b, v, tw0, NONE, NONE, f0, 0, 0, i0, -1, -1, s, r)
    set_tri(T, t1, b, c, v, tw1, NONE, 3 * t + 1, f1, 0, 0, i1, -1, -1, s, r)
    set_tri(T, t2, c, a, v, tw2, 3 * t + 2, 3 * t1 + 1, f2, 0, 0, i2, -1, -1, s, r)
    if reserve_stack(T, 3):
        return ERR_NOMEM
    T.stack[0] = 3 * t
    T.stack[1] = 3 * t1
    T.stack[2] = 3 * t2
    if not is_ghost(T, t):
        T.last = t
    return 3


cdef int split_edge(Tri* T, int e, int v) noexcept nogil:
    """Insert vertex v on the interior of the edge of half-edge e (a->b, in t0 = (a,b,c);
    twin in t1 = (b,a,d)); the two halves keep the edge's flags (a split segment stays
    a segment).  Pushes the four edges opposite v; returns the stack size."""
    cdef int f = T.twin[e]
    cdef int t0 = e // 3, t1 = f // 3
    cdef int e1 = nxt_nb(e), e2 = prv_nb(e), f1 = nxt_nb(f), f2 = prv_nb(f)
    cdef int a = T.tv[e], b = T.tv[e1], c = T.tv[e2], d = T.tv[f2]
    cdef int te1 = T.twin[e1], te2 = T.twin[e2], tf1 = T.twin[f1], tf2 = T.twin[f2]
    cdef uint8_t ge1 = T.eflag[e1], ge2 = T.eflag[e2], gf1 = T.eflag[f1], gf2 = T.eflag[f2]
    cdef int32_t ie1 = T.eseg[e1], ie2 = T.eseg[e2], if1 = T.eseg[f1], if2 = T.eseg[f2]
    cdef uint8_t g = T.eflag[e]
    cdef int32_t ig = T.eseg[e]     # both halves stay pieces of the same segment
    cdef uint8_t s0 = T.tstate[t0], s1 = T.tstate[t1]
    cdef int32_t r0 = T.tregion[t0], r1 = T.tregion[t1]
    cdef int t2 = new_triangle(T)
    if t2 < 0:
        return ERR_NOMEM
    cdef int t3 = new_triangle(T)
    if t3 < 0:
        return ERR_NOMEM
    # (b, c, v) (c, a, v) on t0's side; (a, d, v) (d, b, v) on t1's side
    set_tri(T, t0, b, c, v, te1, NONE, NONE, ge1, 0, g, ie1, -1, ig, s0, r0)
    set_tri(T, t2, c, a, v, te2, NONE, 3 * t0 + 1, ge2, g, 0, ie2, ig, -1, s0, r0)
    set_tri(T, t1, a, d, v, tf1, NONE, 3 * t2 + 1, gf1, 0, g, if1, -1, ig, s1, r1)
    set_tri(T, t3, d, b, v, tf2, 3 * t0 + 2, 3 * t1 + 1, gf2, g, 0, if2, ig, -1, s1, r1)
    if reserve_stack(T, 4):
        return ERR_NOMEM
    T.stack[0] = 3 * t0
    T.stack[1] = 3 * t2
    T.stack[2] = 3 * t1
    T.stack[3] = 3 * t3
    if not is_ghost(T, t0):
        T.last = t0
    return 4


cdef int insert_vertex_at(Tri* T, int v, int loc, int where) noexcept nogil:
    """Insert vertex v at a place found by locate() and restore the CDT by flips."""
    cdef int n
    if loc == LOC_IN_TRIANGLE or loc == LOC_OUTSIDE:
        n = split_triangle(T, where, v)
    elif loc == LOC_ON_EDGE:
        n = split_edge(T, where, v)
    else:
        return ERR_INTERNAL
    if n < 0:
        return n
    return lawson_after_insert(T, n)


cdef int insert_vertex(Tri* T, int v, int start) noexcept nogil:
    """Insert existing vertex v into the triangulation.  Returns v, or the index of an
    existing vertex at the same place (v is then left unconnected), or an error."""
    cdef int where = NONE
    cdef int loc = locate(T, P(T, v), start, &where)
    if loc < 0:
        return loc
    if loc == LOC_ON_VERTEX:
        return where
    cdef int res = insert_vertex_at(T, v, loc, where)
    if res < 0:
        return res
    return v


cdef int insert_point_near(Tri* T, double x, double y, int near) noexcept nogil:
    """Append (x, y) as a vertex and insert it, its walk started at a triangle of
    vertex `near` (a point close to it is then found in a few steps; NONE, or a vertex
    in no triangle: locate's default start).  Returns insert_vertex's result."""
    cdef int start = NONE, v
    if 0 <= near < T.nv and T.vhe[near] >= 0:
        start = tri_of(T.vhe[near])
    v = add_vertex(T, x, y)
    return v if v < 0 else insert_vertex(T, v, start)

cdef int make_first_triangle(Tri* T, int a, int b, int c) noexcept nogil:
    """Start the triangulation with the non-degenerate triangle (a, b, c) and its three
    ghost triangles (a, b, c are put in counter-clockwise order here)."""
    cdef int t, g0, g1, g2, tmp
    if orient2d(P(T, a), P(T, b), P(T, c)) < 0:
        tmp = b
        b = c
        c = tmp
    t = new_triangle(T)
    g0 = new_triangle(T)
    g1 = new_triangle(T)
    g2 = new_triangle(T)
    if t < 0 or g0 < 0 or g1 < 0 or g2 < 0:
        return ERR_NOMEM
    # ghost gk sits across edge k of t: (b, a, G), (c, b, G), (a, c, G)
    set_tri(T, t, a, b, c, NONE, NONE, NONE, 0, 0, 0, -1, -1, -1, T_UNMESHED, 0)
    set_tri(T, g0, b, a, GHOST, 3 * t, NONE, NONE, 0, 0, 0, -1, -1, -1, T_UNMESHED, 0)
    set_tri(T, g1, c, b, GHOST, 3 * t + 1, 3 * g0 + 2, NONE, 0, 0, 0, -1, -1, -1,
            T_UNMESHED, 0)
    set_tri(T, g2, a, c, GHOST, 3 * t + 2, 3 * g1 + 2, 3 * g0 + 1, 0, 0, 0, -1, -1, -1,
            T_UNMESHED, 0)
    T.last = t
    return 0


cdef int find_edge(Tri* T, int a, int b) noexcept nogil:
    """The half-edge a->b, or NONE.  Rotates around a (counter-clockwise)."""
    cdef int e0 = T.vhe[a]
    cdef int e = e0
    cdef int guard = 0
    if e0 < 0:
        return NONE
    while True:
        if T.tv[nxt_nb(e)] == b:
            return e
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0 or guard > T.nt * 3 + 3:
            return NONE


cdef int insert_points(Tri* T, const int32_t* order, int m, int32_t* merged) noexcept nogil:
    """Start the triangulation and insert the vertices order[0..m) in that order (a
    spatially coherent order keeps the walks short).  merged[v] gets the vertex at
    exactly the same place that v was merged into (it is left as is for the inserted
    vertices).  Returns 0, ERR_COLLINEAR when all the points lie on one line, or an
    error."""
    cdef int i, v, first, second = NONE, third = NONE, res, pos
    # a non-degenerate first triangle: the first point, the next distinct one, and the
    # next one off their line
    first = order[0]
    for i in range(1, m):
        v = order[i]
        if T.xy[2 * v] != T.xy[2 * first] or T.xy[2 * v + 1] != T.xy[2 * first + 1]:
            if second == NONE:
                second = v
            elif orient2d(P(T, first), P(T, second), P(T, v)) != 0:
                third = v
                break
    if third == NONE:
        return ERR_COLLINEAR
    res = make_first_triangle(T, first, second, third)
    if res < 0:
        return res
    for i in range(m):
        v = order[i]
        if v == first or v == second or v == third:
            continue
        pos = insert_vertex(T, v, NONE)
        if pos < 0:
            return pos
        merged[v] = pos
    return 0
