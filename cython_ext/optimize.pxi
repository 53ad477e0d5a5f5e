# Optimization-based vertex moves for smooth() (smoothing.pxi).
#
# A vertex that Basic_aft created moves to the place that most lowers the cost of its
# triangles, the sum of 1 / shape^2 (shape: _shape(), 1 when equilateral): the mean of
# its neighbours when that lowers the cost, then (in the rounds that take them, and
# at a vertex next to a bad triangle: OPT_DESCEND_BELOW) a few steps along the cost's
# gradient.  (The optimal-Delaunay point and two steps towards the worst triangle's
# ideal apex were candidates too: in earcut-rain's first round they won about 8 % of
# the moves, and spending their trials on more gradient steps raised the real-world
# group's mean radius ratio, for fewer trials.)
# The cost is dominated by the worst triangle but, unlike the worst shape alone, it
# also rewards improving the others, so a vertex next to a triangle no move can mend
# (a short input edge) still settles the rest.  A move is kept only when it lowers the
# cost, does not lower the worst shape around the vertex and leaves every triangle
# counter-clockwise (exact orient2d), and then Lawson flips restore the CDT around it
# at once: only the edges of its triangles can have become illegal, and each next
# vertex is judged on the swapped mesh.

cdef enum:
    OPT_RING_CAP = 64           # a vertex of more triangles than this is left alone

# a vertex whose triangles all have a shape above this is left alone (on a uniform
# size most are, which saves most of the work there); near equilateral, a shape is
# about the radius ratio.  0.985 left the real-world group's mean radius ratio 0.0004
# lower (every case lower or level); 0.999 gained nothing more; 0.97 in the rounds of
# means only (the descent still judging those vertices) left it 0.0003 lower, with
# 208 more triangles of radius ratio <= 0.9
cdef double OPT_SKIP = 0.995
# descent step lengths tried along the negative gradient, as fractions of the mean
# edge length around the vertex.  After the neighbours' mean a vertex is close to its
# best place: on the real-world group and four main-table cases a fourth, longer
# length (0.2) won 0.4 % of the descents' first steps and was tried, in vain, at the
# start of nearly every one; without it the group's quality is the same (mean radius
# ratio level, 30 fewer poor triangles) for 1.3-1.7 % fewer kernel instructions
cdef enum:
    OPT_DESCENT_LENGTHS = 3
cdef double[OPT_DESCENT_LENGTHS] OPT_DESCENT = [0.08, 0.03, 0.01]
# gradient steps per visit, each the longest of OPT_DESCENT (from the previous step's
# length down) that improves: one step, even with the candidates above, left the
# real-world group's mean radius ratio 0.0003 lower, and six gained no more than four
cdef int OPT_DESCENT_STEPS = 4
# the descent stops after a step that lowered the cost by less than this fraction of
# it: the vertex is then about at its best place, and the next step (a gradient and
# at least one trial) would gain less still.  On the real-world group 3e-4 left the
# mean radius ratio level and 54 fewer poor triangles, for 4-6 % fewer kernel
# instructions; 1e-3 lowered 21 of its 32 cases' means by 0.0001-0.0002, and 1e-2
# (measured with the 0.2 length still tried) earcut-hilbert's by 0.003
cdef double OPT_STOP_DECREASE = 3e-4
# a cost this large means a triangle turned over (or went flat) at the trial place
cdef double OPT_INVALID = 1e300
# a trial place must lower the cost by this fraction: rounding is not progress.  Most
# moves are small but not idle: on the real-world group 1e-4 (6 % fewer moves) saved
# 1-2 % of the instructions for 71 more triangles of radius ratio <= 0.9, 1e-3 (30 %
# fewer) 4-7 % for 2,234 more, and 1e-3 on the neighbours' mean only 1-4 % for 380
cdef double OPT_MIN_DECREASE = 1e-9
# smoothing's rounds before the last try only the neighbours' mean (smoothing.pxi's
# Descent), except at a vertex next to a triangle shaped worse than this, which takes
# the gradient steps in every round: the rounds of means are for the many nearly good
# vertices, and the few bad ones need every step.  Without it the real-world group
# has as many triangles of radius ratio <= 0.9, one case fewer with 97 % above 0.9,
# and test_valence's plate 16 % more, for 2-3 % fewer kernel instructions; with the
# split points' steps in the last round only, 0.8 / 0.85 / 0.9 / 0.95 left the group
# 44361 / 44207 / 44160 / 43919 such triangles, for 3.5 / 2.4 / 0.1 % fewer and 4 %
# more instructions than three rounds with the steps in each (44892)
cdef double OPT_DESCEND_BELOW = 0.85
# a place _cost_at took with every shape at least this has every triangle
# counter-clockwise by the exact test too, which is then skipped: the float twice-area
# it computes is within 2.1 units of rounding (1.1e-16) of the squared lengths' sum S
# of the exact one, and a shape q means a float twice-area of q S / 3.46
cdef double OPT_ORIENT_PROVEN = 1e-12


cdef struct Ring:
    # The ring of the vertex v being moved, gathered once per visit so that each trial
    # place costs one pass over flat arrays: triangle i is (v, n_i, n_(i+1)), with
    # n_n = n_0 stored at the end.  Its edge opposite v does not move with v, so the
    # squares of that edge's components are kept too.
    int n
    double x[OPT_RING_CAP + 1]
    double y[OPT_RING_CAP + 1]
    double ox2[OPT_RING_CAP]
    double oy2[OPT_RING_CAP]


cdef double _cost_at(const Ring* R, double x, double y, double worst0) noexcept nogil:
    """Sum of 1 / shape^2 over the ring's triangles with v at (x, y), or OPT_INVALID
    as soon as one shape is below worst0 (> 0): such a place is never taken, since a
    move may not lower the worst shape, and this also refuses flat and inverted
    triangles.  Each shape is _shape()'s expression term for term, so it rounds the
    same."""
    cdef int i
    cdef double ax = R.x[0] - x, ay = R.y[0] - y, bx, by, sa, s, q, cost = 0.0
    sa = ax * ax + ay * ay
    for i in range(R.n):
        bx = R.x[i + 1] - x
        by = R.y[i + 1] - y
        s = sa + bx * bx + by * by + R.ox2[i] + R.oy2[i]
        q = 3.4641016151377544 * (ax * by - ay * bx) / s
        if q < worst0:
            return OPT_INVALID
        cost += 1.0 / (q * q)
        ax = bx
        ay = by
        sa = bx * bx + by * by
    return cost


cdef void _cost_gradient(const Ring* R, double x, double y, double* gx,
                         double* gy) noexcept nogil:
    """The gradient of _cost_at in (x, y), in closed form: with a = n_i - v,
    b = n_(i+1) - v, twice the area A = a x b and S the sum of squared edge lengths,
    a triangle costs S^2 / (k A)^2, whose derivative is 2 S (A dS - S dA) / (k^2 A^3)
    with dA = (a_y - b_y, b_x - a_x) and dS = -2 (a + b).  Left at 0 when a triangle
    is flat or inverted (its cost is then OPT_INVALID, and no step is taken)."""
    cdef int i
    cdef double ax = R.x[0] - x, ay = R.y[0] - y, bx, by, A, S, f
    gx[0] = 0.0
    gy[0] = 0.0
    for i in range(R.n):
        bx = R.x[i + 1] - x
        by = R.y[i + 1] - y
        A = ax * by - ay * bx
        if not A > 0.0:
            gx[0] = 0.0
            gy[0] = 0.0
            return
        S = ax * ax + ay * ay + bx * bx + by * by + R.ox2[i] + R.oy2[i]
        f = 2.0 * S / (12.0 * A * A * A)          # k^2 = 12
        gx[0] += f * (-2.0 * A * (ax + bx) - S * (ay - by))
        gy[0] += f * (-2.0 * A * (ay + by) - S * (bx - ax))
        ax = bx
        ay = by


cdef int _gather_ring(Tri* T, int v, int e0, Ring* R, double* q) noexcept nogil:
    """Walk around v once: its ring into R and each triangle's shape into q.  Returns
    the number of triangles, or 0 when v must stay (next to a triangle that is not
    meshed or to the outside, or more than OPT_RING_CAP triangles)."""
    cdef int e = e0, n = 0, u, w
    cdef double* pu
    cdef double* pw
    cdef double* pv = P(T, v)
    while True:
        u = T.tv[nxt_nb(e)]
        w = T.tv[prv_nb(e)]
        if u < 0 or w < 0 or T.tstate[tri_of(e)] != T_MESHED or n >= OPT_RING_CAP:
            return 0
        pu = P(T, u)
        pw = P(T, w)
        R.x[n] = pu[0]
        R.y[n] = pu[1]
        R.ox2[n] = (pw[0] - pu[0]) * (pw[0] - pu[0])
        R.oy2[n] = (pw[1] - pu[1]) * (pw[1] - pu[1])
        q[n] = _shape(pv, pu, pw)
        n += 1
        e = T.twin[prv_nb(e)]
        if e == e0:
            break
    R.n = n
    R.x[n] = R.x[0]
    R.y[n] = R.y[0]
    return n


cdef void _laplacian(const Ring* R, double* lap) noexcept nogil:
    """From the gathered ring: lap[0:2] the mean of v's neighbours."""
    cdef int i, n = R.n
    lap[0] = 0.0
    lap[1] = 0.0
    for i in range(n):
        lap[0] += R.x[i]
        lap[1] += R.y[i]
    lap[0] /= n
    lap[1] /= n


cdef double _mean_length(const Ring* R, const double* pv) noexcept nogil:
    """The mean length of the edges from v (at pv) to its gathered neighbours: the
    unit of the gradient steps (only a vertex that takes them needs it)."""
    cdef int i, n = R.n
    cdef double lsum = 0.0
    for i in range(n):
        lsum += sqrt((R.x[i] - pv[0]) ** 2 + (R.y[i] - pv[1]) ** 2)
    return lsum / n


cdef double _cost_of_shapes(const double* q, int n, double* worst) noexcept nogil:
    """_cost_at at v's own place, from the shapes _gather_ring measured there (the
    same expressions, so the same values)."""
    cdef int i
    cdef double cost = 0.0
    worst[0] = 2.0
    for i in range(n):
        if q[i] < worst[0]:
            worst[0] = q[i]
        if q[i] <= 0.0:
            return OPT_INVALID
        cost += 1.0 / (q[i] * q[i])
    return cost


cdef inline bint _settled(double cost, double before) noexcept nogil:
    """A step from a place of cost `before` to one of `cost` (better) was the
    descent's last: see OPT_STOP_DECREASE."""
    return cost > before * (1.0 - OPT_STOP_DECREASE)


cdef inline bint _better(double cost, double best_cost) noexcept nogil:
    """A trial place is better when it lowers the cost (_cost_at has already refused
    every place that lowers the worst shape)."""
    return cost < best_cost * (1.0 - OPT_MIN_DECREASE)


cdef void _descend(const Ring* R, double L, double worst0, double* bx, double* by,
                   double* best) noexcept nogil:
    """Up to OPT_DESCENT_STEPS steps from (bx, by) against the cost's gradient, each
    the longest of OPT_DESCENT that improves, starting from the last step's length,
    until one gains little (_settled); updates (bx, by) and best."""
    cdef double gx, gy, g, c, x, y
    cdef int k, it, k0 = 0
    cdef bint stepped, settled = False
    for it in range(OPT_DESCENT_STEPS):
        _cost_gradient(R, bx[0], by[0], &gx, &gy)
        g = sqrt(gx * gx + gy * gy)
        if not (g > 0.0 and g < INFINITY):
            return                      # flat, or at an invalid place
        stepped = False
        for k in range(k0, OPT_DESCENT_LENGTHS):
            x = bx[0] - OPT_DESCENT[k] * L * gx / g
            y = by[0] - OPT_DESCENT[k] * L * gy / g
            c = _cost_at(R, x, y, worst0)
            if _better(c, best[0]):
                settled = _settled(c, best[0])
                bx[0] = x
                by[0] = y
                best[0] = c
                stepped = True
                k0 = k
                break
        if not stepped or settled:
            return


cdef int _optimize_vertex(Tri* T, int v, bint swaps, bint descend) noexcept nogil:
    """Move v to the best of the places tried (see the top of this file; without
    `descend`, the neighbours' mean only, unless a triangle of v is shaped worse than
    OPT_DESCEND_BELOW) when that lowers the cost of its triangles without lowering
    their worst shape, and every triangle stays counter-clockwise by the exact
    orient2d; then, with `swaps`, restore the CDT around it.  A vertex that may not
    move (see _gather_ring), or whose triangles are all shaped better than OPT_SKIP,
    stays.  Returns 1 if v moved, 0 if not, or an error."""
    cdef int e0 = T.vhe[v], n
    cdef Ring R
    cdef double lap[2]
    cdef double q[OPT_RING_CAP]
    cdef double worst0, c, best, bx, by
    cdef double cx = T.xy[2 * v], cy = T.xy[2 * v + 1]
    cdef bint descended
    if e0 < 0:
        return 0
    n = _gather_ring(T, v, e0, &R, q)
    if n == 0:
        return 0
    best = _cost_of_shapes(q, n, &worst0)
    if worst0 > OPT_SKIP or best >= OPT_INVALID:
        return 0
    _laplacian(&R, lap)
    bx = cx
    by = cy
    c = _cost_at(&R, lap[0], lap[1], worst0)
    if _better(c, best):
        best = c
        bx = lap[0]
        by = lap[1]
    descended = _takes_steps(descend, worst0)
    if descended:
        _descend(&R, _mean_length(&R, P(T, v)), worst0, &bx, &by, &best)
    if bx == cx and by == cy:
        return _stayed(T, v, descended)
    T.xy[2 * v] = bx
    T.xy[2 * v + 1] = by
    if worst0 < OPT_ORIENT_PROVEN and not _ring_ccw(T, v):
        T.xy[2 * v] = cx
        T.xy[2 * v + 1] = cy
        return _stayed(T, v, descended)
    return _legalize_around(T, v) if swaps else 1


cdef inline bint _takes_steps(bint descend, double worst0) noexcept nogil:
    # the gradient steps after the mean: in the rounds that take them, and next to a
    # triangle shaped worse than OPT_DESCEND_BELOW (worst0) in every round
    return descend or worst0 < OPT_DESCEND_BELOW


cdef inline int _stayed(Tri* T, int v, bint descended) noexcept nogil:
    # v stays (returns 0); if only the neighbours' mean was tried, the descent's
    # round is to judge it again (smoothing.pxi's _smooth_rounds)
    if not descended and T.vdirty != NULL:
        T.vdirty[v] = V_OWES_DESCENT
    return 0


cdef bint _ring_ccw(Tri* T, int v) noexcept nogil:
    """Every triangle around v (none of them a ghost) is counter-clockwise, by the
    exact orient2d: the test a trial place must pass once the float cost took it."""
    cdef int e0 = T.vhe[v], e = e0
    while True:
        if orient2d(P(T, T.tv[e]), P(T, T.tv[nxt_nb(e)]), P(T, T.tv[prv_nb(e)])) <= 0:
            return False
        e = T.twin[prv_nb(e)]
        if e == e0:
            return True


cdef int _legalize_around(Tri* T, int v) noexcept nogil:
    """Lawson flips after v moved, starting from the edges of its triangles (the only
    ones whose four points include v).  Returns 1, or an error."""
    cdef int e0 = T.vhe[v], e = e0, n = 0, res
    if not _ring_needs_flips(T, v):
        return 1
    if reserve_stack(T, 2 * OPT_RING_CAP):
        return ERR_NOMEM
    while True:
        # the spoke leaving v and the edge opposite v: each spoke is also the edge
        # entering v of the triangle before, so it is pushed once
        T.stack[n] = e
        T.stack[n + 1] = nxt_nb(e)
        n += 2
        e = T.twin[prv_nb(e)]
        if e == e0 or n >= 2 * OPT_RING_CAP:
            break
    res = legalize_meshed(T, n)
    return res if res < 0 else 1


cdef bint _ring_needs_flips(Tri* T, int v) noexcept nogil:
    """Would legalize_meshed flip any of the edges _legalize_around gives it?  The
    same test on the same edges of the unchanged mesh, without the stack: nearly every
    move leaves them all legal (one flip in about 200 moves on earcut-rain), and when
    one is illegal the stack run tests again from the start, so the flips, and the
    mesh, are exactly those of the stack run alone.

    It is illegal_meshed_edge's test, each predicate given the same points in the
    same argument order, taken in one walk around v: each ring vertex is read once,
    and a spoke's two triangles are the walk's current and previous ones (their
    states known), so the angles facing it come from the two triangles' own passes."""
    cdef int e0 = T.vhe[v], e = e0
    cdef double* pv = P(T, v)
    cdef double* pu
    cdef double* pw
    cdef double* pu_prev = NULL     # the previous triangle's u: across e's spoke
    cdef double* pu0 = NULL         # the first triangle's u and w, for e0's spoke
    cdef double* pw0 = NULL
    cdef bint meshed, meshed_prev = False, meshed0 = False
    cdef bint at_u_prev = False     # the previous triangle's angle at its u is acute
    while True:
        meshed = T.tstate[tri_of(e)] == T_MESHED
        if meshed:
            pu = P(T, T.tv[nxt_nb(e)])
            pw = P(T, T.tv[prv_nb(e)])
            if _opposite_illegal(T, nxt_nb(e), pu, pw, pv):
                return True
            if e == e0:
                pu0 = pu
                pw0 = pw
                meshed0 = True
            elif meshed_prev and _spoke_illegal(T, e, pv, pu, pw, pu_prev, at_u_prev):
                return True
            at_u_prev = surely_acute(pw, pv, pu)
            pu_prev = pu
        meshed_prev = meshed
        e = T.twin[prv_nb(e)]
        if e == e0:
            break
    # e0's spoke: its other triangle is the walk's last
    return (meshed0 and meshed_prev
            and _spoke_illegal(T, e0, pv, pu0, pw0, pu_prev, at_u_prev))


cdef inline bint _spoke_illegal(Tri* T, int e, const double* pv, const double* pu,
                                const double* pw, const double* pd,
                                bint at_d_acute) noexcept nogil:
    # illegal_meshed_edge(T, e) for the spoke e = v -> u of the meshed triangle
    # (v, u, w), whose twin's meshed triangle has apex d (at_d_acute: its angle at d
    # is surely acute, surely_acute(u, v, d))
    if T.eflag[e] & (E_SEGMENT | E_FIXED):
        return False
    if surely_acute(pv, pu, pw) and at_d_acute:
        return False
    return incircle(pv, pu, pw, pd) > 0


cdef inline bint _opposite_illegal(Tri* T, int o, const double* pu, const double* pw,
                                   const double* pv) noexcept nogil:
    # illegal_meshed_edge(T, o) for the edge o = u -> w of the meshed triangle (v, u, w)
    cdef int f = T.twin[o]
    cdef const double* pd
    if T.tstate[tri_of(f)] != T_MESHED or T.eflag[o] & (E_SEGMENT | E_FIXED):
        return False
    pd = P(T, T.tv[prv_nb(f)])
    if surely_acute(pu, pw, pv) and surely_acute(pw, pu, pd):
        return False
    return incircle(pu, pw, pv, pd) > 0
