# Smoothing after the front has closed (optional, on by default in generate()).
#
# Each pass moves vertices that Basic_aft created by optimize.pxi's _optimize_vertex,
# and slides the points that split an input segment along it by sliding.pxi's
# slide_vertex (the input vertices never move).  Both keep every triangle
# counter-clockwise (exact orient2d) and restore the constrained Delaunay property by
# Lawson flips around each moved vertex, so the result is still the CDT of its
# vertices and the input edges.
#
# _shape is the quality measure optimize.pxi's moves are judged by.  The rounds before
# the last try each vertex at its neighbours' mean only, and the last adds the
# gradient steps (Descent below); the rounds that settle new points take them in
# every round.
#
# With VALENCE_ROUNDS rounds or more, the valence flips (valence.pxi) come after the
# first round: the second round then moves the vertices without swaps, the Delaunay
# property is restored from every triangle that changed, and the rounds go on.  The
# valence splits (valence.pxi) come with them: once before the first round, on the
# mesh the front left, and once after the last round for the few vertices the flips
# and moves left in eight triangles or more, followed by SPLIT_SETTLE_ROUNDS rounds
# from the new points.
#
# settle_refined runs the same rounds once more after the minimum-angle pass
# (refine.pxi's refine_settled), only around the points the pass added and without
# valence flips; the pass's own splits slide there too (they are inside chains).
#
# Uses: halfedge.pxd (Tri.vdirty, which triangulation.pxi's legalize_meshed sets);
# aft.pxd (Aft); front.pxi (check_signals); optimize.pxi (_optimize_vertex);
# sliding.pxi (slide_vertex); chains.pxi (chain_ends); valence.pxi (valence_flips,
# valence_splits); triangulation.pxi (legalize_meshed, reserve_stack).
from halfedge cimport *
from aft cimport Aft
from libc.stdlib cimport malloc, calloc, free, realloc
from libc.string cimport memset
from libc.stdint cimport uint8_t, int32_t

# The valence flips need a round before them (vertices settled where the front left
# them), the settling round after them, and a round once the Delaunay swaps have run:
# with fewer rounds, smoothing is what it was without them.
cdef enum:
    VALENCE_ROUNDS = 3
    # rounds from the points the last valence splits add (they stop early when a
    # round moves nothing): with the splits after the last round only, 2 rounds left
    # the real-world group 1 % more triangles of radius ratio <= 0.9 than 5, and 8
    # removed 0.4 % more
    SPLIT_SETTLE_ROUNDS = 5


# Which rounds of a _smooth_rounds call take the gradient steps after the neighbours'
# mean (optimize.pxi; a vertex next to a triangle shaped worse than OPT_DESCEND_BELOW
# takes them in every round).  A round of means costs about half a full one and does
# most of the moving; the steps polish, and pay once, at the end.  On the real-world
# group, four rounds with the steps in the last only left 1.2 % fewer triangles of
# radius ratio <= 0.9 than three rounds with them in each, and one more case with 97 %
# above 0.9, for 1-2 % fewer kernel instructions on its cases and as many on the
# uniform square; three rounds with them in the last only (and nowhere else) left
# 1.2 % more, for 8-9 % fewer.  The rounds of means converge fast (the judged
# vertices' cost falls by about 3 %, 0.5-1 % and 0.1 % in the three), but going
# straight to the last round once a round of means had lowered it by less than 0.5 %
# saved instructions only where the mesh is nearly uniform (comb 6.7 %, the square
# 1.2 %) and cost the group 92 more such triangles (comb's mean radius ratio 0.0004
# lower); below 0.2 %, hardly a case skipped a round.
cdef enum Descent:
    DESCENT_NONE = 0    # no round (but at the vertices next to a bad triangle)
    DESCENT_EVERY = 1   # every round (the settling rounds around new points)
    DESCENT_LAST = 2    # the last round, which also judges the vertices that stayed


cdef struct Movable:
    # which vertices smoothing may move: from first_sliding on, a vertex inside a chain
    # slides along it, and the others from first_movable on move freely
    int first_sliding   # the first vertex that may slide
    int first_movable   # Basic_aft's vertices (and the minimum-angle pass's) from here
    int32_t* vend       # the ends of each point's chain (chains.pxi); NULL: none slide


cdef inline double _shape(const double* a, const double* b, const double* c) noexcept nogil:
    """4 sqrt(3) area / (sum of squared edge lengths): 1 for an equilateral triangle,
    0 for a degenerate one, negative when inverted (a cheap, smooth quality measure)."""
    cdef double abx = b[0] - a[0], aby = b[1] - a[1]
    cdef double acx = c[0] - a[0], acy = c[1] - a[1]
    cdef double bcx = c[0] - b[0], bcy = c[1] - b[1]
    cdef double area2 = abx * acy - aby * acx
    cdef double s = abx * abx + aby * aby + acx * acx + acy * acy + bcx * bcx + bcy * bcy
    return 3.4641016151377544 * area2 / s


cdef int smooth(Aft* A, Tri* T, int first_movable, int passes, bint valence=True,
                int n_corner=-1) noexcept nogil:
    """Up to `passes` rounds of moves of vertices first_movable.. (optimize.pxi), and
    of the split points n_corner..first_movable along their segments (sliding.pxi;
    n_corner: the number of input vertices, -1 or first_movable for none), each
    followed by Delaunay flips; the rounds before the last try the neighbours' means
    only (Descent; they stop early when one moves nothing), the last adds the
    gradient steps; signals are checked after each round.  With `valence` and at
    least VALENCE_ROUNDS rounds, the valence flips come after the first, and the
    valence splits before the first and after the last (see the top of this file):
    the mesh may gain vertices, from T.nv on.  Returns the number of vertex moves, or
    an error.

    After the first round a vertex is judged again only if it moved or its ring
    changed since it was last judged (a neighbour moved, or a flip touched it), or,
    for the last round, if it stayed where only the mean was tried (T.vdirty's marks):
    the judgement depends on nothing else, so the others would stay where they are."""
    cdef int res = 0, moved
    cdef Movable M
    cdef uint8_t* dirty
    cdef bint topology = valence and passes >= VALENCE_ROUNDS and first_movable < T.nv
    if topology:
        res = valence_splits(A, T, first_movable, True)
        if res < 0:
            return res
        res = 0
    dirty = <uint8_t*> malloc(T.nv if T.nv > 0 else 1)
    M.first_movable = first_movable
    M.first_sliding = n_corner if 0 <= n_corner < first_movable else first_movable
    M.vend = NULL
    if M.first_sliding < first_movable:
        M.vend = <int32_t*> malloc(2 * T.nv * sizeof(int32_t))
        res = ERR_NOMEM if M.vend == NULL else chain_ends(T, M.first_sliding, M.vend)
    if dirty == NULL or res < 0:
        free(dirty)
        free(M.vend)
        return ERR_NOMEM if dirty == NULL else res
    memset(dirty, V_CHANGED, T.nv)
    T.vdirty = dirty
    if topology:
        res = _smooth_with_valence(A, T, &M, passes)
    else:
        res = _smooth_rounds(A, T, &M, passes, NULL, True, DESCENT_LAST)
    T.vdirty = NULL
    free(dirty)
    if topology and res >= 0:
        moved = _split_and_settle(A, T, &M)
        res = moved if moved < 0 else res + moved
    free(M.vend)
    return res


cdef int _split_and_settle(Aft* A, Tri* T, Movable* M) noexcept nogil:
    """The valence splits after the last round, then SPLIT_SETTLE_ROUNDS rounds from
    the new points (settle_refined; M.vend, when set, grows to cover them: none of
    them slides).  Returns the number of moves, or an error."""
    cdef int nv0 = T.nv, v, res
    cdef int32_t* grown
    res = valence_splits(A, T, M.first_movable, False)
    if res <= 0:
        return res
    if M.vend != NULL:
        grown = <int32_t*> realloc(M.vend, 2 * T.nv * sizeof(int32_t))
        if grown == NULL:
            return ERR_NOMEM
        M.vend = grown
        for v in range(2 * nv0, 2 * T.nv):
            M.vend[v] = -1
    return settle_refined(A, T, nv0, M.first_movable, M.vend, SPLIT_SETTLE_ROUNDS)


cdef int _smooth_with_valence(Aft* A, Tri* T, const Movable* M, int passes) noexcept nogil:
    """A round, the valence flips, a settling round without swaps, the Delaunay
    swaps from every triangle with a flipped or moved vertex, the other rounds."""
    cdef int moved, res, flips, left = passes - 1
    cdef uint8_t* touched = <uint8_t*> calloc(T.nv if T.nv > 0 else 1, 1)
    if touched == NULL:
        return ERR_NOMEM
    moved = _smooth_rounds(A, T, M, 1, NULL, True, DESCENT_NONE)
    flips = valence_flips(T, M.first_movable, touched) if moved >= 0 else 0
    res = flips
    if flips > 0:
        res = _smooth_rounds(A, T, M, 1, touched, False, DESCENT_NONE)
        if res >= 0:
            moved += res
            left -= 1
            res = _legalize_touched(T, touched)
    free(touched)
    if moved < 0 or res < 0:
        return moved if moved < 0 else res
    res = _smooth_rounds(A, T, M, left, NULL, True, DESCENT_LAST)
    return res if res < 0 else moved + res


cdef int _legalize_touched(Tri* T, const uint8_t* touched) noexcept nogil:
    """Lawson flips from the edges of every meshed triangle with a touched vertex."""
    cdef int t, n = 0
    if reserve_stack(T, 3 * T.nt):
        return ERR_NOMEM
    for t in range(T.nt):
        if T.tstate[t] != T_MESHED:
            continue
        if touched[T.tv[3 * t]] or touched[T.tv[3 * t + 1]] or touched[T.tv[3 * t + 2]]:
            T.stack[n] = 3 * t
            T.stack[n + 1] = 3 * t + 1
            T.stack[n + 2] = 3 * t + 2
            n += 3
    return legalize_meshed(T, n)


cdef int _smooth_rounds(Aft* A, Tri* T, const Movable* M, int passes, uint8_t* touched,
                        bint swaps, Descent descent) noexcept nogil:
    """`passes` rounds over the marked vertices (see smooth), with gradient steps in
    the rounds `descent` says; without `swaps` the moves leave the Delaunay swaps to
    the caller, and touched (when not NULL) gets every vertex that moved.  A round
    that moves nothing ends the rounds, or, before the last round of DESCENT_LAST,
    the rounds of means alone."""
    cdef int p = 0, v, res, moved = 0, moved_now
    cdef bint descend
    while p < passes:
        descend = descent == DESCENT_EVERY or (descent == DESCENT_LAST and p == passes - 1)
        moved_now = 0
        for v in range(M.first_sliding, T.nv):
            # a vertex that stayed at a round of means is judged again for the descent
            if T.vdirty[v] != V_CHANGED and not (descend and T.vdirty[v] == V_OWES_DESCENT):
                continue
            T.vdirty[v] = V_SETTLED
            if M.vend != NULL and M.vend[2 * v] >= 0:
                res = slide_vertex(T, v, M.vend[2 * v], M.vend[2 * v + 1], swaps, descend)
            elif v >= M.first_movable:
                res = _optimize_vertex(T, v, swaps, descend)
            else:
                continue
            if res < 0:
                return res
            if res:
                _mark_ring(T, v)
                if touched != NULL:
                    touched[v] = 1
            moved_now += res
        moved += moved_now
        if check_signals(A) != 0:
            return ERR_INTERRUPTED
        if moved_now == 0:
            if descend or descent != DESCENT_LAST:
                break
            p = passes - 1                  # the means have settled: on to the descent
        else:
            p += 1
    return moved


cdef void _mark_ring(Tri* T, int v) noexcept nogil:
    """v moved: it and its neighbours are to be judged again."""
    cdef uint8_t* dirty = T.vdirty
    cdef int e0 = T.vhe[v], e = e0, u
    dirty[v] = V_CHANGED
    if e0 < 0:
        return
    while True:
        u = T.tv[nxt_nb(e)]
        if u >= 0:
            dirty[u] = V_CHANGED
        e = T.twin[prv_nb(e)]
        if e == e0 or e < 0:
            return


cdef int settle_refined(Aft* A, Tri* T, int first_new, int first_movable,
                        int32_t* vend, int rounds) noexcept nogil:
    """Smoothing rounds over the vertices added from first_new on (by the
    minimum-angle pass, or the last valence splits) and their neighbours, without
    valence flips: Basic_aft's vertices (first_movable on) and the added interior ones
    move (optimize.pxi), the points inside a chain slide along it (sliding.pxi) when
    vend (chain ends, 2 per vertex) is not NULL.  Returns the number of moves, or an
    error."""
    cdef int res, v
    cdef Movable M
    cdef uint8_t* dirty
    if rounds <= 0 or first_new >= T.nv:
        return 0
    dirty = <uint8_t*> calloc(T.nv, 1)
    if dirty == NULL:
        return ERR_NOMEM
    M.first_movable = first_movable
    M.first_sliding = 0 if vend != NULL else first_movable
    M.vend = vend
    T.vdirty = dirty
    for v in range(first_new, T.nv):
        _mark_ring(T, v)
    res = _smooth_rounds(A, T, &M, rounds, NULL, True, DESCENT_EVERY)
    T.vdirty = NULL
    free(dirty)
    return res
