# Moves of split points along their input segment, for smooth() (smoothing.pxi).
#
# The boundary's discretization spaces the points that split an input segment by the
# size alone, before any triangle exists.  Where the front then closes against such a
# point at a poor angle (a short piece, a size that changes along the segment, a
# corner's neighbour), no move of the interior vertices mends the triangle on the
# piece (on the real-world group's touching-holes6, two thirds of the poor triangles
# next to the boundary had a split point as a vertex).  A split point may move along
# its segment without changing the domain, so smoothing slides it there too:
#
# * its place is computed on the line of its chain's ends (chains.pxi), a + t (b - a),
#   as every split point is, so it stays within the rounding of its input segment
#   (ARCHITECTURE.md's rounding rules);
# * the places tried are optimize.pxi's, restricted to that line: the neighbours' mean
#   projected on it, then steps along it, judged by optimize.pxi's cost over the
#   meshed triangles around it (one side of a boundary segment, both sides of an
#   interface);
# * a place is kept only when it lowers that cost without lowering the worst shape,
#   and every triangle around the point, outside the domain too, stays
#   counter-clockwise (exact orient2d); then Lawson flips restore the CDT around it.
#   Sliding past a neighbour on the segment would turn the triangle on that piece
#   over, so the order of the points on the segment is kept.
#
# A point on the convex hull stays: its ghost triangles would need the hull's
# convexity checked at it and at its hull neighbours, and on the real-world group
# that gained a mean radius ratio of 2e-5.  So does a point with more than
# OPT_RING_CAP triangles around it (so that _legalize_around reaches all of them).
#
# Uses: halfedge.pxd; optimize.pxi (Ring, _cost_at, _cost_gradient, _laplacian,
# _mean_length, _cost_of_shapes, _better, _settled, _ring_ccw, _takes_steps, _stayed,
# _legalize_around, OPT_SKIP, OPT_DESCENT, OPT_DESCENT_LENGTHS, OPT_DESCENT_STEPS,
# OPT_RING_CAP, OPT_INVALID);
# smoothing.pxi (_shape).
from halfedge cimport *
from libc.math cimport sqrt, INFINITY


cdef int _fan_start(Tri* T, int v) noexcept nogil:
    """A segment piece leaving v whose triangle is meshed (where the fan of
    _gather_fan starts), or NONE when v may not slide: a ghost triangle around it,
    not exactly two segment pieces at it, neither piece's triangle meshed, or more
    than OPT_RING_CAP triangles around it."""
    cdef int e0 = T.vhe[v], e = e0, s = NONE, pieces = 0, n = 0
    if e0 < 0:
        return NONE
    while True:
        if T.tv[nxt_nb(e)] == GHOST or T.tv[prv_nb(e)] == GHOST or n >= OPT_RING_CAP:
            return NONE
        if T.eflag[e] & E_SEGMENT:
            pieces += 1
            if T.tstate[e // 3] == T_MESHED:
                s = e
        n += 1
        e = T.twin[prv_nb(e)]
        if e == e0:
            break
    return s if pieces == 2 else NONE


cdef int _gather_fan(Tri* T, int v, int s, Ring* R, double* q) noexcept nogil:
    """From piece s around v, the meshed triangles into R and their shapes into q:
    up to the other piece when the triangle beyond it is not meshed (an open fan),
    else all the way round (a closed ring).  Returns their number, or 0 when a
    triangle that is not meshed lies between the two pieces."""
    cdef int e = s, n = 0, u, w
    cdef double* pu
    cdef double* pw
    cdef double* pv = P(T, v)
    while True:
        if T.tstate[e // 3] != T_MESHED:
            return 0
        u = T.tv[nxt_nb(e)]
        w = T.tv[prv_nb(e)]
        pu = P(T, u)
        pw = P(T, w)
        R.x[n] = pu[0]
        R.y[n] = pu[1]
        R.ox2[n] = (pw[0] - pu[0]) * (pw[0] - pu[0])
        R.oy2[n] = (pw[1] - pu[1]) * (pw[1] - pu[1])
        q[n] = _shape(pv, pu, pw)
        n += 1
        e = T.twin[prv_nb(e)]
        if e == s or ((T.eflag[e] & E_SEGMENT) and T.tstate[e // 3] != T_MESHED):
            break
    R.n = n
    R.x[n] = P(T, T.tv[nxt_nb(e)])[0]
    R.y[n] = P(T, T.tv[nxt_nb(e)])[1]
    return n


cdef struct Line:
    # the line a + t d of a chain, and the length unit of the descent along it
    double ax, ay, dx, dy, L2, step


cdef inline void _on_line(const Line* G, double t, double* x, double* y) noexcept nogil:
    x[0] = G.ax + t * G.dx
    y[0] = G.ay + t * G.dy


cdef inline double _param(const Line* G, double x, double y) noexcept nogil:
    return ((x - G.ax) * G.dx + (y - G.ay) * G.dy) / G.L2


cdef void _descend_on_line(const Ring* R, const Line* G, double worst0, double* bt,
                           double* bx, double* by, double* best) noexcept nogil:
    """optimize.pxi's _descend restricted to the line: up to OPT_DESCENT_STEPS steps
    along it against the cost's slope, each the longest that improves, until one
    gains little (_settled)."""
    cdef double gx, gy, slope, c, x, y, t
    cdef int k, it, k0 = 0
    cdef bint stepped, settled = False
    for it in range(OPT_DESCENT_STEPS):
        _cost_gradient(R, bx[0], by[0], &gx, &gy)
        slope = gx * G.dx + gy * G.dy
        if not (slope != 0.0 and slope > -INFINITY and slope < INFINITY):
            return                      # flat, or at an invalid place
        stepped = False
        for k in range(k0, OPT_DESCENT_LENGTHS):
            t = bt[0] - (OPT_DESCENT[k] * G.step if slope > 0 else -OPT_DESCENT[k] * G.step)
            _on_line(G, t, &x, &y)
            c = _cost_at(R, x, y, worst0)
            if _better(c, best[0]):
                settled = _settled(c, best[0])
                bt[0] = t
                bx[0] = x
                by[0] = y
                best[0] = c
                stepped = True
                k0 = k
                break
        if not stepped or settled:
            return


cdef int slide_vertex(Tri* T, int v, int a, int b, bint swaps, bint descend) noexcept nogil:
    """Move split point v along the line of its chain's ends a, b to the best of the
    places tried (see the top of this file; without `descend`, the neighbours' mean's
    foot on the line only, as in _optimize_vertex); then, with `swaps`, restore the
    CDT around it.  Returns 1 if v moved, 0 if not, or an error."""
    cdef int s = _fan_start(T, v), n
    cdef Ring R
    cdef Line G
    cdef double lap[2]
    cdef double q[OPT_RING_CAP]
    cdef double worst0, c, best, x, y, t, bt, bx, by
    cdef double cx = T.xy[2 * v], cy = T.xy[2 * v + 1]
    cdef bint descended
    if s == NONE:
        return 0
    n = _gather_fan(T, v, s, &R, q)
    if n == 0:
        return 0
    best = _cost_of_shapes(q, n, &worst0)
    if worst0 > OPT_SKIP or best >= OPT_INVALID:
        return 0
    G.ax = T.xy[2 * a]
    G.ay = T.xy[2 * a + 1]
    G.dx = T.xy[2 * b] - G.ax
    G.dy = T.xy[2 * b + 1] - G.ay
    G.L2 = G.dx * G.dx + G.dy * G.dy
    if not G.L2 > 0.0:
        return 0
    _laplacian(&R, lap)
    bt = _param(&G, cx, cy)
    bx = cx
    by = cy
    t = _param(&G, lap[0], lap[1])
    _on_line(&G, t, &x, &y)
    c = _cost_at(&R, x, y, worst0)
    if _better(c, best):
        best = c
        bt = t
        bx = x
        by = y
    descended = _takes_steps(descend, worst0)
    if descended:
        G.step = _mean_length(&R, P(T, v)) / sqrt(G.L2)
        _descend_on_line(&R, &G, worst0, &bt, &bx, &by, &best)
    if bx == cx and by == cy:
        return _stayed(T, v, descended)
    T.xy[2 * v] = bx
    T.xy[2 * v + 1] = by
    if not _ring_ccw(T, v):
        T.xy[2 * v] = cx
        T.xy[2 * v + 1] = cy
        return _stayed(T, v, descended)
    return _legalize_around(T, v) if swaps else 1
