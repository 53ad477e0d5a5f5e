# Constrained edges (Cline & Renka) and flood fills over the triangulation.
#
# A new constrained edge a-b is inserted by removing exactly the triangles whose
# interiors it crosses and re-triangulating the two pseudo-polygons on either side of it
# as constrained Delaunay triangulations (Cline & Renka's Theorem 1: the rest of the
# triangulation is untouched and stays a CDT).  The same routine serves the CDT of the
# input domain and Update_internal's edges F and G.

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
        x = T.tv[nxt(e)]
        y = T.tv[prv(e)]
        if x != GHOST:
            ox = orient2d(P(T, a), P(T, b), P(T, x))
            if ox == 0 and _on_ray(T, a, b, x):
                out[0] = x
                return 1
            if y != GHOST and ox < 0:
                oy = orient2d(P(T, a), P(T, b), P(T, y))
                if oy > 0:
                    out[0] = nxt(e)
                    return 0
        e = T.twin[prv(e)]
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
    also gives it its id (a later duplicate of a segment wins)."""
    T.eflag[e] |= flag
    T.eflag[T.twin[e]] |= flag
    if seg >= 0:
        T.eseg[e] = seg
        T.eseg[T.twin[e]] = seg


cdef int _insert_piece(Tri* T, int a, int b, uint8_t flag, int32_t seg,
                       int* reached) noexcept nogil:
    """Insert the constrained edge from a toward b up to the first vertex on the segment
    (b itself, or a vertex lying exactly on a-b); `reached` gets that vertex.  The new
    edge gets `flag` and segment id `seg`; the cavity's other edges keep theirs.

    The walk along a->b collects the crossed triangles and the chains of vertices to the
    left and right.  A chain can visit a vertex twice: when every triangle around a
    vertex is crossed (the segment passes close by it, crossing all its edges but one),
    that vertex hangs inside the cavity on an edge that both neighbouring crossed
    triangles share.  Such edges appear twice in a chain, once each way; after the
    re-triangulation their two new half-edges are paired with each other."""
    cdef int res, h, g, w, ow, u, v, ntri, nl, nr, i, j, nused, topr, topl, t0, nc
    cdef int end = NONE
    cdef int m = CAVITY_INITIAL_CAP
    cdef int32_t* tris
    cdef int32_t* lch
    cdef int32_t* rch
    cdef int32_t* lorig
    cdef int32_t* rorig
    cdef int32_t* cch
    cdef int32_t* corig
    cdef int32_t* cext
    cdef int32_t* cnew
    cdef int32_t* cflag
    cdef int32_t* cseg
    cdef uint8_t state
    cdef int32_t region
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
        if reserve_buf(T, 17 * m):
            return ERR_NOMEM
        tris = T.buf
        lch = T.buf + m
        rch = T.buf + 2 * m
        lorig = T.buf + 3 * m      # half-edge of chain edge lch[j+1] -> lch[j]
        rorig = T.buf + 4 * m      # half-edge of chain edge rch[j] -> rch[j+1]
        # the polygon in the form _triangulate_pseudo_polygon wants: the right chain,
        # then the left chain reversed, one after the other (2m entries each)
        cch = T.buf + 5 * m
        corig = T.buf + 7 * m
        cext = T.buf + 9 * m
        # first triangle (a, x, y), h = x->y: right chain starts a->x, left chain y->a
        t0 = h // 3
        lch[0] = a
        rch[0] = a
        rch[1] = T.tv[h]
        rorig[0] = prv(h)
        nr = 2
        lch[1] = T.tv[nxt(h)]
        lorig[0] = nxt(h)
        nl = 2
        tris[0] = t0
        ntri = 1
        state = T.tstate[t0]
        region = T.tregion[t0]
        end = NONE
        while ntri < m - 1 and nl < m - 1 and nr < m - 1:
            if blocking(T, h):
                T.err_a = a
                T.err_b = b
                T.err_u = T.tv[h]
                T.err_v = T.tv[nxt(h)]
                T.err_seg = T.eseg[h]
                return ERR_CROSSING
            g = T.twin[h]
            u = T.tv[g]            # left end of the crossed edge
            v = T.tv[nxt(g)]       # right end
            w = T.tv[prv(g)]
            if w == GHOST:
                return ERR_INTERNAL
            tris[ntri] = g // 3
            ntri += 1
            if w == b:
                ow = 0
            else:
                ow = orient2d(P(T, a), P(T, b), P(T, w))
            if ow == 0:
                end = w
                rch[nr] = w
                rorig[nr - 1] = nxt(g)
                nr += 1
                lch[nl] = w
                lorig[nl - 1] = prv(g)
                nl += 1
                break
            if ow > 0:
                lch[nl] = w
                lorig[nl - 1] = prv(g)
                nl += 1
                h = nxt(g)
            else:
                rch[nr] = w
                rorig[nr - 1] = nxt(g)
                nr += 1
                h = prv(g)
        if end != NONE:
            break
        m *= 4
        # restart with bigger buffers (nothing was modified yet)
        if _first_crossing(T, a, b, &h) != 0:
            return ERR_INTERNAL
    # Lay out both polygons in c* arrays: right chain at [0, nr), left chain reversed at
    # [nr, nr + nl).  Chain edge k of a polygon runs cch[k] -> cch[k+1].
    for i in range(nr):
        cch[i] = rch[i]
    for i in range(nr - 1):
        corig[i] = rorig[i]
    for i in range(nl):
        cch[nr + i] = lch[nl - 1 - i]
    for i in range(nl - 1):
        corig[nr + i] = lorig[nl - 2 - i]
    nc = nr + nl
    # Mark the cavity, then find each chain edge's outer twin and flags.
    cnew = T.buf + 11 * m
    cflag = T.buf + 13 * m
    cseg = T.buf + 15 * m
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
    nused = 0
    topr = _triangulate_pseudo_polygon(T, cch, cext, cnew, nr - 1, tris, &nused, state, region)
    if topr < 0:
        return topr
    topl = _triangulate_pseudo_polygon(T, cch + nr, cext + nr, cnew + nr, nl - 1, tris,
                                       &nused, state, region)
    if topl < 0:
        return topl
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
    T.twin[topr] = topl
    T.twin[topl] = topr
    T.eflag[topr] = flag
    T.eflag[topl] = flag
    T.eseg[topr] = seg
    T.eseg[topl] = seg
    T.last = topr // 3
    reached[0] = end
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


# ---------------------------------------------------------------- flood fills

cdef int flood(Tri* T, int nseed, uint8_t from_state, uint8_t to_state, int32_t region,
               bint set_region) noexcept nogil:
    """Spread from the triangles T.stack[0:nseed] across edges that are not segments,
    changing every reached triangle of state from_state to to_state (and its region)."""
    cdef int sp = nseed, t, k, e, u
    while sp > 0:
        sp -= 1
        t = T.stack[sp]
        if T.tstate[t] != from_state:
            continue
        T.tstate[t] = to_state
        if set_region:
            T.tregion[t] = region
        for k in range(3):
            e = 3 * t + k
            if T.eflag[e] & E_SEGMENT:
                continue
            u = T.twin[e] // 3
            if T.tstate[u] == from_state:
                if reserve_stack(T, sp + 1):
                    return ERR_NOMEM
                T.stack[sp] = u
                sp += 1
    return 0


# Seeds of the flood fills: hole and region points located in the triangulation.

cdef bint _vertex_on_segment(Tri* T, int v) noexcept nogil:
    """Whether a constrained edge ends at v (a seed located on v lies on a segment)."""
    cdef int e0 = T.vhe[v], e = e0
    while True:
        if T.eflag[e] & E_SEGMENT:
            return True
        e = T.twin[prv(e)]
        if e == e0:
            return False


cdef int _seed_triangle(Tri* T, int loc, int where) noexcept nogil:
    """The triangle a flood fill starts from for a seed point located at (loc, where)."""
    if loc == LOC_IN_TRIANGLE:
        return where
    if loc == LOC_ON_EDGE:
        return where // 3
    if loc == LOC_ON_VERTEX:
        return T.vhe[where] // 3
    return NONE
