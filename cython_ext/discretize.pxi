# The boundary's discretization: each input segment cut into n pieces, n the rounded
# integral of 1/h along it, the cut points where the integral reaches k/n of its
# total (src/aftmesh/boundary.py says why; this is its arithmetic, compiled, for the
# common case without the rounding-retry's exclusions).
#
# The integral is taken at evenly spaced samples (a few per piece the ends' sizes
# predict, at least DISCRETIZE_MIN_SAMPLES, at most the caller's cap), h linear between them, whose
# exact integral of 1/h is ds * ln(h1 / h0) / (h1 - h0) (the trapezoid rule would
# overcount enormously next to a tiny size); a cut point is found by inverse linear
# interpolation of the cumulative integral, as numpy.interp computes it.
#
# Uses: sizing.pxi (size_at, SizeField).
from libc.math cimport log, fabs, rint, sqrt, isnan
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
