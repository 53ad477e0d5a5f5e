# The boundary's discretization: each input segment cut into n pieces, n the rounded
# integral of 1/h along it, the cut points where the integral reaches k/n of its
# total (src/aftmesh/boundary.py says why; this is its arithmetic, compiled, for the
# common case without the rounding-retry's exclusions).
#
# The integral is taken at evenly spaced samples (a few per piece the ends' sizes
# predict, at least DISCRETIZE_MIN_SAMPLES, at most the caller's cap), h linear between them, whose
# exact integral of 1/h is ds * ln(h1 / h0) / (h1 - h0) (the trapezoid rule would
# overcount enormously next to a tiny size); a cut point is found by inverse linear
# interpolation of the cumulative integral, as numpy.interp computes it.  The counting
# pass keeps the split segments' integrals (SampleStore), and the cut points are placed
# on those: the size field is sampled once per segment.
#
# Uses: sizing.pxi (size_at, SizeField).
from libc.math cimport log, fabs, rint, sqrt, isnan
from libc.stdlib cimport free, realloc
from libc.string cimport memcpy
from sizing cimport SizeField

# below this relative difference of h between two samples, 1/h is integrated as the
# mean of the ends (the log formula would divide by nearly zero)
cdef double DISCRETIZE_FLAT = 1e-9
# samples per piece the ends' sizes predict: the cut points are placed by inverse
# interpolation between samples, so a few per piece place them within a few percent
cdef double DISCRETIZE_SAMPLES_PER_PIECE = 4.0
cdef enum:
    # the ends and the middle at least: a size dipping between the ends (a short edge
    # near the segment's middle) still shows
    DISCRETIZE_MIN_SAMPLES = 3


cdef inline double _sample(int k, int ns) noexcept nogil:
    # numpy.linspace(0, 1, ns)[k]
    return 1.0 if k == ns - 1 else k * (1.0 / (ns - 1))


cdef int _sample_count(SizeField* S, const double* a, const double* b, int cap) noexcept nogil:
    cdef double dx = b[0] - a[0], dy = b[1] - a[1], h, n
    if S.nt == 0:
        return 2        # a constant: the integral is linear, its ends say it all
    h = min(size_at(S, a[0], a[1]), size_at(S, b[0], b[1]))
    n = DISCRETIZE_SAMPLES_PER_PIECE * sqrt(dx * dx + dy * dy) / h + 1.0
    if not n < cap:     # also NaN
        return cap
    return max(<int> n + 1, DISCRETIZE_MIN_SAMPLES)


cdef double _inverse_size_integral(SizeField* S, const double* a, const double* b, int ns,
                                   double* cum) noexcept nogil:
    """cum[0..ns) = the integral of 1/h from a to the samples a + _sample(k) (b - a);
    returns cum[ns - 1]."""
    cdef double dx = b[0] - a[0], dy = b[1] - a[1]
    cdef double L = sqrt(dx * dx + dy * dy)
    cdef double ds = L / (ns - 1)
    cdef double h0, h1, lm, t
    cdef int k
    cum[0] = 0.0
    if S.nt == 0:
        cum[1] = L / S.constant
        return cum[1]
    h0 = size_at(S, a[0], a[1])
    for k in range(1, ns):
        t = _sample(k, ns)
        h1 = size_at(S, a[0] + dx * t, a[1] + dy * t)
        if fabs(h1 - h0) > DISCRETIZE_FLAT * h0:
            lm = (log(h1) - log(h0)) / (h1 - h0)
        else:
            lm = 2.0 / (h0 + h1)
        cum[k] = cum[k - 1] + ds * lm
        h0 = h1
    return cum[ns - 1]


cdef double _inverse_interp(double x, const double* cum, int ns) noexcept nogil:
    """The parameter where cum reaches x (numpy.interp(x, cum, samples), the same
    roundings)."""
    cdef int j = -1, k, j1, last = ns - 1
    cdef double left, right, slope, val, sj, sj1
    for k in range(ns):
        if cum[k] <= x:
            j += 1
    if j < 0:
        j = 0
    if j > last:
        j = last
    j1 = j + 1 if j < last else last
    left = cum[j]
    right = cum[j1]
    sj = _sample(j, ns)
    sj1 = _sample(j1, ns)
    if j == last or left == x:
        return sj
    slope = (sj1 - sj) / (right - left)
    val = slope * (x - left) + sj
    if isnan(val):
        val = slope * (x - right) + sj1
        if isnan(val) and sj == sj1:
            val = sj
    return val


cdef struct SampleStore:
    # The integrals of the split segments, kept by discretize_counts for
    # discretize_points: each as its sample count ns, then cum[0..ns).  Sampling the
    # size field again would cost as much as the first pass, and its walks could end
    # in another background triangle for a point on a background edge, so the cut
    # points would follow slightly different sizes than the piece counts.
    double* buf
    Py_ssize_t used, cap
    int64_t* at             # per segment: where its entry starts in buf, -1 if unsplit


cdef void sample_store_free(SampleStore* K) noexcept nogil:
    free(K.buf)
    free(K.at)
    K.buf = NULL
    K.at = NULL
    K.used = K.cap = 0


cdef int _store_keep(SampleStore* K, Py_ssize_t i, const double* cum, int ns) noexcept nogil:
    cdef double* grown
    cdef Py_ssize_t cap = K.cap
    while K.used + ns + 1 > cap:
        cap = 2 * cap + 64
    if cap != K.cap:
        grown = <double*> realloc(K.buf, cap * sizeof(double))
        if grown == NULL:
            return -1
        K.buf = grown
        K.cap = cap
    K.at[i] = K.used
    K.buf[K.used] = ns
    memcpy(&K.buf[K.used + 1], cum, ns * sizeof(double))
    K.used += ns + 1
    return 0


cdef double discretize_counts(SizeField* S, const double* v, const int32_t* seg,
                              Py_ssize_t m, int max_samples, double* cum,
                              int64_t* pieces, Py_ssize_t* n_pts,
                              SampleStore* K) noexcept nogil:
    """pieces[i] = the number of pieces of segment i (seg[2i] -> seg[2i+1] on the
    points v) by the size (at least 1); n_pts = the split points in all; the split
    segments' integrals into K (its `at` allocated for m segments).  Returns the
    total number of pieces (a float: it may exceed any integer type), or -1 when out
    of memory."""
    cdef Py_ssize_t i
    cdef int ns
    cdef double total = 0.0, c
    cdef const double* a
    cdef const double* b
    n_pts[0] = 0
    for i in range(m):
        a = &v[2 * seg[2 * i]]
        b = &v[2 * seg[2 * i + 1]]
        ns = _sample_count(S, a, b, max_samples)
        c = rint(_inverse_size_integral(S, a, b, ns, cum))
        pieces[i] = <int64_t> c if c >= 1.0 else 1
        total += c if c >= 1.0 else 1.0
        n_pts[0] += pieces[i] - 1
        K.at[i] = -1
        if pieces[i] > 1 and _store_keep(K, i, cum, ns):
            return -1.0
    return total


cdef void discretize_points(const double* v, const int32_t* seg, Py_ssize_t m,
                            const int64_t* pieces, double* pts, int64_t* row,
                            const SampleStore* K) noexcept nogil:
    """The split points of each segment with pieces[i] > 1, segment by segment and in
    order along each, into pts (and the segment of each into row, unless NULL), from
    the integrals discretize_counts kept in K."""
    cdef Py_ssize_t i, k, at = 0
    cdef int ns
    cdef double t
    cdef const double* a
    cdef const double* b
    cdef const double* cum
    for i in range(m):
        if pieces[i] == 1:
            continue
        a = &v[2 * seg[2 * i]]
        b = &v[2 * seg[2 * i + 1]]
        ns = <int> K.buf[K.at[i]]
        cum = &K.buf[K.at[i] + 1]
        for k in range(1, pieces[i]):
            t = _inverse_interp(cum[ns - 1] * k / pieces[i], cum, ns)
            pts[2 * at] = a[0] + t * (b[0] - a[0])
            pts[2 * at + 1] = a[1] + t * (b[1] - a[1])
            if row != NULL:
                row[at] = i
            at += 1


cdef Py_ssize_t chain_keep(const double* v, const int32_t* seg, Py_ssize_t m,
                           const int64_t* pieces, const double* pts,
                           uint8_t* keep) noexcept nogil:
    """keep[j] = 1 for the split points that differ from the point before them on
    their segment and from the segment's end (a piece of zero length would be
    fatal); returns how many are kept."""
    cdef Py_ssize_t i, j, at = 0, kept = 0
    cdef const double* prev
    cdef const double* end
    for i in range(m):
        if pieces[i] == 1:
            continue
        prev = &v[2 * seg[2 * i]]
        end = &v[2 * seg[2 * i + 1]]
        for j in range(pieces[i] - 1):
            keep[at] = not ((pts[2 * at] == prev[0] and pts[2 * at + 1] == prev[1])
                            or (pts[2 * at] == end[0] and pts[2 * at + 1] == end[1]))
            kept += keep[at]
            prev = &pts[2 * at]
            at += 1
    return kept


cdef void chain_write(const double* v, Py_ssize_t nv, const int32_t* seg,
                      const int32_t* source, Py_ssize_t m, const int64_t* pieces,
                      const double* pts, const uint8_t* keep, double* vo, int32_t* so,
                      int32_t* eo) noexcept nogil:
    """The new PSLG: vo = the points v then the kept split points; so / eo = the
    unsplit segments first, then each split segment as the chain through its kept
    split points, each piece with its segment's source."""
    cdef Py_ssize_t i, j, at = 0, kept = 0, s_at = 0
    cdef int32_t first
    for i in range(2 * nv):
        vo[i] = v[i]
    for i in range(m):
        if pieces[i] == 1:
            so[2 * s_at] = seg[2 * i]
            so[2 * s_at + 1] = seg[2 * i + 1]
            eo[s_at] = source[i]
            s_at += 1
    for i in range(m):
        if pieces[i] == 1:
            continue
        first = seg[2 * i]
        for j in range(pieces[i] - 1):
            if keep[at]:
                vo[2 * (nv + kept)] = pts[2 * at]
                vo[2 * (nv + kept) + 1] = pts[2 * at + 1]
                so[2 * s_at] = first
                so[2 * s_at + 1] = <int32_t> (nv + kept)
                eo[s_at] = source[i]
                first = <int32_t> (nv + kept)
                s_at += 1
                kept += 1
            at += 1
        so[2 * s_at] = first
        so[2 * s_at + 1] = seg[2 * i + 1]
        eo[s_at] = source[i]
        s_at += 1
