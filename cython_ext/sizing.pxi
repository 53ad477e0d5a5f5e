# The compiled size field: target edge length h(x, y) read by Compute_new_candidate.
#
# A constant, or sizes stored at the vertices of a background Delaunay triangulation
# (the input vertices, the bounding box's corners, and points where a size callable
# needed them: sizing.py builds it).  Its cost grows with the input, never with the
# bounding box.  Inside the background triangle holding p,
#
#     h(p) = min( linear interpolation of w,  min over nearby vertices v of cone_v(p) ),
#     cone_v(p) = g_v + rate max(0, |p - v| - reach g_v)
#
# w is the user's size (smooth, so linear interpolation follows it once the background
# resolves it); g is what the boundary asks for (a short input edge's length at its
# ends), which changes by orders of magnitude within one background triangle: the cones
# cones give it the gradation limit exactly, where interpolating g would
# spread a tiny size across the whole triangle.  (The size holds for reach g_v around
# the vertex before it grows: the first layer of triangles on a boundary is then as
# large as the boundary's edges, not larger.)  "Nearby" is the triangle's own three
# vertices and the three across its edges.  Points outside the background read the
# nearest point of the last triangle of the walk.
#
# So the gradation limit holds along the background's edges and near each vertex, not
# everywhere: where a long background triangle (across a wide domain, between a
# detailed coast and a straight edge) lies next to small sizes whose vertices are
# not among its nearby ones, the field reads larger than the smallest cone, and jumps
# at that triangle's edges.  On rw-earcut-eberly-6 it exceeds the exact lower envelope
# of all the cones by more than 10 % at 14 % of the mesh's triangle centroids (at most
# 4.5 times).  Reading every cone instead made the real-world group 2.7 % more
# triangles for a mean radius ratio 0.0003 higher and 1.6 % fewer of radius ratio
# <= 0.9 (the detailed coasts gained, up to 0.002; funny and archipelago fell below
# 97 % above 0.9); that experiment evaluated every background vertex's cone at every
# look-up, and an exact field at a bounded cost would need a search structure.
#
# Uses: sizing.pxd (SizeField); nothing else of the kernel.

from libc.math cimport sqrt, fabs, log1p, INFINITY, isinf
from libc.stdlib cimport malloc, free, realloc
from libc.string cimport memcpy
from libc.stdint cimport int32_t
from sizing cimport SizeField


# i % 3 for i < 5, by table: the walk below indexes with it several times per step,
# and a load is cheaper than the multiply and shifts a compiled % 3 becomes
cdef int[5] _MOD3 = [0, 1, 2, 0, 1]


cdef void size_field_free(SizeField* S) noexcept nogil:
    free(S.xy)
    free(S.w)
    free(S.g)
    free(S.tv)
    free(S.nb)
    free(S.op)
    free(S.tedge)
    free(S.vhint)
    S.xy = S.w = S.g = S.tedge = NULL
    S.tv = S.nb = S.op = S.vhint = NULL
    S.nv = S.nt = S.vhint_cap = 0
    S.hint = 0


cdef int size_field_set(SizeField* S, double constant, int nv, int nt, const double* xy,
                        const double* w, const double* g, const int32_t* tv,
                        const int32_t* nb, double rate, double reach) noexcept nogil:
    """Replace S by copies of the given arrays (nt == 0: the constant) and the arrays
    derived from them; 0 or ERR_NOMEM."""
    cdef int t, k, j, n
    cdef const double* a
    cdef const double* b
    size_field_free(S)
    S.constant = constant
    S.rate = rate
    S.reach = reach
    if nt == 0:
        return 0
    S.xy = <double*> malloc(2 * nv * sizeof(double))
    S.w = <double*> malloc(nv * sizeof(double))
    S.g = <double*> malloc(nv * sizeof(double))
    S.tv = <int32_t*> malloc(3 * nt * sizeof(int32_t))
    S.nb = <int32_t*> malloc(3 * nt * sizeof(int32_t))
    S.op = <int32_t*> malloc(3 * nt * sizeof(int32_t))
    S.tedge = <double*> malloc(12 * nt * sizeof(double))
    if (S.xy == NULL or S.w == NULL or S.g == NULL or S.tv == NULL or S.nb == NULL
            or S.op == NULL or S.tedge == NULL):
        size_field_free(S)
        return -1
    memcpy(S.xy, xy, 2 * nv * sizeof(double))
    memcpy(S.w, w, nv * sizeof(double))
    memcpy(S.g, g, nv * sizeof(double))
    memcpy(S.tv, tv, 3 * nt * sizeof(int32_t))
    memcpy(S.nb, nb, 3 * nt * sizeof(int32_t))
    S.w_finite = True
    for k in range(nv):
        if isinf(w[k]):
            S.w_finite = False
    for t in range(nt):
        for k in range(3):
            S.op[3 * t + k] = -1
            n = nb[3 * t + k]
            if n >= 0:
                for j in range(3):
                    if nb[3 * n + j] == t:
                        S.op[3 * t + k] = tv[3 * n + j]
                        break
            a = &xy[2 * tv[3 * t + _MOD3[k + 1]]]
            b = &xy[2 * tv[3 * t + _MOD3[k + 2]]]
            S.tedge[12 * t + 4 * k] = a[0]
            S.tedge[12 * t + 4 * k + 1] = a[1]
            S.tedge[12 * t + 4 * k + 2] = b[0] - a[0]
            S.tedge[12 * t + 4 * k + 3] = b[1] - a[1]
    S.nv = nv
    S.nt = nt
    return 0


cdef inline double _side_of_edge(const double* q, double x, double y) noexcept nogil:
    # twice the signed area of (a, b, p), > 0 when p is left of a -> b, from a and
    # b - a as tedge keeps them (floating point is enough: the result only weighs
    # sizes, it never decides topology)
    return q[2] * (y - q[1]) - q[3] * (x - q[0])


cdef int size_locate(SizeField* S, double x, double y, double* side,
                     bint* sides_known) noexcept nogil:
    """The background triangle holding (x, y), or the last one a walk towards it
    reached (at the hull, or after as many steps as there are triangles: rounding can
    make a walk circle, and any nearby triangle gives a good enough size).  When the
    walk ended inside it, side[k] holds _side_of_edge of (x, y) from its edge k
    (opposite its corner k) and sides_known is set: size_at's weights, already
    computed."""
    cdef int t = S.hint, step, k, j, n, first = 0
    cdef const double* q
    sides_known[0] = False
    if t < 0 or t >= S.nt:
        t = 0
    for step in range(S.nt):
        q = &S.tedge[12 * t]
        n = -1
        sides_known[0] = True
        for j in range(3):
            k = _MOD3[first + j]    # rotate the first edge tried: no walk cycles for good
            side[k] = _side_of_edge(&q[4 * k], x, y)
            if side[k] < 0.0:
                n = S.nb[3 * t + k]
                sides_known[0] = False
                break
        if n < 0:
            break
        t = n
        first = _MOD3[first + 1]    # step % 3
    S.hint = t
    return t


cdef inline double _grown(double h, double dist, double rate, double reach) noexcept nogil:
    # a size h held out to reach * h, growing at `rate` beyond
    dist -= reach * h
    return h + rate * dist if dist > 0.0 else h


cdef inline double _cone(const SizeField* S, int v, const double* p, double x,
                         double y) noexcept nogil:
    # the cone of vertex v, at p (v's coordinates)
    cdef double dx = x - p[0], dy = y - p[1]
    return _grown(S.g[v], sqrt(dx * dx + dy * dy), S.rate, S.reach)


cdef double size_at(SizeField* S, double x, double y) noexcept nogil:
    cdef int t, k, a
    cdef double lam[3]
    cdef double s = 0.0, h = 0.0, c
    cdef bint known
    cdef const int32_t* v
    cdef const double* e
    if S.nt == 0:
        return S.constant
    t = size_locate(S, x, y, lam, &known)
    v = &S.tv[3 * t]
    e = &S.tedge[12 * t]
    for k in range(3):
        if not known:
            lam[k] = _side_of_edge(&e[4 * k], x, y)
        if not lam[k] > 0.0:        # outside that edge, or NaN: its nearest point
            lam[k] = 0.0
        s += lam[k]
    if not s > 0.0:
        lam[0] = lam[1] = lam[2] = 1.0
        s = 3.0
    if S.w_finite:
        for k in range(3):
            h += lam[k] * S.w[v[k]]
    else:
        for k in range(3):
            if isinf(S.w[v[k]]):
                h = INFINITY
                break
            h += lam[k] * S.w[v[k]]
    h /= s
    # a cone is never below its vertex's g (it only grows away from the vertex, and
    # adding a non-negative term never rounds down), so taking the least of h and
    # every cone, whether or not its g is below h, changes no result; computing them
    # all costs a few square roots, where the test 'g below h' was a branch
    # mispredicted about one time in three
    for k in range(3):
        c = _cone(S, v[k], &e[4 * _MOD3[k + 2]], x, y)     # edge k + 2 starts at k
        h = c if c < h else h
        a = S.op[3 * t + k]
        if a >= 0:
            c = _cone(S, a, &S.xy[2 * a], x, y)
            h = c if c < h else h
    return h


cdef double size_at_from(SizeField* S, double x, double y, int v, int w) noexcept nogil:
    """size_at, with the walk started where the last look-up made from mesh vertex v
    ended (a look-up near v: Compute_new_candidate's, at the middle of the edge vw),
    or from w when v has none yet (a vertex the front has just made).  The front
    jumps across the domain between steps, and the walk from the last look-up
    anywhere would then cross the background."""
    cdef int32_t* grown
    cdef int cap, i
    cdef double h
    if S.nt == 0 or v < 0:
        return size_at(S, x, y)
    if v >= S.vhint_cap or w >= S.vhint_cap:
        cap = 2 * (v if v > w else w) + 64
        grown = <int32_t*> realloc(S.vhint, cap * sizeof(int32_t))
        if grown == NULL:
            return size_at(S, x, y)     # no cache: only the walks are longer
        for i in range(S.vhint_cap, cap):
            grown[i] = -1
        S.vhint = grown
        S.vhint_cap = cap
    if S.vhint[v] >= 0:
        S.hint = S.vhint[v]
    elif w >= 0 and S.vhint[w] >= 0:
        S.hint = S.vhint[w]
    h = size_at(S, x, y)
    S.vhint[v] = S.hint
    return h


cdef double count_triangles_asked(SizeField* S, double min_rate, double unit_area,
                                  double* area_out) noexcept nogil:
    """About how many triangles of area unit_area h^2 the field asks for over its
    background.  Each background triangle counts the larger of its area over its
    centroid's size and the graded disks around its corners: around a vertex of size
    g with h growing at rate r, the count within radius R is about
    2 pi / r^2 ln(1 + r R / g), only logarithmic in 1 / g, so one tiny feature does
    not make the count explode, nor vanish inside a large triangle.  The triangles'
    total area goes to area_out."""
    cdef int t, k
    cdef const double* p[3]
    cdef double cx, cy, area, hc, dense, disks, r, dx, dy, total = 0.0
    cdef double rate = S.rate if S.rate > min_rate else min_rate
    # each corner is a third of a disk on average (a triangle's angles sum to pi)
    cdef double disk = 2.0 * 3.141592653589793 / 3.0 / (unit_area * rate * rate)
    area_out[0] = 0.0
    for t in range(S.nt):
        for k in range(3):
            p[k] = &S.xy[2 * S.tv[3 * t + k]]
        area = 0.5 * fabs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                          - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]))
        cx = (p[0][0] + p[1][0] + p[2][0]) / 3.0
        cy = (p[0][1] + p[1][1] + p[2][1]) / 3.0
        S.hint = t      # the centroid is in t: no walk
        hc = size_at(S, cx, cy)
        dense = area / (unit_area * hc * hc)
        disks = 0.0
        for k in range(3):
            dx = p[k][0] - cx
            dy = p[k][1] - cy
            r = sqrt(dx * dx + dy * dy)
            disks += disk * log1p(rate * r / S.g[S.tv[3 * t + k]])
        total += dense if dense > disks else disks
        area_out[0] += area
    return total


# ------------------------------------------------ gradation limit on a graph

cdef inline void _heap_push(double* key, int32_t* item, int* n, double k, int32_t v) noexcept nogil:
    cdef int i = n[0], p
    n[0] += 1
    while i > 0:
        p = (i - 1) >> 1
        if key[p] <= k:
            break
        key[i] = key[p]
        item[i] = item[p]
        i = p
    key[i] = k
    item[i] = v


cdef inline int32_t _heap_pop(double* key, int32_t* item, int* n) noexcept nogil:
    cdef int32_t top = item[0], v
    cdef double k
    cdef int i = 0, c
    n[0] -= 1
    k = key[n[0]]
    v = item[n[0]]
    while True:
        c = 2 * i + 1
        if c >= n[0]:
            break
        if c + 1 < n[0] and key[c + 1] < key[c]:
            c += 1
        if key[c] >= k:
            break
        key[i] = key[c]
        item[i] = item[c]
        i = c
    key[i] = k
    item[i] = v
    return top


cdef int limit_gradation_graph(int nv, const int32_t* start, const int32_t* adj,
                               const double* xy, double* h, double rate,
                               double reach) noexcept nogil:
    """In place: the largest h' <= h with h'[v] <= _grown(h'[u], |uv|) along the edges
    (adj[start[u]:start[u + 1]] are u's neighbours), by Dijkstra from the smallest
    sizes out: each vertex is settled once, so the cost is O(E log E).  0 or ERR_NOMEM."""
    cdef int cap = start[nv] + nv, n = 0, i
    cdef int32_t u, v
    cdef double d, dx, dy
    cdef double* key = <double*> malloc(cap * sizeof(double))
    cdef int32_t* item = <int32_t*> malloc(cap * sizeof(int32_t))
    cdef char* done = <char*> malloc(nv + 1)
    if key == NULL or item == NULL or done == NULL:
        free(key)
        free(item)
        free(done)
        return -1
    for u in range(nv):
        done[u] = 0
        if not isinf(h[u]):
            _heap_push(key, item, &n, h[u], u)
    while n > 0:
        u = _heap_pop(key, item, &n)
        if done[u]:
            continue
        done[u] = 1
        for i in range(start[u], start[u + 1]):
            v = adj[i]
            if done[v]:
                continue
            dx = xy[2 * v] - xy[2 * u]
            dy = xy[2 * v + 1] - xy[2 * u + 1]
            d = _grown(h[u], sqrt(dx * dx + dy * dy), rate, reach)
            if d < h[v]:
                h[v] = d
                _heap_push(key, item, &n, d, v)
    free(key)
    free(item)
    free(done)
    return 0
