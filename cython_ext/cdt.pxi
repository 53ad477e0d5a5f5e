# Constrained edges by Cline & Renka's retriangulation (flood fills: domain.pxi).
#
# A new constrained edge a-b is inserted by removing exactly the triangles whose
# interiors it crosses and re-triangulating the two pseudo-polygons on either side of it
# as constrained Delaunay triangulations (Cline & Renka's Theorem 1: the rest of the
# triangulation is untouched and stays a CDT).  The same routine serves the CDT of the
# input domain and Update_internal's edges F and G.  Each new constrained edge carries
# the id of the input segment it is a piece of (eseg, see halfedge.pxd).
#
# Uses: halfedge.pxd; predicates.pxi (orient2d, incircle); triangulation.pxi
# (set_tri, find_edge, reserve_stack, reserve_buf).
from halfedge cimport *

cdef enum:
    # _insert_piece's first guess at the crossed triangles of one piece; it restarts
    # with 4 times more when the walk outgrows it (nothing is modified before that)
    CAVITY_INITIAL_CAP = 64


cdef inline bint _on_ray(Tri* T, int a, int b, int x) noexcept nogil:
    """x is collinear with a-b (checked by the caller): is it on the side of b?"""
    cdef double* pa = P(T, a)
    cdef double* pb = P(T, b)
    cdef double* px = P(T, x)
    return (px[0] - pa[0]) * (pb[0] - pa[0]) + (px[1] - pa[1]) * (pb[1] - pa[1]) > 0


cdef int _first_crossing(Tri* T, int a, int b, int* out) noexcept nogil:
    """Around vertex a, find where the segment a->b leaves a.

    Returns 1 with out = a vertex x on the open segment (a-x is then a collinear piece),
    or 0 with out = the half-edge x->y opposite a of the triangle (a, x, y) whose
    interior the segment enters (x strictly right, y strictly left of a->b)."""
    cdef int e0 = T.vhe[a]
    cdef int e = e0, x, y, ox, oy, guard = 0
    while True:
        x = T.tv[nxt_nb(e)]
        y = T.tv[prv_nb(e)]
        if x != GHOST:
            ox = orient2d(P(T, a), P(T, b), P(T, x))
            if ox == 0 and _on_ray(T, a, b, x):
                out[0] = x
                return 1
            if y != GHOST and ox < 0:
                oy = orient2d(P(T, a), P(T, b), P(T, y))
                if oy > 0:
                    out[0] = nxt_nb(e)
                    return 0
        e = T.twin[prv_nb(e)]
        guard += 1
        if e == e0 or guard > 3 * T.nt + 3:
            return ERR_INTERNAL


cdef int _triangulate_pseudo_polygon(Tri* T, int32_t* chain, int32_t* ext, int32_t* newhe,
                                     int n, int32_t* slots, int* nused, uint8_t state,
                                     int32_t region) noexcept nogil:
    """CDT of the pseudo-polygon chain[0..n] lying to the right of chain[0] -> chain[n].

    The polygon's boundary is the base chain[n] -> chain[0] plus the chain edges
    chain[j] -> chain[j+1], whose outer twins are ext[j] (NONE for an edge whose other
    side is inside the cavity too; newhe[j] receives the new half-edge of every chain
    edge so the caller can pair those).  Each step takes a base (lo, hi) and picks the
    chain vertex c whose circle through chain[lo], chain[hi] holds no other vertex of the
    sub-chain (the constrained Delaunay apex), then goes on with (lo, c) and (c, hi); an
    explicit stack replaces the recursion.  Triangles go into the slots of the removed
    ones.  Returns the half-edge of the top base chain[n] -> chain[0].
    """
    cdef int top = NONE, sp = 0, lo, hi, par, c, j, t, tw0, tw1
    cdef uint8_t f0, f1
    cdef int32_t i0, i1
    if reserve_stack(T, 3 * (n + 2)):
        return ERR_NOMEM
    T.stack[0] = 0
    T.stack[1] = n
    T.stack[2] = NONE
    sp = 3
    while sp > 0:
        sp -= 3
        lo = T.stack[sp]
        hi = T.stack[sp + 1]
        par = T.stack[sp + 2]
        c = lo + 1
        for j in range(lo + 2, hi):
            if incircle(P(T, chain[lo]), P(T, chain[c]), P(T, chain[hi]), P(T, chain[j])) > 0:
                c = j
        t = slots[nused[0]]
        nused[0] += 1
        tw0 = NONE
        f0 = 0
        i0 = -1
        if c == lo + 1:
            newhe[lo] = 3 * t
            tw0 = ext[lo]
            if tw0 >= 0:
                f0 = T.eflag[tw0]
                i0 = T.eseg[tw0]
        tw1 = NONE
        f1 = 0
        i1 = -1
        if hi == c + 1:
            newhe[c] = 3 * t + 1
            tw1 = ext[c]
            if tw1 >= 0:
                f1 = T.eflag[tw1]
                i1 = T.eseg[tw1]
        set_tri(T, t, chain[lo], chain[c], chain[hi], tw0, tw1, par, f0, f1, 0, i0, i1, -1,
                state, region)
        if par == NONE:
            top = 3 * t + 2
        if c > lo + 1:
            T.stack[sp] = lo
            T.stack[sp + 1] = c
            T.stack[sp + 2] = 3 * t
            sp += 3
        if hi > c + 1:
            T.stack[sp] = c
            T.stack[sp + 1] = hi
            T.stack[sp + 2] = 3 * t + 1
            sp += 3
    return top


cdef inline void _mark_edge(Tri* T, int e, uint8_t flag, int32_t seg) noexcept nogil:
    """Add `flag` to the existing edge e (both twins); an input segment (seg >= 0)
    also gives it its id unless it has one: where input segments overlap, the first
    one inserted names the pieces (as Triangle keeps the first segment's marker)."""
    T.eflag[e] |= flag
    T.eflag[T.twin[e]] |= flag
    if seg >= 0 and T.eseg[e] < 0:
        T.eseg[e] = seg
        T.eseg[T.twin[e]] = seg


# The scratch buffer T.buf during one piece's insertion, for a capacity m (entries):
#   [0, m)      tris   the crossed triangles (their slots are refilled)
#   [m, 2m)     lch    left chain of vertices, from a
#   [2m, 3m)    rch    right chain of vertices, from a
#   [3m, 4m)    lorig  half-edge of left chain edge lch[j+1] -> lch[j]
#   [4m, 5m)    rorig  half-edge of right chain edge rch[j] -> rch[j+1]
#   then, 2m entries each, the two pseudo-polygons laid out one after the other (the
#   right chain, then the left chain reversed) as _triangulate_pseudo_polygon wants:
#   cch (vertices) at 5m, corig (old half-edges) at 7m, cext (outer twins) at 9m,
#   cnew (new half-edges) at 11m, cflag at 13m, cseg (segment ids) at 15m.
cdef enum:
    CAVITY_BUF_PER_CAP = 17


cdef int _walk_cavity(Tri* T, int a, int b, int h, int m, int* out) noexcept nogil:
    """Walk along a->b from the half-edge h = x->y opposite a of the first crossed
    triangle (a, x, y), collecting the crossed triangles and the left / right chains
    into T.buf (layout above, capacity m), up to the first vertex w on the line a-b.

    Returns 0 with out = (ntri, nl, nr, w), 1 when the capacity is too small (nothing
    was modified), or ERR_CROSSING / ERR_INTERNAL.  A chain can visit a vertex twice:
    when every triangle around a vertex is crossed (the segment passes close by it,
    crossing all its edges but one), that vertex hangs inside the cavity on an edge
    that both neighbouring crossed triangles share; such edges appear twice in a chain,
    once each way (_refill_cavity pairs them)."""
    cdef int32_t* tris = T.buf
    cdef int32_t* lch = T.buf + m
    cdef int32_t* rch = T.buf + 2 * m
    cdef int32_t* lorig = T.buf + 3 * m
    cdef int32_t* rorig = T.buf + 4 * m
    cdef int g, w, ow, ntri = 1, nl = 2, nr = 2
    # first triangle (a, x, y), h = x->y: right chain starts a->x, left chain y->a
    lch[0] = a
    rch[0] = a
    rch[1] = T.tv[h]
    rorig[0] = prv_nb(h)
    lch[1] = T.tv[nxt_nb(h)]
    lorig[0] = nxt_nb(h)
    tris[0] = h // 3
    while ntri < m - 1 and nl < m - 1 and nr < m - 1:
        if blocking(T, h):
            T.err_a = a
            T.err_b = b
            T.err_u = T.tv[h]
            T.err_v = T.tv[nxt_nb(h)]
            T.err_seg = T.eseg[h]
            return ERR_CROSSING
        g = T.twin[h]
        w = T.tv[prv_nb(g)]
        if w == GHOST:
            return ERR_INTERNAL
        tris[ntri] = g // 3
        ntri += 1
        ow = 0 if w == b else orient2d(P(T, a), P(T, b), P(T, w))
        if ow >= 0:
            lch[nl] = w
            lorig[nl - 1] = prv_nb(g)
            nl += 1
            h = nxt_nb(g)
        if ow <= 0:
            rch[nr] = w
            rorig[nr - 1] = nxt_nb(g)
            nr += 1
            h = prv_nb(g)
        if ow == 0:
            out[0] = ntri
            out[1] = nl
            out[2] = nr
            out[3] = w
            return 0
    return 1


cdef int _refill_cavity(Tri* T, int m, int ntri, int nl, int nr, uint8_t state,
                        int32_t region, int* tops) noexcept nogil:
    """Replace the crossed triangles that _walk_cavity collected by the CDTs of the
    two pseudo-polygons on either side of the new edge, in the same slots; tops =
    (right, left) half-edges of the new edge (not yet twinned or flagged).  Chain edges
    with the cavity on both sides are paired with each other."""
    cdef int32_t* tris = T.buf
    cdef int32_t* lch = T.buf + m
    cdef int32_t* rch = T.buf + 2 * m
    cdef int32_t* lorig = T.buf + 3 * m
    cdef int32_t* rorig = T.buf + 4 * m
    cdef int32_t* cch = T.buf + 5 * m
    cdef int32_t* corig = T.buf + 7 * m
    cdef int32_t* cext = T.buf + 9 * m
    cdef int32_t* cnew = T.buf + 11 * m
    cdef int32_t* cflag = T.buf + 13 * m
    cdef int32_t* cseg = T.buf + 15 * m
    cdef int i, j, e, g, nused = 0, nc = nr + nl
    # right chain at [0, nr), left chain reversed at [nr, nr + nl); chain edge k of a
    # polygon runs cch[k] -> cch[k+1]
    for i in range(nr):
        cch[i] = rch[i]
    for i in range(nr - 1):
        corig[i] = rorig[i]
    for i in range(nl):
        cch[nr + i] = lch[nl - 1 - i]
    for i in range(nl - 1):
        corig[nr + i] = lorig[nl - 2 - i]
    # mark the cavity, then find each chain edge's outer twin, flags and segment id
    for i in range(ntri):
        T.tstate[tris[i]] = T_FREE
    for i in range(nc):
        if i == nr - 1 or i == nc - 1:
            continue                # the last vertex of a chain starts no chain edge
        e = corig[i]
        cflag[i] = T.eflag[e]
        cseg[i] = T.eseg[e]
        g = T.twin[e]
        cext[i] = g if T.tstate[g // 3] != T_FREE else NONE
    tops[0] = _triangulate_pseudo_polygon(T, cch, cext, cnew, nr - 1, tris, &nused,
                                          state, region)
    if tops[0] < 0:
        return tops[0]
    tops[1] = _triangulate_pseudo_polygon(T, cch + nr, cext + nr, cnew + nr, nl - 1, tris,
                                          &nused, state, region)
    if tops[1] < 0:
        return tops[1]
    if nused != ntri:
        return ERR_INTERNAL
    # pair up the chain edges that had the cavity on both sides
    for i in range(nc):
        if i == nr - 1 or i == nc - 1 or cext[i] != NONE:
            continue
        # the partner is the chain edge running the other way between the same two
        # vertices (the old twin array is overwritten by now)
        for j in range(nc):
            if (j != nr - 1 and j != nc - 1 and j != i and cext[j] == NONE
                    and cch[j] == cch[i + 1] and cch[j + 1] == cch[i]):
                T.twin[cnew[i]] = cnew[j]
                T.eflag[cnew[i]] = <uint8_t> cflag[i]
                T.eseg[cnew[i]] = cseg[i]
                break
        else:
            return ERR_INTERNAL
    return 0


cdef int _insert_piece(Tri* T, int a, int b, uint8_t flag, int32_t seg,
                       int* reached) noexcept nogil:
    """Insert the constrained edge from a toward b up to the first vertex on the segment
    (b itself, or a vertex lying exactly on a-b); `reached` gets that vertex.  The new
    edge gets `flag` and segment id `seg`; the cavity's other edges keep theirs.  The
    walk (_walk_cavity) collects the crossed triangles, _refill_cavity retriangulates
    them."""
    cdef int res, h, t0
    cdef int m = CAVITY_INITIAL_CAP
    cdef int walked[4]
    cdef int tops[2]
    cdef int e = find_edge(T, a, b)
    if e >= 0:
        _mark_edge(T, e, flag, seg)
        reached[0] = b
        return 0
    res = _first_crossing(T, a, b, &h)
    if res < 0:
        return res
    if res == 1:
        e = find_edge(T, a, h)
        _mark_edge(T, e, flag, seg)
        reached[0] = h
        return 0
    while True:
        if reserve_buf(T, CAVITY_BUF_PER_CAP * m):
            return ERR_NOMEM
        res = _walk_cavity(T, a, b, h, m, walked)
        if res <= 0:
            break
        m *= 4                  # restart with bigger buffers (nothing was modified yet)
    if res < 0:
        return res
    t0 = h // 3
    res = _refill_cavity(T, m, walked[0], walked[1], walked[2], T.tstate[t0],
                         T.tregion[t0], tops)
    if res < 0:
        return res
    T.twin[tops[0]] = tops[1]
    T.twin[tops[1]] = tops[0]
    T.eflag[tops[0]] = flag
    T.eflag[tops[1]] = flag
    T.eseg[tops[0]] = seg
    T.eseg[tops[1]] = seg
    T.last = tops[0] // 3
    reached[0] = walked[3]
    return 0


cdef int insert_segment(Tri* T, int a, int b, uint8_t flag, int32_t seg) noexcept nogil:
    """Make a-b an edge of the triangulation with `flag` set on it (on each piece, if
    vertices lie exactly on a-b: the segment is then split there), each piece carrying
    segment id `seg` (-1 for a temporary constraint).  Returns 0, or 1 if it was split,
    or a negative error code."""
    cdef int reached = NONE, res, guard = 0
    while a != b:
        res = _insert_piece(T, a, b, flag, seg, &reached)
        if res < 0:
            return res
        a = reached
        guard += 1
        if guard > T.nv + 1:
            return ERR_INTERNAL
    return 1 if guard > 1 else 0
