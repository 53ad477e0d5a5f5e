# Smoothing after the front has closed (optional, on by default in generate()).
#
# Each pass moves vertices that Basic_aft created (the input vertices never move) by
# optimize.pxi's _optimize_vertex, which keeps every triangle counter-clockwise (exact
# orient2d) and restores the constrained Delaunay property by Lawson flips around each
# moved vertex, so the result is still the CDT of its vertices and the input edges.
# (_smooth_vertex below is the earlier max-min move, kept for comparison.)

cdef inline double _shape(const double* a, const double* b, const double* c) noexcept nogil:
    """4 sqrt(3) area / (sum of squared edge lengths): 1 for an equilateral triangle,
    0 for a degenerate one, negative when inverted (a cheap, smooth quality measure)."""
    cdef double abx = b[0] - a[0], aby = b[1] - a[1]
    cdef double acx = c[0] - a[0], acy = c[1] - a[1]
    cdef double bcx = c[0] - b[0], bcy = c[1] - b[1]
    cdef double area2 = abx * acy - aby * acx
    cdef double s = abx * abx + aby * aby + acx * acx + acy * acy + bcx * bcx + bcy * bcy
    return 3.4641016151377544 * area2 / s


cdef double _worst_around(Tri* T, int e0) noexcept nogil:
    cdef int e = e0
    cdef double q, worst = 2.0
    while True:
        q = _shape(P(T, T.tv[e]), P(T, T.tv[nxt(e)]), P(T, T.tv[prv(e)]))
        if q < worst:
            worst = q
        e = T.twin[prv(e)]
        if e == e0:
            return worst


cdef double _try_at(Tri* T, int v, int e0, double x, double y) noexcept nogil:
    """Worst shape around v if it stood at (x, y) (v is put back afterwards)."""
    cdef double ox = T.xy[2 * v], oy = T.xy[2 * v + 1], q
    T.xy[2 * v] = x
    T.xy[2 * v + 1] = y
    q = _worst_around(T, e0)
    T.xy[2 * v] = ox
    T.xy[2 * v + 1] = oy
    return q


cdef int _smooth_vertex(Tri* T, int v) noexcept nogil:
    """Move v to whichever of a few candidate places makes the worst of its triangles
    best: the mean of its neighbours (Laplacian), the mean of its triangles' ideal
    apexes (each the point that would make that triangle equilateral on its edge
    opposite v), and two steps towards the ideal apex of its worst triangle.  The move
    is kept only if it improves the worst shape (so smoothing never makes the worst
    triangle around a vertex worse) and every triangle stays counter-clockwise (exact
    orient2d).  A vertex whose triangles are all nearly equilateral (shape > 0.985) is
    left alone: most are, which saves most of the work.  Returns 1 if v moved."""
    cdef int e0 = T.vhe[v], e = e0, guard = 0, n = 0, u, w, k
    cdef double lx = 0.0, ly = 0.0, ix = 0.0, iy = 0.0, ax, ay, mx, my, q, worst_q = 2.0
    cdef double wx = 0.0, wy = 0.0, best, bx, by, cx, cy, t
    cdef double* pu
    cdef double* pw
    if e0 < 0:
        return 0
    while True:
        u = T.tv[nxt(e)]
        w = T.tv[prv(e)]
        if u < 0 or w < 0 or T.tstate[e // 3] != T_MESHED:
            return 0                # on the hull or next to the outside: keep it
        pu = P(T, u)
        pw = P(T, w)
        # the equilateral apex on edge u->w, on v's side (left of u->w)
        mx = 0.5 * (pu[0] + pw[0])
        my = 0.5 * (pu[1] + pw[1])
        ax = mx - 0.8660254037844386 * (pw[1] - pu[1])
        ay = my + 0.8660254037844386 * (pw[0] - pu[0])
        lx += pu[0]
        ly += pu[1]
        ix += ax
        iy += ay
        q = _shape(P(T, v), pu, pw)
        if q < worst_q:
            worst_q = q
            wx = ax
            wy = ay
        n += 1
        e = T.twin[prv(e)]
        guard += 1
        if e == e0:
            break
        if guard > 64:
            return 0
    if worst_q > 0.985:
        return 0                    # all its triangles are nearly equilateral already
    best = worst_q
    bx = T.xy[2 * v]
    by = T.xy[2 * v + 1]
    cx = bx
    cy = by
    for k in range(4):
        if k == 0:
            ax, ay = lx / n, ly / n
        elif k == 1:
            ax, ay = ix / n, iy / n
        else:
            t = 0.25 if k == 2 else 0.5
            ax = cx + t * (wx - cx)
            ay = cy + t * (wy - cy)
        q = _try_at(T, v, e0, ax, ay)
        if q > best + 1e-6:
            best = q
            bx = ax
            by = ay
    if bx == cx and by == cy:
        return 0
    T.xy[2 * v] = bx
    T.xy[2 * v + 1] = by
    e = e0
    while True:
        if orient2d(P(T, T.tv[e]), P(T, T.tv[nxt(e)]), P(T, T.tv[prv(e)])) <= 0:
            T.xy[2 * v] = cx
            T.xy[2 * v + 1] = cy
            return 0
        e = T.twin[prv(e)]
        if e == e0:
            return 1


cdef int smooth(Aft* A, Tri* T, int first_movable, int passes) noexcept nogil:
    """Up to `passes` rounds of moves of vertices first_movable.. (optimize.pxi), each
    followed by Delaunay flips around the vertex, stopping early when a round moves
    nothing; signals are checked after each round.  Returns the number of vertex
    moves, or an error."""
    cdef int p, v, res, moved = 0, moved_now
    for p in range(passes):
        moved_now = 0
        for v in range(first_movable, T.nv):
            res = _optimize_vertex(T, v)
            if res < 0:
                return res
            moved_now += res
        moved += moved_now
        if check_signals(A) != 0:
            return ERR_INTERRUPTED
        if moved_now == 0:
            break
    return moved
