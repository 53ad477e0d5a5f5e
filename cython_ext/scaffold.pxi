# Scaffold vertices: temporary interior points of the unmeshed CDT.
#
# The unmeshed CDT of a large domain has only front vertices, so its triangles span
# the whole unmeshed region: each point the front inserts lies in the circumcircles
# of many of them, and its Lawson flips grow as the square root of the region's width
# over the size (benchmarks/README.md, "Scaling").  A sparse lattice of extra
# vertices, SCAFFOLD_SPACING sizes apart, cuts those triangles short.
#
# A scaffold vertex is never a vertex of a meshed triangle: it is removed (Delaunay
# vertex removal from the unmeshed CDT) when it becomes the apex S of a front edge, or
# when it lies within the proximity distance of a candidate R.  Every unmeshed
# triangle is meshed by the end, so every scaffold vertex is gone by then, and the
# output's vertices are those Basic_aft would have made.  Each removal takes finitely
# many flips and there are finitely many scaffold vertices, so the termination
# argument of §2 is unchanged; the unmeshed triangulation stays a CDT, so Check_visible
# and Lemma 3.1 hold as they are.  Nothing is planted under max_triangles (formula
# (4)): the lattice follows the size asked, not the capped count.
#
# Uses: halfedge.pxd; aft.pxd; predicates.pxi (orient2d); triangulation.pxi
# (add_vertex, locate, insert_vertex_at, flip, in_circle_ext, find_edge,
# reserve_stack, _grow); sizing.pxi (size_at); front.pxi (_dist2_point_segment,
# _in_circle_value); refine.pxi (_d2).
from libc.math cimport ceil, fabs

# Lattice spacing in units of the local size: the unmeshed triangles then stay within
# a few spacings, whatever the domain's extent.  Instructions of generate on the unit
# square (callgrind), 8 against 16: -32 % against -22 % at 2.3e4 triangles, -44 %
# against -40 % at 1.4e5; 4 and 24 did worse.
cdef double SCAFFOLD_SPACING = 8.0
# No scaffold vertex nearer than this many spacings to a vertex or constrained edge of
# the boundary CDT's triangle it falls in: the front's first layers would remove it at
# once.
cdef double SCAFFOLD_MARGIN = 0.5
# Lattice indices stay below this (far inside an int): no scaffold where the
# coordinates are more than this many spacings from the origin.
cdef double SCAFFOLD_MAX_INDEX = 1.0e9
# Each lattice point moves by up to this fraction of the spacing, by a hash of its
# indices: an exact lattice has collinear and cocircular vertices everywhere, and a
# vertex exactly between two of its neighbours can have no edge that flips away, so
# it could not be removed (measured: 21 of 154 kept on the unit square).
cdef double SCAFFOLD_JITTER = 0.5
cdef enum:
    SCAFFOLD_INITIAL_CAP = 256      # lattice points gathered, grown by doubling
cdef uint32_t SALT_X = 0x243F6A88u  # the jitter's two hashes differ by these
cdef uint32_t SALT_Y = 0xB7E15162u


cdef inline bint is_scaffold(Aft* A, int v) noexcept nogil:
    return (A.n_scaffold > 0 and A.scaffold_lo <= v < A.scaffold_hi
            and A.scaffold_alive[v - A.scaffold_lo])


cdef double _least_size(SizeField* S) noexcept nogil:
    """A lower bound of size_at over the whole field: every look-up interpolates w or
    follows a cone that starts at some vertex's g."""
    cdef int k
    cdef double h
    if S.nt == 0:
        return S.constant
    h = INFINITY
    for k in range(S.nv):
        h = S.w[k] if S.w[k] < h else h
        h = S.g[k] if S.g[k] < h else h
    return h


cdef bint _clear_of(Tri* T, int t, double x, double y, double margin) noexcept nogil:
    """(x, y) is at least `margin` from t's vertices and constrained edges."""
    cdef int k, e
    cdef double p[2]
    cdef double dx, dy, m2 = margin * margin
    p[0] = x
    p[1] = y
    for k in range(3):
        e = 3 * t + k
        dx = T.xy[2 * T.tv[e]] - x
        dy = T.xy[2 * T.tv[e] + 1] - y
        if dx * dx + dy * dy < m2:
            return False
        if blocking(T, e) and _dist2_point_segment(p, P(T, T.tv[e]), P(T, T.tv[nxt(e)])) < m2:
            return False
    return True


cdef inline double _jitter(int i, int j, uint32_t salt) noexcept nogil:
    """A deterministic offset in [-SCAFFOLD_JITTER / 2, SCAFFOLD_JITTER / 2) for
    lattice point (i, j) (a 32-bit integer hash: the same domain gets the same
    scaffold in every run)."""
    cdef uint32_t x = (<uint32_t> i) * 0x9E3779B1u ^ (<uint32_t> j) * 0x85EBCA77u ^ salt
    x ^= x >> 16
    x *= 0x7FEB352Du
    x ^= x >> 15
    x *= 0x846CA68Bu
    x ^= x >> 16
    return SCAFFOLD_JITTER * (x * 2.3283064365386963e-10 - 0.5)


cdef int _gather_row(Tri* T, int t, int j, double s, double** pts, int* n,
                     int* cap) noexcept nogil:
    """Append the lattice points (i s, j s) of row j inside triangle t (floating
    point: the insertion decides exactly), each moved by its jitter, that stay
    clear of t's boundary."""
    cdef int k, i, i0, i1
    cdef double y = j * s, px, py
    cdef double* p
    cdef double* q
    cdef double x, xl = 1e308, xr = -1e308
    for k in range(3):
        p = P(T, T.tv[3 * t + k])
        q = P(T, T.tv[3 * t + (k + 1) % 3])
        if (p[1] - y) * (q[1] - y) <= 0.0 and p[1] != q[1]:
            x = p[0] + (y - p[1]) * (q[0] - p[0]) / (q[1] - p[1])
            xl = x if x < xl else xl
            xr = x if x > xr else xr
    if not xl <= xr:
        return 0
    i0 = <int> ceil(xl / s)
    i1 = <int> floor(xr / s)
    for i in range(i0, i1 + 1):
        px = (i + _jitter(i, j, SALT_X)) * s
        py = (j + _jitter(i, j, SALT_Y)) * s
        if not _clear_of(T, t, px, py, SCAFFOLD_MARGIN * s):
            continue
        if n[0] >= cap[0]:
            if _grow(<void**> pts, 4 * cap[0] * sizeof(double)):
                return ERR_NOMEM
            cap[0] *= 2
        pts[0][2 * n[0]] = px
        pts[0][2 * n[0] + 1] = py
        n[0] += 1
    return 0


cdef int _gather_lattice(Aft* A, Tri* T, double** pts, int* n, int* cap) noexcept nogil:
    """The lattice points of every unmeshed triangle, row by row (a lattice of spacing
    SCAFFOLD_SPACING times the size at the triangle's centroid, anchored at the
    origin: one lattice for a constant size)."""
    cdef int t, j, j0, j1, res
    cdef double* a
    cdef double* b
    cdef double* c
    cdef double s, ylo, yhi
    # a triangle's points are all within its longest edge of each corner, so one whose
    # longest edge is below the least margin holds no point clear of its corners: most
    # triangles of a detailed outline, skipped without a size look-up
    cdef double least = SCAFFOLD_MARGIN * SCAFFOLD_SPACING * _least_size(&A.size)
    for t in range(T.nt):
        if T.tstate[t] != T_UNMESHED:
            continue
        a = P(T, T.tv[3 * t])
        b = P(T, T.tv[3 * t + 1])
        c = P(T, T.tv[3 * t + 2])
        if max(_d2(a, b), max(_d2(b, c), _d2(c, a))) < least * least:
            continue
        s = SCAFFOLD_SPACING * size_at(&A.size, (a[0] + b[0] + c[0]) / 3.0,
                                       (a[1] + b[1] + c[1]) / 3.0)
        if not s > 0.0:
            continue
        ylo = min(a[1], min(b[1], c[1]))
        yhi = max(a[1], max(b[1], c[1]))
        if max(fabs(ylo), fabs(yhi), fabs(min(a[0], min(b[0], c[0]))),
               fabs(max(a[0], max(b[0], c[0])))) > SCAFFOLD_MAX_INDEX * s:
            continue                # lattice indices would overflow an int
        j0 = <int> ceil(ylo / s)
        j1 = <int> floor(yhi / s)
        for j in range(j0, j1 + 1):
            res = _gather_row(T, t, j, s, pts, n, cap)
            if res < 0:
                return res
    return 0


cdef int plant_scaffold(Aft* A, Tri* T) noexcept nogil:
    """Insert the scaffold vertices into the unmeshed CDT if set_options asked for
    them (A.scaffold_on).  They get the vertex numbers scaffold_lo..scaffold_hi.
    Returns their number or an error."""
    cdef int n = 0, cap = SCAFFOLD_INITIAL_CAP, i, v, loc, where, res = 0
    cdef double* pts
    A.scaffold_lo = A.scaffold_hi = T.nv
    A.n_scaffold = 0
    # with max_triangles the lattice would follow the size asked, not the capped
    # output: a huge request would plant millions of vertices for a small mesh
    if not A.scaffold_on or A.greedy or A.max_triangles >= 0:
        return 0
    pts = <double*> malloc(2 * cap * sizeof(double))
    if pts == NULL:
        return ERR_NOMEM
    res = _gather_lattice(A, T, &pts, &n, &cap)
    if res >= 0:
        free(A.scaffold_alive)
        A.scaffold_alive = <uint8_t*> malloc(n if n > 0 else 1)
        if A.scaffold_alive == NULL:
            res = ERR_NOMEM
    i = 0
    while res >= 0 and i < n:
        v = add_vertex(T, pts[2 * i], pts[2 * i + 1])
        i += 1
        if v < 0:
            res = v
            break
        loc = locate(T, P(T, v), NONE, &where)
        if loc == LOC_IN_TRIANGLE and T.tstate[where] == T_UNMESHED:
            res = insert_vertex_at(T, v, loc, where)
            A.scaffold_alive[v - A.scaffold_lo] = 1
            A.n_scaffold += 1
        elif loc < 0:
            res = loc
        else:
            T.nv -= 1               # on an edge or a vertex, or outside: not planted
    free(pts)
    A.scaffold_hi = T.nv
    return res if res < 0 else <int> A.n_scaffold


# ---------------------------------------------------------------- removal

cdef int _star_flippable(Tri* T, int v, int e) noexcept nogil:
    """e leaves v in (v, b, c); its twin is in (b, v, d).  Flipping e (to c-d) is
    allowed when both new triangles (v, d, c) and (d, b, c) are counter-clockwise."""
    cdef int b = T.tv[nxt(e)], c = T.tv[prv(e)], d = T.tv[prv(T.twin[e])]
    if b < 0 or c < 0 or d < 0:
        return 0
    return orient2d(P(T, v), P(T, d), P(T, c)) > 0 and orient2d(P(T, d), P(T, b), P(T, c)) > 0


cdef double _ear_score(Tri* T, int v, int e) noexcept nogil:
    """How far v lies inside the circumcircle of the ear (d, b, c) that flipping e
    cuts off (incircle over orientation, v's negated power): the ear with the highest
    score is a Delaunay triangle of the star without v (Devillers' ear order), so the
    flips afterwards have little to repair.  Floating point: only the order depends
    on it."""
    cdef double* pb = P(T, T.tv[nxt(e)])
    cdef double* pc = P(T, T.tv[prv(e)])
    cdef double* pd = P(T, T.tv[prv(T.twin[e])])
    cdef double* pv = P(T, v)
    cdef double o = (pb[0] - pd[0]) * (pc[1] - pd[1]) - (pb[1] - pd[1]) * (pc[0] - pd[0])
    return _in_circle_value(pd, pb, pc, pv) / o


cdef int _star_removable(Tri* T, int v, int* degree) noexcept nogil:
    """v's triangles are all unmeshed and none of its edges is constrained."""
    cdef int e0 = T.vhe[v], e = e0, n = 0
    if e0 < 0:
        return 0
    while True:
        if T.tstate[e // 3] != T_UNMESHED or blocking(T, e):
            return 0
        n += 1
        e = T.twin[prv(e)]
        if e == e0:
            break
        if n > T.nt:
            return 0
    degree[0] = n
    return 1


cdef int _legalize_unmeshed(Tri* T, int nstack) noexcept nogil:
    """Lawson's flips from the half-edges T.stack[0:nstack] until the unmeshed CDT is
    locally Delaunay there again (any triangulation converges; constrained edges and
    edges to other states are never flipped)."""
    cdef int e, f, t0, t1, k
    while nstack > 0:
        nstack -= 1
        e = T.stack[nstack]
        if blocking(T, e):
            continue
        f = T.twin[e]
        if in_circle_ext(T, T.tv[e], T.tv[nxt(e)], T.tv[prv(e)], T.tv[prv(f)]):
            t0 = e // 3
            t1 = f // 3
            flip(T, e)
            if reserve_stack(T, nstack + 4):
                return ERR_NOMEM
            # the four outer edges of the quadrilateral (not the new diagonal)
            for k in range(2):
                T.stack[nstack] = 3 * t0 + k
                T.stack[nstack + 1] = 3 * t1 + k
                nstack += 2
    return 0


cdef int _pairs_to_edges(Tri* T, int n) noexcept nogil:
    """T.stack[0:n] holds n / 2 vertex pairs (flips move edges between slots, so the
    inner edges of a star are recorded by their ends); replace them by their
    half-edges, in place.  Returns their number or ERR_INTERNAL."""
    cdef int k, e
    for k in range(n // 2):
        e = find_edge(T, T.stack[2 * k], T.stack[2 * k + 1])
        if e < 0:
            return ERR_INTERNAL
        T.stack[k] = e
    return n // 2


cdef int remove_scaffold_vertex(Aft* A, Tri* T, int v) noexcept nogil:
    """Take scaffold vertex v out of the unmeshed CDT: flip its edges away, the best
    ear first, down to three; merge those three triangles into one (two slots become
    T_FREE, v loses its half-edge); then restore the Delaunay property over the star.
    If v cannot be removed (a constrained edge reached it), it stays as an ordinary
    vertex, which is still a valid mesh vertex.  Returns 0 or an error."""
    cdef int degree = 0, e0, e, best, n, k, t0, t1, t2
    cdef int p0, p1, p2, o0, o1, o2
    cdef double score, best_score
    A.scaffold_alive[v - A.scaffold_lo] = 0
    A.n_scaffold -= 1
    if not _star_removable(T, v, &degree):
        A.n_scaffold_kept += 1
        return 0
    if reserve_stack(T, 2 * degree + 3):
        return ERR_NOMEM
    n = 0
    while degree > 3:
        best = NONE
        best_score = -1e308
        e0 = T.vhe[v]
        e = e0
        while True:
            if _star_flippable(T, v, e):
                score = _ear_score(T, v, e)
                if best == NONE or score > best_score:
                    best = e
                    best_score = score
            e = T.twin[prv(e)]
            if e == e0:
                break
        if best == NONE:
            A.n_scaffold_kept += 1
            # no flip possible: v stays, as an ordinary vertex, and the flips so far
            # are made Delaunay again (its own edges too)
            n = _pairs_to_edges(T, n)
            if n < 0:
                return n
            if reserve_stack(T, n + degree):
                return ERR_NOMEM
            e = e0
            while True:
                T.stack[n] = nxt(e)
                n += 1
                e = T.twin[prv(e)]
                if e == e0:
                    break
            return _legalize_unmeshed(T, n)
        # the new edge c-d is an inner edge of the star: check it once v is gone
        T.stack[n] = T.tv[prv(best)]
        T.stack[n + 1] = T.tv[prv(T.twin[best])]
        n += 2
        flip(T, best)
        degree -= 1
    # three triangles (v, p0, p1), (v, p1, p2), (v, p2, p0) become (p0, p1, p2)
    e0 = T.vhe[v]
    t0 = e0 // 3
    p0 = T.tv[nxt(e0)]
    p1 = T.tv[prv(e0)]
    e = T.twin[prv(e0)]
    t1 = e // 3
    p2 = T.tv[prv(e)]
    t2 = T.twin[prv(e)] // 3
    if T.tv[prv(T.twin[prv(e)])] != p0:
        return ERR_INTERNAL
    o0 = T.twin[nxt(e0)]                 # outside p0 -> p1
    o1 = T.twin[nxt(e)]                  # outside p1 -> p2
    o2 = T.twin[nxt(T.twin[prv(e)])]     # outside p2 -> p0
    set_tri(T, t0, p0, p1, p2, o0, o1, o2, T.eflag[o0], T.eflag[o1], T.eflag[o2],
            T.eseg[o0], T.eseg[o1], T.eseg[o2], T_UNMESHED, T.tregion[t0])
    T.tstate[t1] = T_FREE
    T.tstate[t2] = T_FREE
    T.vhe[v] = NONE
    if T.last == t1 or T.last == t2:
        T.last = t0
    A.n_unmeshed -= 2
    # the recorded inner edges and t0's
    n = _pairs_to_edges(T, n)
    if n < 0:
        return n
    for k in range(3):
        T.stack[n] = 3 * t0 + k
        n += 1
    return _legalize_unmeshed(T, n)


# ---------------------------------------------------------------- compaction

cdef void _compact_vertices(Aft* A, Tri* T, int32_t* remap) noexcept nogil:
    """Renumber the live vertices from scaffold_lo on in their order, over the removed
    ones (remap: scratch of T.nv entries)."""
    cdef int v, k = A.scaffold_lo, e
    cdef bint hints = A.size.vhint != NULL
    for v in range(A.scaffold_lo, T.nv):
        if T.vhe[v] < 0:
            remap[v] = NONE
            continue
        remap[v] = k
        if k != v:
            T.xy[2 * k] = T.xy[2 * v]
            T.xy[2 * k + 1] = T.xy[2 * v + 1]
            T.vhe[k] = T.vhe[v]
            if hints and v < A.size.vhint_cap:
                A.size.vhint[k] = A.size.vhint[v]
        k += 1
    for e in range(3 * T.nt):
        if T.tstate[e // 3] != T_FREE and T.tv[e] >= A.scaffold_lo:
            T.tv[e] = remap[T.tv[e]]
    T.nv = k


cdef void _compact_triangles(Tri* T, int32_t* remap) noexcept nogil:
    """Move the live triangles down over the free slots, in their order (remap:
    scratch of T.nt entries)."""
    cdef int t, k = 0, j, e
    for t in range(T.nt):
        if T.tstate[t] == T_FREE:
            remap[t] = NONE
            continue
        remap[t] = k
        if k != t:
            for j in range(3):
                T.tv[3 * k + j] = T.tv[3 * t + j]
                T.twin[3 * k + j] = T.twin[3 * t + j]
                T.eflag[3 * k + j] = T.eflag[3 * t + j]
                T.eseg[3 * k + j] = T.eseg[3 * t + j]
            T.tstate[k] = T.tstate[t]
            T.tregion[k] = T.tregion[t]
        k += 1
    for e in range(3 * k):
        T.twin[e] = 3 * remap[T.twin[e] // 3] + T.twin[e] % 3
    for t in range(T.nv):
        e = T.vhe[t]
        if e >= 0:
            T.vhe[t] = 3 * remap[e // 3] + e % 3
    T.last = remap[T.last] if 0 <= T.last < T.nt and remap[T.last] >= 0 else 0
    T.nt = k


cdef int compact_after_scaffold(Aft* A, Tri* T) noexcept nogil:
    """Close the holes that removed scaffold vertices left in the vertex numbers and
    triangle slots, keeping the order of what stays: the vertices keep the order the
    front made them in, as without the scaffold.  Every later stage then sees a
    triangulation without free slots or unconnected vertices.  Returns 0 or
    ERR_NOMEM."""
    cdef int32_t* remap = <int32_t*> malloc(
        (T.nv if T.nv > T.nt else T.nt) * sizeof(int32_t) + 1)
    if remap == NULL:
        return ERR_NOMEM
    _compact_vertices(A, T, remap)
    _compact_triangles(T, remap)
    free(remap)
    A.scaffold_lo = A.scaffold_hi = T.nv
    return 0
