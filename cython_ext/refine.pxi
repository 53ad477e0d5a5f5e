# The minimum-angle pass: Delaunay refinement of the final mesh (Ruppert, Shewchuk).
#
# Every meshed triangle whose smallest angle is below the bound gets a new vertex at
# its off-centre (Üngör: on the bisector of its shortest edge, no farther than the
# circumcentre, where the new triangle on that edge just meets the bound), inserted
# with Lawson flips that respect the constrained edges, so the mesh stays the CDT of
# its vertices and the input edges.  A candidate that lies across a segment (seen
# from the triangle) or inside a segment's diametral circle is not inserted: the
# segment is split instead, and the triangle tried again.  Splits keep the edge flags
# (split_edge) and the states and regions of both sides.
#
# Small input angles.  Two input segments ("chains": the pieces between input
# vertices) meeting at an apex at an angle below the bound force bad triangles between
# them.  Such a triangle, recognised by its shortest edge joining two different chains
# with a common end seen from it at an angle below the bound (Miller, Pav and
# Walkington's rule), is left alone and reported as excepted.  Splits of a chain that
# meets another one at an apex below 60 degrees are put at dyadic distances from the
# apex (concentric shells), so neighbouring chains are split at the same radii and do
# not encroach each other forever.
#
# Settling (refine_settled, with smoothing on).  The pass places its points by the
# bound alone: segment splits at the middle of a piece or on the shells, off-centres
# just good enough.  Splits on the two sides of a narrow wedge or channel come at the
# same radii, so the ladder between them is of nearly right triangles (radius ratio
# about 0.83) where points out of step would make nearly equilateral ones.  So after
# the pass, the vertices around its new ones get REFINE_SETTLE_ROUNDS smoothing rounds
# (the chain points sliding along their segments), which mend most of that, and the
# pass runs again for whatever the moves left below the bound (they never lower the
# worst shape around a vertex, but a shape is not an angle).  The second run is the
# same capped pass, so the final mesh meets the bound as before, and is the CDT of its
# vertices and the input edges (the moves end with Lawson flips).
#
# Termination: in exact arithmetic, Ruppert's argument with these two rules bounds the
# insertions for bounds up to about 26.5 degrees (and in practice to about 33.8).  In
# floating point the pass is also capped: no work on edges shorter, or triangles
# thinner, than REFINE_TINY_ULPS units in the last place of the coordinates, at most
# max_triangles triangles (formula (4) wins over the bound), and at most
# REFINE_CAP_PER_TRIANGLE insertions per triangle of the mesh it started from.  Each
# loop step inserts a vertex or consumes a queue entry, so the loop is finite.

#
# Uses: halfedge.pxd; aft.pxd (Aft); predicates.pxi (orient2d, incircle);
# triangulation.pxi (split_triangle, split_edge, find_edge, locate, Lawson flips,
# legalize_meshed_with).
from halfedge cimport *
from aft cimport Aft
from libc.math cimport fabs, ldexp, frexp, ceil

cdef enum:
    # why the pass stopped before the queue was empty
    STOP_NONE = 0
    STOP_MAX_TRIANGLES = 1
    STOP_CAP = 2
    # results of one refinement action
    ACT_DROPPED = 0     # nothing could be done for this entry
    ACT_INSERTED = 1    # a vertex was inserted at the candidate
    ACT_SPLIT = 2       # segments in the way were split; the triangle is tried again
    # results of the walk toward a candidate
    WALK_FOUND = 0
    WALK_BLOCKED = 1
    WALK_FAILED = 2

# A float bad-angle test errs by a few 1e-16; triangles within this relative margin of
# the bound count as bad, so every triangle left unrefined is good in exact arithmetic.
cdef double REFINE_ANGLE_MARGIN = 1e-12
# Edges shorter, and triangles thinner, than this many ulps of the largest coordinate
# are not refined: a point placed between their ends is mostly rounding.
cdef double REFINE_TINY_ULPS = 4096.0
# Last-resort guard: insertions per triangle of the mesh the pass started from (Ruppert's
# bound is proportional to the mesh size; this is far above what it inserts in practice).
cdef int64_t REFINE_CAP_PER_TRIANGLE = 8
cdef int64_t REFINE_CAP_MIN = 100000
# Off-centre distance as a fraction of the one that makes the new triangle's apex angle
# exactly the bound (a little closer: the new triangle is then strictly good).
cdef double OFFCENTRE_FACTOR = 0.95
# Concentric shells at apexes where two segments meet below this cosine (60 degrees,
# the smallest input angle Ruppert's proof covers without them).
cdef double SHELL_COS = 0.5
# A split point may be moved this many ulps off its segment (beyond the rounding of
# the point itself) to keep the triangles next to it counter-clockwise.
cdef int SPLIT_NUDGE_ULPS = 1
# Places in the middle half of a piece tried for its split when the first ones would
# invert a sliver (slivers are thicker at some places than at others).
cdef int SPLIT_TRIES = 32
# Rotations around one vertex are capped by this many triangles (a broken structure
# would otherwise loop).
cdef int ROTATION_CAP = 1 << 20
# Smoothing rounds around the pass's new vertices before it runs again (with smoothing
# on; never more than the user's rounds): on the real-world group of the benchmarks,
# 1 / 2 / 3 rounds took the triangles of radius ratio <= 0.9 from 52,364 to
# 48,086 / 47,386 / 47,253 and the mean radius ratio from 0.9674 to 0.9685 / 0.9686 /
# 0.9687, each round costing about as much as the last
cdef int REFINE_SETTLE_ROUNDS = 2


cdef struct Refine:
    double c2_bad           # cos^2 of the bound, lowered by the margin: bad above it
    double c2_small         # cos^2 of the bound, raised by the margin: a small input angle
    double offcentre        # off-centre distance / shortest edge length
    double tiny
    bint split_segments
    int n_corner            # vertices below this index are input vertices (chain ends)
    int64_t max_triangles, n_meshed, max_insert
    int64_t inserted, interior, splits, dropped, excepted, unresolved
    int stop
    int32_t* vend           # 2 per vertex: the ends of the chain it is inside, or -1
    int vend_cap
    int32_t* tq             # FIFO of (t, a, b, c)
    int64_t tq_head, tq_n, tq_cap
    int32_t* sq             # stack of segments (u, w) to split
    int sq_n, sq_cap
    int32_t* cav            # cavity triangles of a candidate
    int cav_cap
    int32_t* enc            # segments a candidate encroaches
    int enc_n, enc_cap
    uint32_t* mark          # per triangle slot: epoch of the last cavity search
    int mark_cap
    uint32_t epoch


cdef void refine_free(Refine* R) noexcept nogil:
    free(R.vend)
    free(R.tq)
    free(R.sq)
    free(R.cav)
    free(R.enc)
    free(R.mark)
    R.vend = NULL
    R.tq = NULL
    R.sq = NULL
    R.cav = NULL
    R.enc = NULL
    R.mark = NULL


cdef int _grow_i32(int32_t** p, int* cap, int n) noexcept nogil:
    """Make p hold n int32 (contents kept, new entries unset)."""
    cdef int c = cap[0] if cap[0] > 0 else 64
    if n <= cap[0]:
        return 0
    while c < n:
        c *= 2
    if _grow(<void**> p, c * sizeof(int32_t)):
        return ERR_NOMEM
    cap[0] = c
    return 0


cdef int _vend_reserve(Refine* R, int nv) noexcept nogil:
    cdef int old = R.vend_cap, i
    if _grow_i32(&R.vend, &R.vend_cap, 2 * nv):
        return ERR_NOMEM
    for i in range(old, R.vend_cap):
        R.vend[i] = NONE
    return 0


# ---------------------------------------------------------------- angles

cdef inline double _d2(const double* a, const double* b) noexcept nogil:
    return (b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1])


cdef inline bint _angle_below(const double* a, const double* p, const double* q,
                              double c2) noexcept nogil:
    """Whether the angle at a between a->p and a->q has cos^2 above c2 and is acute."""
    cdef double ux = p[0] - a[0], uy = p[1] - a[1], vx = q[0] - a[0], vy = q[1] - a[1]
    cdef double dot = ux * vx + uy * vy
    return dot > 0 and dot * dot > c2 * (ux * ux + uy * uy) * (vx * vx + vy * vy)


cdef bint _points_bad(Refine* R, const double* a, const double* b,
                      const double* c) noexcept nogil:
    """Whether the triangle a, b, c has an angle below the bound (at the corner
    opposite its shortest side)."""
    cdef double ab = _d2(a, b), bc = _d2(b, c), ca = _d2(c, a)
    if ab <= bc and ab <= ca:
        return _angle_below(c, a, b, R.c2_bad)
    if bc <= ca:
        return _angle_below(a, b, c, R.c2_bad)
    return _angle_below(b, c, a, R.c2_bad)


cdef inline int _bad_edge(Refine* R, Tri* T, int t) noexcept nogil:
    """The shortest half-edge of triangle t (the first of equal ones) when the angle
    opposite it is below the bound (_angle_below at that corner), else NONE, from
    one load of the three points.  With D_k the vector along edge k, the corner's
    sides are D_(k+2) and -D_(k+1): negating is exact and so are the products'
    signs, so every value is _angle_below's (the scans run over every triangle, up
    to four times a call)."""
    cdef const double* p0 = P(T, T.tv[3 * t])
    cdef const double* p1 = P(T, T.tv[3 * t + 1])
    cdef const double* p2 = P(T, T.tv[3 * t + 2])
    cdef double x[3]
    cdef double y[3]
    cdef double d[3]
    cdef double dot
    cdef int k, a, b
    x[0] = p1[0] - p0[0]
    y[0] = p1[1] - p0[1]
    x[1] = p2[0] - p1[0]
    y[1] = p2[1] - p1[1]
    x[2] = p0[0] - p2[0]
    y[2] = p0[1] - p2[1]
    for k in range(3):
        d[k] = x[k] * x[k] + y[k] * y[k]
    k = 0
    if d[1] < d[0]:
        k = 2 if d[2] < d[1] else 1
    elif d[2] < d[0]:
        k = 2
    a = (k + 2) % 3
    b = (k + 1) % 3
    dot = x[a] * x[b] + y[a] * y[b]
    return 3 * t + k if dot < 0 and dot * dot > R.c2_bad * d[a] * d[b] else NONE


cdef inline bint _is_bad(Refine* R, Tri* T, int t) noexcept nogil:
    return _bad_edge(R, T, t) != NONE


# ---------------------------------------------------------------- queues

cdef int _push_tri(Refine* R, Tri* T, int t) noexcept nogil:
    """Queue triangle t if it is meshed and bad; 0 or ERR_NOMEM."""
    if T.tstate[t] != T_MESHED or not _is_bad(R, T, t):
        return 0
    return _enqueue_tri(R, T, t)


cdef int _enqueue_tri(Refine* R, Tri* T, int t) noexcept nogil:
    """Queue triangle t (with its vertices, so that _pop_tri can tell whether it
    still exists); 0 or ERR_NOMEM."""
    cdef int64_t i, n
    if R.tq_head + R.tq_n + 1 > R.tq_cap:
        if R.tq_head > 0:           # slide the live entries to the front
            for i in range(4 * R.tq_n):
                R.tq[i] = R.tq[4 * R.tq_head + i]
            R.tq_head = 0
        if R.tq_n + 1 > R.tq_cap:
            n = 2 * R.tq_cap if R.tq_cap > 0 else 1024
            if _grow(<void**> &R.tq, 4 * n * sizeof(int32_t)):
                return ERR_NOMEM
            R.tq_cap = n
    i = 4 * (R.tq_head + R.tq_n)
    R.tq[i] = t
    R.tq[i + 1] = T.tv[3 * t]
    R.tq[i + 2] = T.tv[3 * t + 1]
    R.tq[i + 3] = T.tv[3 * t + 2]
    R.tq_n += 1
    return 0


cdef int _pop_tri(Refine* R, Tri* T) noexcept nogil:
    """The next queued triangle that still exists, or NONE."""
    cdef int64_t i
    cdef int t
    while R.tq_n > 0:
        i = 4 * R.tq_head
        R.tq_head += 1
        R.tq_n -= 1
        t = R.tq[i]
        if (T.tstate[t] == T_MESHED and T.tv[3 * t] == R.tq[i + 1]
                and T.tv[3 * t + 1] == R.tq[i + 2] and T.tv[3 * t + 2] == R.tq[i + 3]):
            return t
    return NONE


cdef int _push_seg(Refine* R, int u, int w) noexcept nogil:
    if _grow_i32(&R.sq, &R.sq_cap, 2 * R.sq_n + 2):
        return ERR_NOMEM
    R.sq[2 * R.sq_n] = u
    R.sq[2 * R.sq_n + 1] = w
    R.sq_n += 1
    return 0


cdef int _push_star(Refine* R, Tri* T, int v) noexcept nogil:
    """Queue the bad triangles around vertex v (all those an insertion at v made)."""
    cdef int e0 = T.vhe[v], e = e0, guard = 0
    while True:
        if _push_tri(R, T, e // 3):
            return ERR_NOMEM
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0:
            return 0
        if guard > ROTATION_CAP:
            return ERR_INTERNAL


cdef inline bint _encroaches(const double* x, const double* a, const double* b) noexcept nogil:
    """x strictly inside the circle with diameter a-b."""
    return (x[0] - a[0]) * (x[0] - b[0]) + (x[1] - a[1]) * (x[1] - b[1]) < 0


cdef int _queue_encroached_near(Refine* R, Tri* T, int v) noexcept nogil:
    """After v was put on a segment: queue the segments around v that a vertex
    encroaches (the two halves by their apexes, the far edges of v's star by v), but
    not a piece encroached by a vertex on another chain meeting it at a small angle:
    near an apex a few ulps wide every split would encroach the other chain again.
    Nor in a triangle below the resolution (_below_resolution): across a gap thinner
    than that, each split would encroach the other side again until the cap."""
    cdef int e0 = T.vhe[v], e = e0, f, g, guard = 0, k
    while True:
        if T.tstate[e // 3] == T_MESHED and not _below_resolution(R, T, e // 3):
            f = nxt_nb(e)                  # the edge of v's triangle opposite v
            if (T.eflag[f] & E_SEGMENT) and _encroaches(
                    P(T, v), P(T, T.tv[f]), P(T, T.tv[nxt_nb(f)])) and not _across_apex(
                    R, T, v, T.tv[f], T.tv[nxt_nb(f)]):
                if _push_seg(R, T.tv[f], T.tv[nxt_nb(f)]):
                    return ERR_NOMEM
            for k in range(2):
                g = e if k == 0 else prv_nb(e)     # the two edges of this triangle at v
                if (T.eflag[g] & E_SEGMENT) and _encroaches(
                        P(T, T.tv[prv_nb(g)]), P(T, T.tv[g]), P(T, T.tv[nxt_nb(g)])) and not \
                        _across_apex(R, T, T.tv[prv_nb(g)], T.tv[g], T.tv[nxt_nb(g)]):
                    if _push_seg(R, T.tv[g], T.tv[nxt_nb(g)]):
                        return ERR_NOMEM
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0:
            return 0
        if guard > ROTATION_CAP:
            return ERR_INTERNAL


# ---------------------------------------------------------------- chains

cdef int _chain_init(Refine* R, Tri* T) noexcept nogil:
    """R.vend for every vertex of T (chains.pxi's chain_ends); the pass keeps it for
    the points it adds, and moves along a chain keep it too, so a second run of the
    pass on the same R finds it set (vend is NULL until this first runs)."""
    if _vend_reserve(R, T.nv):
        return ERR_NOMEM
    return chain_ends(T, R.n_corner, R.vend)


cdef int _chains_of(Refine* R, Tri* T, int p, int32_t* out, int cap) noexcept nogil:
    """The chains p lies on, as (end, end) pairs in out; returns how many."""
    cdef int e0, e, w, other, n = 0, guard = 0
    if R.vend[2 * p] >= 0:
        out[0] = R.vend[2 * p]
        out[1] = R.vend[2 * p + 1]
        return 1
    e0 = T.vhe[p]
    if e0 < 0:
        return 0
    e = e0
    while n < cap:
        if T.eflag[e] & E_SEGMENT:
            w = T.tv[nxt_nb(e)]
            other = w
            if R.vend[2 * w] >= 0:
                other = R.vend[2 * w + 1] if R.vend[2 * w] == p else R.vend[2 * w]
            out[2 * n] = p
            out[2 * n + 1] = other
            n += 1
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0 or guard > ROTATION_CAP:
            break
    return n


cdef bint _same_chain(const int32_t* c, const int32_t* d) noexcept nogil:
    return (c[0] == d[0] and c[1] == d[1]) or (c[0] == d[1] and c[1] == d[0])


cdef bint _excepted(Refine* R, Tri* T, int e) noexcept nogil:
    """Whether the bad triangle with shortest edge e (p->q) is forced by a small input
    angle: p and q lie on two different chains with a common end a (not p or q) that
    sees p and q at an angle below the bound."""
    cdef int32_t cp[32]
    cdef int32_t cq[32]
    cdef int p = T.tv[e], q = T.tv[nxt_nb(e)], np_, nq, i, j, k, m, a
    np_ = _chains_of(R, T, p, cp, 16)
    if np_ == 0:
        return False
    nq = _chains_of(R, T, q, cq, 16)
    for i in range(np_):
        for j in range(nq):
            if _same_chain(&cp[2 * i], &cq[2 * j]):
                continue
            for k in range(2):
                a = cp[2 * i + k]
                if a == p or a == q:
                    continue
                for m in range(2):
                    if cq[2 * j + m] == a and _angle_below(
                            P(T, a), P(T, p), P(T, q), R.c2_small):
                        return True
    return False


cdef bint _across_apex(Refine* R, Tri* T, int z, int x, int y) noexcept nogil:
    """Whether vertex z lies on a chain other than that of segment piece x-y, the two
    chains meeting at a common end below 60 degrees (seen from z and the piece)."""
    cdef int32_t cz[32]
    cdef int32_t a, b
    cdef int n, i, k
    cdef double mid[2]
    n = _chains_of(R, T, z, cz, 16)
    if n == 0:
        return False
    _chain_of_piece(R, x, y, &a, &b)
    mid[0] = 0.5 * (P(T, x)[0] + P(T, y)[0])
    mid[1] = 0.5 * (P(T, x)[1] + P(T, y)[1])
    for i in range(n):
        if (cz[2 * i] == a and cz[2 * i + 1] == b) or (cz[2 * i] == b and cz[2 * i + 1] == a):
            continue
        for k in range(2):
            if (cz[2 * i + k] == a or cz[2 * i + k] == b) and cz[2 * i + k] != z and \
                    _angle_below(P(T, cz[2 * i + k]), P(T, z), mid, SHELL_COS * SHELL_COS):
                return True
    return False


# ---------------------------------------------------------------- segment splits

cdef bint _small_apex(Refine* R, Tri* T, int a, const double* toward, int32_t ca,
                      int32_t cb) noexcept nogil:
    """Whether another segment than the chain (ca, cb) leaves vertex a (one of its
    ends) within 60 degrees of the direction a->toward."""
    cdef int e0 = T.vhe[a], e = e0, guard = 0, w
    cdef double ux = toward[0] - P(T, a)[0], uy = toward[1] - P(T, a)[1], vx, vy, dot
    if e0 < 0:
        return False
    while True:
        w = T.tv[nxt_nb(e)]
        if (T.eflag[e] & E_SEGMENT) and w >= 0 and w != ca and w != cb and not (
                (R.vend[2 * w] == ca and R.vend[2 * w + 1] == cb)
                or (R.vend[2 * w] == cb and R.vend[2 * w + 1] == ca)):
            vx = P(T, w)[0] - P(T, a)[0]
            vy = P(T, w)[1] - P(T, a)[1]
            dot = ux * vx + uy * vy
            if dot > 0 and dot * dot > SHELL_COS * SHELL_COS * (ux * ux + uy * uy) * (
                    vx * vx + vy * vy):
                return True
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0 or guard > ROTATION_CAP:
            return False


cdef double _dyadic_radius(double lo, double hi) noexcept nogil:
    """The number on the coarsest dyadic grid (multiples of a power of two) in the
    middle half of [lo, hi], nearest the middle: split radii that pieces of different
    chains around the same apex share (concentric shells)."""
    cdef double L = hi - lo, a = lo + 0.25 * L, b = hi - 0.25 * L, g, k, best
    cdef int ex, guard
    frexp(b, &ex)
    g = ldexp(1.0, ex)
    for guard in range(1100):
        k = ceil(a / g)
        if k * g <= b:
            best = k * g
            # the next multiples may be nearer the middle on this grid
            while (k + 1) * g <= b and fabs((k + 1) * g - 0.5 * (lo + hi)) < fabs(
                    best - 0.5 * (lo + hi)):
                k += 1
                best = k * g
            return best
        g *= 0.5
    return 0.5 * (lo + hi)


cdef void _chain_of_piece(Refine* R, int u, int w, int32_t* a, int32_t* b) noexcept nogil:
    """The ends of the chain that segment piece u-w belongs to."""
    if R.vend[2 * u] >= 0:
        a[0] = R.vend[2 * u]
        b[0] = R.vend[2 * u + 1]
    elif R.vend[2 * w] >= 0:
        a[0] = R.vend[2 * w]
        b[0] = R.vend[2 * w + 1]
    else:
        a[0] = u
        b[0] = w


cdef void _chain_point(Refine* R, Tri* T, int u, int w, double s, double* m) noexcept nogil:
    """m = the point a fraction s of the way from u to w, computed on the line of the
    chain's ends (its input segment), not from u and w: those are rounded points
    already, and pieces of pieces would drift off the segment ulp by ulp."""
    cdef int32_t a = NONE, b = NONE
    cdef double* A
    cdef double* B
    cdef double dx, dy, L2, tu, tw, t
    _chain_of_piece(R, u, w, &a, &b)
    A = P(T, a)
    B = P(T, b)
    dx = B[0] - A[0]
    dy = B[1] - A[1]
    L2 = dx * dx + dy * dy
    tu = ((P(T, u)[0] - A[0]) * dx + (P(T, u)[1] - A[1]) * dy) / L2
    tw = ((P(T, w)[0] - A[0]) * dx + (P(T, w)[1] - A[1]) * dy) / L2
    t = tu + s * (tw - tu)
    if not (t > 0 and t < 1) or L2 <= 0:
        m[0] = P(T, u)[0] + s * (P(T, w)[0] - P(T, u)[0])
        m[1] = P(T, u)[1] + s * (P(T, w)[1] - P(T, u)[1])
        return
    m[0] = A[0] + t * dx
    m[1] = A[1] + t * dy


cdef void _split_point(Refine* R, Tri* T, int u, int w, double* m) noexcept nogil:
    """Where to split segment piece u-w: at the middle, or at a dyadic distance from an
    end of its chain where it meets another segment below 60 degrees."""
    cdef int32_t a = NONE, b = NONE
    cdef int apex = NONE
    cdef double mid[2]
    cdef double du, dw, r
    mid[0] = 0.5 * (P(T, u)[0] + P(T, w)[0])
    mid[1] = 0.5 * (P(T, u)[1] + P(T, w)[1])
    _chain_point(R, T, u, w, 0.5, m)
    _chain_of_piece(R, u, w, &a, &b)
    if _small_apex(R, T, a, mid, a, b):
        apex = a
    if _small_apex(R, T, b, mid, a, b) and (apex == NONE or _d2(P(T, b), mid) < _d2(P(T, a), mid)):
        apex = b
    if apex == NONE:
        return
    du = sqrt(_d2(P(T, apex), P(T, u)))
    dw = sqrt(_d2(P(T, apex), P(T, w)))
    if not dw != du:
        return
    if du < dw:
        r = _dyadic_radius(du, dw)
    else:
        r = _dyadic_radius(dw, du)
    _chain_point(R, T, u, w, (r - du) / (dw - du), m)


cdef bint _split_is_valid(Tri* T, int e, const double* m) noexcept nogil:
    """Putting a vertex at m on the edge of e keeps the four new triangles
    counter-clockwise (m is off the segment by up to an ulp)."""
    cdef int f = T.twin[e]
    cdef int a = T.tv[e], b = T.tv[nxt_nb(e)], c = T.tv[prv_nb(e)], d = T.tv[prv_nb(f)]
    if c >= 0 and (orient2d(P(T, b), P(T, c), m) <= 0 or orient2d(P(T, c), P(T, a), m) <= 0):
        return False
    if d >= 0 and (orient2d(P(T, a), P(T, d), m) <= 0 or orient2d(P(T, d), P(T, b), m) <= 0):
        return False
    return (m[0] != P(T, a)[0] or m[1] != P(T, a)[1]) and (
        m[0] != P(T, b)[0] or m[1] != P(T, b)[1])


cdef inline double _ulp(double v) noexcept nogil:
    """The spacing of doubles at |v| (one unit in the last place)."""
    cdef int ex
    frexp(v, &ex)
    return ldexp(1.0, ex - 53)


cdef bint _valid_split_near(Tri* T, int e, double* m) noexcept nogil:
    """Accept m, or move it by up to SPLIT_NUDGE_ULPS to either side of e's edge: a
    point an ulp off a segment can invert a sliver of triangle next to it."""
    cdef double* a = P(T, T.tv[e])
    cdef double* b = P(T, T.tv[nxt_nb(e)])
    cdef double nx = a[1] - b[1], ny = b[0] - a[0], L = sqrt(nx * nx + ny * ny), h
    cdef double x0 = m[0], y0 = m[1]
    cdef int k
    if _split_is_valid(T, e, m):
        return True
    h = _ulp(max(fabs(x0), fabs(y0))) / L
    for k in range(1, 2 * SPLIT_NUDGE_ULPS + 1):
        # 1, -1, 2, -2, ... ulps along the normal
        m[0] = x0 + ((k + 1) // 2) * (1 if k % 2 else -1) * h * nx
        m[1] = y0 + ((k + 1) // 2) * (1 if k % 2 else -1) * h * ny
        if _split_is_valid(T, e, m):
            return True
    return False


cdef bint _choose_split(Refine* R, Tri* T, int e, int u, int w, double* m) noexcept nogil:
    """A valid place m for the split of e's edge u-w: the shell point, else the
    midpoint, else other points of its middle half (an exterior sliver behind a
    boundary segment is thicker at some places than at others)."""
    cdef int k
    cdef double s
    _split_point(R, T, u, w, m)
    if _valid_split_near(T, e, m):
        return True
    for k in range(SPLIT_TRIES - 1):
        s = 0.5 + ((k + 1) // 2) * (1 if k % 2 else -1) * (0.25 / SPLIT_TRIES)
        _chain_point(R, T, u, w, s, m)
        if _valid_split_near(T, e, m):
            return True
    return False


cdef bint _inward_point(Refine* R, Tri* T, int f, int u, int w, double* m) noexcept nogil:
    """A split point for boundary piece u-w strictly inside the meshed triangle of f
    (its edge u-w): the shell point, the midpoint or another point of the middle half,
    moved by up to SPLIT_NUDGE_ULPS into the domain."""
    cdef double* a = P(T, T.tv[f])
    cdef double* b = P(T, T.tv[nxt_nb(f)])
    cdef double* c = P(T, T.tv[prv_nb(f)])
    cdef double nx = a[1] - b[1], ny = b[0] - a[0], L = sqrt(nx * nx + ny * ny), h, x0, y0, t
    cdef int k, j
    for j in range(SPLIT_TRIES):
        if j == 0:
            _split_point(R, T, u, w, m)
        else:
            t = 0.5 + (j // 2) * (1 if j % 2 else -1) * (0.25 / SPLIT_TRIES)
            _chain_point(R, T, u, w, t, m)
        x0 = m[0]
        y0 = m[1]
        h = _ulp(max(fabs(x0), fabs(y0))) / L
        for k in range(SPLIT_NUDGE_ULPS + 1):
            m[0] = x0 + k * h * nx      # (nx, ny) / L: the normal into f's triangle
            m[1] = y0 + k * h * ny
            if (orient2d(a, b, m) > 0 and orient2d(b, c, m) > 0
                    and orient2d(c, a, m) > 0):
                return True
    return False


cdef int _split_inward(Tri* T, int f, int v) noexcept nogil:
    """Put v (strictly inside the meshed triangle of f, an ulp or so from f's boundary
    edge a-b) on the boundary: split that triangle at v, hand the sliver (a, b, v) to
    the exterior and move the segment's flags from a-b to a-v and v-b.  The domain
    loses the sliver (about an ulp times the edge's length).  Returns how many edges
    facing v on the meshed side are on T.stack for the Lawson flips."""
    cdef int a = T.tv[f], b = T.tv[nxt_nb(f)], n, h, s, x, i, k = 0
    cdef uint8_t g
    cdef int32_t sid
    n = split_triangle(T, f // 3, v)
    if n < 0:
        return n
    h = find_edge(T, a, b)
    if h < 0:
        return ERR_INTERNAL
    s = h // 3
    T.tstate[s] = T_EXTERIOR
    T.tregion[s] = T.tregion[T.twin[h] // 3]
    g = T.eflag[h]
    sid = T.eseg[h]     # both new pieces stay pieces of the same input segment
    T.eflag[h] = 0
    T.eflag[T.twin[h]] = 0
    T.eseg[h] = -1
    T.eseg[T.twin[h]] = -1
    for i in range(2):
        x = nxt_nb(h) if i == 0 else prv_nb(h)
        T.eflag[x] = g
        T.eflag[T.twin[x]] = g
        T.eseg[x] = sid
        T.eseg[T.twin[x]] = sid
    for i in range(n):
        if T.tstate[T.stack[i] // 3] == T_MESHED:
            T.stack[k] = T.stack[i]
            k += 1
    return k


cdef int _queue_flipped(void* ctx, Tri* T, int t) noexcept nogil:
    return _push_tri(<Refine*> ctx, T, t)


cdef int _legalize_split(Refine* R, Tri* T, int v) noexcept nogil:
    """Finish the CDT after v was put on a segment.  v is a rounded point, up to an
    ulp or two off the segment's line, so an edge at v can be illegal too, not only
    the edges facing v that Lawson's insertion flips look at (between nearly
    collinear points of one chain it is).  Every edge of the meshed triangles around
    v is tested, flips go on from there, and the triangles they make are queued."""
    cdef int e0 = T.vhe[v], e = e0, n = 0, guard = 0
    while True:
        if T.tstate[e // 3] == T_MESHED:
            if reserve_stack(T, n + 3):
                return ERR_NOMEM
            T.stack[n] = e
            T.stack[n + 1] = nxt_nb(e)
            T.stack[n + 2] = prv_nb(e)
            n += 3
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0:
            break
        if guard > ROTATION_CAP:
            return ERR_INTERNAL
    return legalize_meshed_with(T, n, _queue_flipped, R)


cdef int _split_segment(Refine* R, Aft* A, Tri* T, int u, int w) noexcept nogil:
    """Split segment piece u-w (if it still is one).  Returns ACT_INSERTED, ACT_DROPPED
    or an error."""
    cdef int e = find_edge(T, u, w), v, n, add, res
    cdef bint inward
    cdef double m[2]
    if e < 0 or not (T.eflag[e] & E_SEGMENT) or not R.split_segments:
        return ACT_DROPPED
    if _d2(P(T, u), P(T, w)) < 4.0 * R.tiny * R.tiny:
        return ACT_DROPPED
    add = (T.tstate[e // 3] == T_MESHED) + (T.tstate[T.twin[e] // 3] == T_MESHED)
    if R.max_triangles >= 0 and R.n_meshed + add > R.max_triangles:
        R.stop = STOP_MAX_TRIANGLES
        return ACT_DROPPED
    inward = False
    if T.tstate[e // 3] != T_MESHED:
        e = T.twin[e]               # e on the meshed side from here on
    if not _choose_split(R, T, e, u, w, m):
        # behind a boundary piece, slivers of exterior triangles between it and the
        # convex hull (points an ulp inside the hull) may leave no double to split
        # at: put the point an ulp or so into the domain instead
        if add != 1 or not _inward_point(R, T, e, u, w, m):
            return ACT_DROPPED
        inward = True
    v = add_vertex(T, m[0], m[1])
    if v < 0 or _vend_reserve(R, T.nv):
        return ERR_NOMEM
    _chain_of_piece(R, u, w, &R.vend[2 * v], &R.vend[2 * v + 1])
    if inward:
        n = _split_inward(T, e, v)
        if n < 0:
            return n
    else:
        n = split_edge(T, e, v)
        if n < 0:
            return n
        # Flip only on the meshed side(s): split_edge stacked the edges facing v on
        # e's (meshed) side first.  Flips among exterior triangles could make slivers
        # out there that a later split an ulp off the line would invert.
        if add == 1:
            n = 2
    res = lawson_after_insert(T, n)
    if res == 0:
        res = _legalize_split(R, T, v)
    if res < 0:
        return res
    R.n_meshed += add
    R.inserted += 1
    R.splits += 1
    if add == 2:
        R.interior += 1
    res = _push_star(R, T, v)
    if res == 0:
        res = _queue_encroached_near(R, T, v)
    return res if res < 0 else ACT_INSERTED


# ---------------------------------------------------------------- one bad triangle

cdef void _candidate(Refine* R, Tri* T, int e, double* M, double* X) noexcept nogil:
    """The off-centre of the triangle of e (its shortest edge p->q, apex r): on the
    bisector of p-q on r's side, at the circumcentre or nearer (where the triangle on
    p-q would have an apex angle just above the bound), whichever is nearer."""
    cdef double* p = P(T, T.tv[e])
    cdef double* q = P(T, T.tv[nxt_nb(e)])
    cdef double* r = P(T, T.tv[prv_nb(e)])
    cdef double ex = q[0] - p[0], ey = q[1] - p[1], L = sqrt(ex * ex + ey * ey)
    cdef double ux = p[0] - r[0], uy = p[1] - r[1], vx = q[0] - r[0], vy = q[1] - r[1]
    cdef double cross = ux * vy - uy * vx, dot = ux * vx + uy * vy
    cdef double d = R.offcentre * L
    M[0] = 0.5 * (p[0] + q[0])
    M[1] = 0.5 * (p[1] + q[1])
    if cross > 0 and 0.5 * L * dot / cross < d:
        d = 0.5 * L * dot / cross       # the circumcentre is nearer
    X[0] = M[0] - d * ey / L
    X[1] = M[1] + d * ex / L


cdef int _walk(Tri* T, int e, const double* M, const double* X, int* where) noexcept nogil:
    """Walk from the midpoint M of e (into e's triangle) along the line to X, across
    edges that are not constrained.  Returns WALK_FOUND with where = a triangle holding
    X or (as 3 * nt + half-edge) an unconstrained edge X lies on; WALK_BLOCKED with
    where = the constrained half-edge met first (X lies across it or on it); or
    WALK_FAILED (X at a vertex, the line through a vertex, a broken structure)."""
    cdef int g = e, u, v, w, o1, o2, ow, exit_e, steps = 0
    if orient2d(P(T, T.tv[e]), P(T, T.tv[nxt_nb(e)]), X) <= 0:
        return WALK_FAILED
    while steps <= T.nt:
        steps += 1
        u = T.tv[g]
        v = T.tv[nxt_nb(g)]
        w = T.tv[prv_nb(g)]
        if w < 0:
            return WALK_FAILED
        o1 = orient2d(P(T, v), P(T, w), X)
        o2 = orient2d(P(T, w), P(T, u), X)
        if o1 >= 0 and o2 >= 0:
            if o1 == 0 and o2 == 0:
                return WALK_FAILED
            exit_e = nxt_nb(g) if o1 == 0 else (prv_nb(g) if o2 == 0 else NONE)
            if exit_e == NONE:
                where[0] = g // 3
                return WALK_FOUND
            where[0] = exit_e
            if blocking(T, exit_e):
                return WALK_BLOCKED
            where[0] = 3 * T.nt + exit_e
            return WALK_FOUND
        ow = orient2d(M, X, P(T, w))
        if ow == 0:
            return WALK_FAILED
        exit_e = nxt_nb(g) if ow > 0 else prv_nb(g)
        if blocking(T, exit_e):
            where[0] = exit_e
            return WALK_BLOCKED
        g = T.twin[exit_e]
    return WALK_FAILED


cdef int _cavity_add(Refine* R, Tri* T, int t, int* n) noexcept nogil:
    if R.mark[t] == R.epoch:
        return 0
    if _grow_i32(&R.cav, &R.cav_cap, n[0] + 1):
        return ERR_NOMEM
    R.mark[t] = R.epoch
    R.cav[n[0]] = t
    n[0] += 1
    return 0


cdef inline bint _harmful(Refine* R, Tri* T, int h, const double* X) noexcept nogil:
    """With segments kept whole, bad triangles near them cannot always be repaired, and
    inserting there could make the mesh worse: X is then inserted only if every
    triangle it makes (X and an edge h of the cavity's boundary) meets the bound, so
    the worst angle never gets smaller."""
    return not R.split_segments and _points_bad(R, P(T, T.tv[h]), P(T, T.tv[nxt_nb(h)]), X)


cdef int _encroached_by(Refine* R, Tri* T, const double* X, int t0, int t1) noexcept nogil:
    """Collect in R.enc the segments on the boundary of the cavity of X (the triangles
    whose circumcircles hold X, reached from t0 / t1 without crossing a constrained
    edge: after the insertion these edges face X) whose diametral circles hold X."""
    cdef int n = 0, i, k, h, nb, old
    R.enc_n = 0
    if T.nt > R.mark_cap:
        old = R.mark_cap
        if _grow_i32(<int32_t**> &R.mark, &R.mark_cap, T.nt):
            return ERR_NOMEM
        memset(&R.mark[old], 0, (R.mark_cap - old) * sizeof(uint32_t))
    R.epoch += 1
    if _cavity_add(R, T, t0, &n) or (t1 >= 0 and _cavity_add(R, T, t1, &n)):
        return ERR_NOMEM
    i = 0
    while i < n:
        for k in range(3):
            h = 3 * R.cav[i] + k
            if blocking(T, h):
                if _encroaches(X, P(T, T.tv[h]), P(T, T.tv[nxt_nb(h)])) or _harmful(R, T, h, X):
                    if _grow_i32(&R.enc, &R.enc_cap, 2 * R.enc_n + 2):
                        return ERR_NOMEM
                    R.enc[2 * R.enc_n] = T.tv[h]
                    R.enc[2 * R.enc_n + 1] = T.tv[nxt_nb(h)]
                    R.enc_n += 1
                continue
            nb = T.twin[h] // 3
            if R.mark[nb] == R.epoch:
                continue
            if incircle(P(T, T.tv[3 * nb]), P(T, T.tv[3 * nb + 1]), P(T, T.tv[3 * nb + 2]),
                        X) > 0:
                if _cavity_add(R, T, nb, &n):
                    return ERR_NOMEM
            elif _harmful(R, T, h, X):
                R.enc_n += 1            # (only counted: without splits X is dropped)
        i += 1
    return 0


cdef int _split_all(Refine* R, Aft* A, Tri* T, int32_t* segs, int n) noexcept nogil:
    """Split the segments segs[2i], segs[2i+1]; ACT_SPLIT if one was, else ACT_DROPPED."""
    cdef int i, res, done = 0
    for i in range(n):
        res = _split_segment(R, A, T, segs[2 * i], segs[2 * i + 1])
        if res < 0:
            return res
        done += res == ACT_INSERTED
    return ACT_SPLIT if done else ACT_DROPPED


cdef int _refine_triangle(Refine* R, Aft* A, Tri* T, int t, int e) noexcept nogil:
    """Insert the off-centre of bad triangle t (e: its shortest half-edge, from
    _bad_edge), or split the segments in its way."""
    cdef int where = NONE, res, loc, v, t1 = NONE
    cdef int32_t seg[2]
    cdef double M[2]
    cdef double X[2]
    _candidate(R, T, e, M, X)
    res = _walk(T, e, M, X, &where)
    if res == WALK_FAILED:
        return ACT_DROPPED
    if res == WALK_BLOCKED:
        if not (T.eflag[where] & E_SEGMENT):
            return ACT_DROPPED
        seg[0] = T.tv[where]
        seg[1] = T.tv[nxt_nb(where)]
        return _split_all(R, A, T, seg, 1)
    loc = LOC_IN_TRIANGLE
    if where >= 3 * T.nt:
        loc = LOC_ON_EDGE
        where -= 3 * T.nt
        t1 = T.twin[where] // 3
        res = _encroached_by(R, T, X, where // 3, t1)
    else:
        res = _encroached_by(R, T, X, where, NONE)
    if res < 0:
        return res
    if R.enc_n > 0:
        # (splits queue further pieces in R.sq; R.enc stays as it is meanwhile).
        # Without segment splits, a point near a segment would only make way for
        # the next one nearer still: the triangle is left as it is.
        if not R.split_segments:
            return ACT_DROPPED
        return _split_all(R, A, T, R.enc, R.enc_n)
    if R.max_triangles >= 0 and R.n_meshed + 2 > R.max_triangles:
        R.stop = STOP_MAX_TRIANGLES
        return ACT_DROPPED
    v = add_vertex(T, X[0], X[1])
    if v < 0 or _vend_reserve(R, T.nv):
        return ERR_NOMEM
    res = insert_vertex_at(T, v, loc, where)
    if res < 0:
        return res
    R.n_meshed += 2
    R.inserted += 1
    R.interior += 1
    res = _push_star(R, T, v)
    return res if res < 0 else ACT_INSERTED


# ---------------------------------------------------------------- the pass

cdef int _scan_bad(Refine* R, Tri* T) noexcept nogil:
    """Count the meshed triangles and queue the bad ones; returns how many are bad."""
    cdef int t, nbad = 0
    R.n_meshed = 0
    for t in range(T.nt):
        if T.tstate[t] == T_MESHED:
            R.n_meshed += 1
            if _is_bad(R, T, t):
                nbad += 1
                if _enqueue_tri(R, T, t):
                    return ERR_NOMEM
    return nbad


cdef double _tiny_length(Tri* T) noexcept nogil:
    cdef int v
    cdef double big = 0.0
    for v in range(T.nv):
        big = max(big, max(fabs(T.xy[2 * v]), fabs(T.xy[2 * v + 1])))
    return REFINE_TINY_ULPS * big * 2.220446049250313e-16


cdef bint _below_resolution(Refine* R, Tri* T, int t) noexcept nogil:
    """Triangle t has an edge shorter than R.tiny, or is thinner than R.tiny (its
    smallest height, twice its area over its longest edge): its small angle comes
    from points closer together, or closer to a line through two others, than the
    pass resolves, and it is left as it is.  (A region or a gap between segments
    that narrow is made only of such triangles; points put for them split the
    segments on both sides in turn, down to the insertion cap.)"""
    cdef const double* a = P(T, T.tv[3 * t])
    cdef const double* b = P(T, T.tv[3 * t + 1])
    cdef const double* c = P(T, T.tv[3 * t + 2])
    cdef double ab = _d2(a, b), bc = _d2(b, c), ca = _d2(c, a), t2 = R.tiny * R.tiny
    cdef double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    if ab < t2 or bc < t2 or ca < t2:
        return True
    return cross * cross < t2 * max(ab, max(bc, ca))


cdef int _refine_step(Refine* R, Aft* A, Tri* T) noexcept nogil:
    """One step of the loop: split a queued segment, or work on a queued triangle.
    Returns 1 to go on, 0 when the queues are empty, or an error."""
    cdef int t, res, u, w, e
    if R.sq_n > 0:
        R.sq_n -= 1
        u = R.sq[2 * R.sq_n]
        w = R.sq[2 * R.sq_n + 1]
        res = _split_segment(R, A, T, u, w)
        return res if res < 0 else 1
    t = _pop_tri(R, T)
    if t == NONE:
        return 0
    e = _bad_edge(R, T, t)
    if e == NONE or _excepted(R, T, e):
        return 1
    if _below_resolution(R, T, t):
        return 1
    res = _refine_triangle(R, A, T, t, e)
    if res < 0:
        return res
    if res == ACT_SPLIT:
        if _push_tri(R, T, t):      # try it again once the segments are split
            return ERR_NOMEM
    elif res == ACT_DROPPED:
        R.dropped += 1
    return 1


cdef int _final_scan(Refine* R, Tri* T) noexcept nogil:
    """Count the triangles still below the bound: excepted ones (forced by a small
    input angle) and the others."""
    cdef int t, e
    R.excepted = 0
    R.unresolved = 0
    for t in range(T.nt):
        if T.tstate[t] != T_MESHED:
            continue
        e = _bad_edge(R, T, t)
        if e != NONE:
            if _excepted(R, T, e):
                R.excepted += 1
            else:
                R.unresolved += 1
    return 0


cdef int refine_mesh(Refine* R, Aft* A, Tri* T) noexcept nogil:
    """The minimum-angle pass over the meshed triangles (see the top of this file).
    R holds the bound and the options; it receives the counts.  Returns 0 or an
    error."""
    cdef int res = _refine_loop(R, A, T)
    if res <= 0:
        return res                  # an error, or nothing is bad: the counts stay 0
    return _final_scan(R, T)


cdef int _refine_loop(Refine* R, Aft* A, Tri* T) noexcept nogil:
    """refine_mesh without the final count: 1 when there were bad triangles to work
    on, 0 when none, or an error."""
    cdef int res, steps = 0
    R.max_triangles = A.max_triangles
    res = _scan_bad(R, T)
    if res <= 0:
        return res
    R.tiny = _tiny_length(T)
    R.max_insert = max(REFINE_CAP_MIN, REFINE_CAP_PER_TRIANGLE * R.n_meshed)
    if R.vend == NULL:
        res = _chain_init(R, T)
        if res < 0:
            return res
    while True:
        if R.inserted >= R.max_insert:
            R.stop = STOP_CAP
            break
        res = _refine_step(R, A, T)
        if res < 0:
            return res
        if res == 0 or R.stop != STOP_NONE:
            break
        steps += 1
        if steps % 4096 == 0 and check_signals(A) != 0:
            return ERR_INTERRUPTED
    return 1


cdef int refine_settled(Refine* R, Aft* A, Tri* T, int first_movable, bint slide,
                        int smooth_rounds) noexcept nogil:
    """refine_mesh, then (smooth_rounds > 0: smoothing is on) up to
    REFINE_SETTLE_ROUNDS smoothing rounds around the vertices it added (smoothing.pxi's
    settle_refined: Basic_aft's vertices, first_movable on, and the pass's interior
    ones move; with `slide`, the points inside a chain slide), then refine_mesh again,
    so that the bound holds for the final mesh (see the top of this file).  Returns 0
    or an error.  The counts are those of the last run (the first run's final count
    is skipped when a second run follows)."""
    cdef int first_new = T.nv, res
    cdef int rounds = min(REFINE_SETTLE_ROUNDS, smooth_rounds)
    res = _refine_loop(R, A, T)
    if res <= 0:
        return res                  # an error, or nothing is bad: the counts stay 0
    if rounds <= 0 or T.nv == first_new or R.stop != STOP_NONE:
        return _final_scan(R, T)
    res = settle_refined(A, T, first_new, first_movable, R.vend if slide else NULL, rounds)
    if res < 0:
        return res
    R.excepted = 0
    R.unresolved = 0
    return refine_mesh(R, A, T)
