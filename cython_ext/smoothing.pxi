# Smoothing after the front has closed (optional, on by default in generate()).
#
# Each pass moves every vertex that Basic_aft created (the input vertices never move)
# towards the position that would make its triangles equilateral, when that keeps
# them all counter-clockwise (exact orient2d) and does not spoil the worst, and then
# restores the constrained Delaunay
# property by Lawson flips over the whole mesh, so the result is still the CDT of its
# vertices and the input edges.

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


cdef int _smooth_vertex(Tri* T, int v) noexcept nogil:
    """Move v to the mean, over its triangles, of the midpoint between a neighbour and
    the ideal apex (the one that would make the triangle equilateral on its edge
    opposite v): half Laplacian, half "equilateral" smoothing, which measured better
    than either alone.  The move is kept only if every triangle around v stays
    counter-clockwise and the worst of them loses at most 0.02 of shape quality (a
    small loss lets a vertex leave a local optimum that blocks its neighbours).
    Returns 1 if v moved."""
    cdef int e0 = T.vhe[v], e = e0, guard = 0, n = 0, u, w
    cdef double sx = 0.0, sy = 0.0, ox, oy, mx, my, before, after
    if e0 < 0:
        return 0
    while True:
        u = T.tv[nxt(e)]
        w = T.tv[prv(e)]
        if u < 0 or w < 0 or T.tstate[e // 3] != T_MESHED:
            return 0                # on the hull or next to the outside: keep it
        # the equilateral apex on edge u->w, on v's side (left of u->w)
        mx = 0.5 * (T.xy[2 * u] + T.xy[2 * w])
        my = 0.5 * (T.xy[2 * u + 1] + T.xy[2 * w + 1])
        sx += 0.5 * (mx - 0.8660254037844386 * (T.xy[2 * w + 1] - T.xy[2 * u + 1])) + 0.5 * T.xy[2 * u]
        sy += 0.5 * (my + 0.8660254037844386 * (T.xy[2 * w] - T.xy[2 * u])) + 0.5 * T.xy[2 * u + 1]
        n += 1
        e = T.twin[prv(e)]
        guard += 1
        if e == e0:
            break
        if guard > 64:
            return 0
    before = _worst_around(T, e0)
    ox = T.xy[2 * v]
    oy = T.xy[2 * v + 1]
    T.xy[2 * v] = sx / n
    T.xy[2 * v + 1] = sy / n
    after = _worst_around(T, e0)
    if after >= before - 0.02:
        e = e0
        while True:
            if orient2d(P(T, T.tv[e]), P(T, T.tv[nxt(e)]), P(T, T.tv[prv(e)])) <= 0:
                break
            e = T.twin[prv(e)]
            if e == e0:
                return 1
    T.xy[2 * v] = ox
    T.xy[2 * v + 1] = oy
    return 0


cdef int smooth(Tri* T, int first_movable, int passes) noexcept nogil:
    """`passes` rounds of smoothing of vertices first_movable.. and Delaunay flips.
    Returns the number of vertex moves, or an error."""
    cdef int p, v, t, k, n, res, moved = 0
    for p in range(passes):
        for v in range(first_movable, T.nv):
            moved += _smooth_vertex(T, v)
        if reserve_stack(T, 3 * T.nt):
            return ERR_NOMEM
        n = 0
        for t in range(T.nt):
            if T.tstate[t] == T_MESHED:
                for k in range(3):
                    T.stack[n] = 3 * t + k
                    n += 1
        res = legalize_meshed(T, n)
        if res < 0:
            return res
    return moved
