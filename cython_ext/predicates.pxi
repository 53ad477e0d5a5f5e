# Exact geometric predicates: orient2d and incircle.
#
# CONVENTIONS
# -----------
# Every point is a pointer to an (x, y) pair of doubles.
#
# orient2d(a, b, c) is the exact sign of
#     | bx-ax  by-ay |
#     | cx-ax  cy-ay |
# +1 when a, b, c turn counter-clockwise (c strictly left of the directed
# line a->b), -1 when they turn clockwise, 0 when they are collinear.
#
# incircle(a, b, c, d) is the exact sign of the lifted determinant
#     | ax-dx  ay-dy  (ax-dx)^2 + (ay-dy)^2 |
#     | bx-dx  by-dy  (bx-dx)^2 + (by-dy)^2 |
#     | cx-dx  cy-dy  (cx-dx)^2 + (cy-dy)^2 |
# With a, b, c counter-clockwise: +1 when d is strictly inside their
# circumcircle, -1 strictly outside, 0 on it.  If a, b, c are clockwise the
# sign is reversed.  The determinant equals the 4x4 determinant with rows
# (x, y, x^2+y^2, 1), so swapping ANY two of the four points flips the sign.
#
# HOW
# ---
# Each predicate first evaluates the determinant in plain floating point and
# compares it with an error bound that is relative to the permanent (the
# same expression with every product replaced by its absolute value).  If
# |det| exceeds the bound, the rounded det has the true sign.  Otherwise a
# non-inline exact routine recomputes the determinant as a floating-point
# expansion (a sum of non-overlapping doubles) and reads its sign off the
# largest component.  No adaptive middle stage: the exact stage is only
# reached for (nearly) degenerate inputs.
#
# ERROR BOUNDS (eps = 2^-53, the unit roundoff of binary64)
# ----------------------------------------------------------
# orient2d: |det_true - det_fl| <= (3 + 16 eps) eps * (|detleft| + |detright|)
#   where detleft = fl(fl(bx-ax) * fl(cy-ay)), detright likewise.  Why: each
#   product carries three roundings (two differences, one product), so
#   |detleft - Ltrue| <= ((1-eps)^-3 - 1) |detleft| = (3 eps + 6 eps^2 + ...) |detleft|;
#   the final subtraction cannot change the sign (rounding is monotone and
#   preserves sign), it only shrinks |det| by at most a factor (1+eps), and
#   computing the bound itself costs two more roundings.  Folding these
#   (1 +- eps) factors into the constant needs 3 eps + 7 eps^2 + O(eps^3), which
#   (3 + 16 eps) eps covers.  This is the bound of Shewchuk, "Adaptive
#   Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates"
#   (1997), where the full derivation is given.
# incircle: |det_true - det_fl| <= (10 + 96 eps) eps * permanent, where
#   permanent = (|bdx*cdy| + |cdx*bdy|) * alift + ... in floating point.
#   Why 10: a lifted term alift (4 roundings: 2 differences, square, sum of
#   positive terms), times a cross term (3 roundings per product, 1 for the
#   subtraction), times 1 for the product, plus 1 for the first of the two
#   additions; the last addition does not affect the sign.  Constant from the
#   same paper.
# Both constants are exactly representable (tested in tests/test_predicates.py).
#
# EXACT RANGE
# -----------
# The error bounds and the expansion arithmetic are proven in a model with
# unbounded exponent range.  Real doubles match that model as long as nothing
# overflows and every value that gets rounded is normal (subnormal results
# that are exact do no harm).  If every input coordinate is 0 or has
#     orient2d:  2^-430 <= |x| <= 2^500   (about 2.9e-130 .. 3.2e150)
#     incircle:  2^-190 <= |x| <= 2^250   (about 6.4e-58  .. 1.8e75)
# then (infinities and NaN excluded):
#   * every coordinate is a multiple of L = 2^(kmin-52) (kmin = -430 or -190),
#     so every difference, product, sum and expansion component of degree k
#     (orient2d k<=2, incircle k<=4) is an exact multiple of L^k >= 2^-968.
#     Rounding a multiple of a power of two P >= 2^-1074 never gives a
#     non-multiple, so no value ever becomes a nonzero number below L^k, hence
#     nothing underflows, every rounding error is relative, every product's
#     low part is representable (so two-product via fma is exact), and a
#     rounded value is 0 only if the exact value is 0;
#   * a nonzero permanent is at least L^k, so the error bound (constant *
#     permanent) is at least 2^-1018, a normal number, and computing it
#     rounds relatively too;
#   * magnitudes stay below 2^1010 (differences <= 2^(h+1), degree-4 sums of
#     at most a few thousand such terms), so nothing overflows.
# Within these ranges the returned sign is exact for ALL inputs.  Both
# predicates are exact for every coordinate in 1e-57 <= |x| <= 1e75 or x == 0.
# Outside the ranges the result is still computed without crashing, but may
# be wrong (as for a naive evaluation).
#
# PLATFORM ASSUMPTIONS
# --------------------
# IEEE-754 binary64 with round-to-nearest-even (the default mode), no
# extended-precision intermediates (SSE2 on x86-64, not x87), a correctly
# rounded fma() (C99; glibc uses the hardware instruction or an exact
# software emulation), and no contraction of a*b+c into fma or any other
# value-changing optimisation: setup.py passes -ffp-contract=off and never
# -ffast-math.

from libc.math cimport fabs, fma


# Capacities of the fixed stack buffers used by the exact stage.  Every call
# to _exp_grow adds at most one component, so a buffer never needs more
# components than the number of doubles grown into it:
#   a 2x2 cross term p*q - r*s of two-component differences:
#       2 products * (2*2 component pairs) * 2 doubles per two-product = 16;
#   a lifted term dx^2 + dy^2: the same count, 16;
#   the incircle determinant: 3 terms * (16*16 pairs) * 2 doubles = 1536.
cdef enum:
    _exp_max_diff = 2
    _exp_max_cross = 16
    _exp_max_lift = 16
    _exp_max_incircle = 1536

# Filter outcome meaning "cannot decide, run the exact stage".
cdef enum:
    _pred_undecided = 2


# The filter constants, written as their defining formulas with
# eps = 2^-53 (the literal below is exactly 2^-53).  Every step is exact, so
# the C compiler folds each to the exact constant.

cdef inline double _pred_orient2d_errbound() noexcept nogil:
    return (3.0 + 16.0 * 1.1102230246251565e-16) * 1.1102230246251565e-16


cdef inline double _pred_incircle_errbound() noexcept nogil:
    return (10.0 + 96.0 * 1.1102230246251565e-16) * 1.1102230246251565e-16


# ---------------------------------------------------------------------------
# Error-free transformations.  Each turns one floating-point operation into
# a rounded result plus the exact rounding error, so result + error equals
# the real-number result.
# ---------------------------------------------------------------------------

cdef inline void _exp_two_sum(double a, double b, double* s, double* err) noexcept nogil:
    # Knuth's branch-free two-sum: exact for any ordering of |a| and |b|
    # (unlike the cheaper fast-two-sum), which keeps the proofs simple, and
    # exact even when the result is subnormal.
    cdef double x = a + b
    cdef double b_virtual = x - a
    cdef double a_virtual = x - b_virtual
    err[0] = (a - a_virtual) + (b - b_virtual)
    s[0] = x


cdef inline void _exp_two_product(double a, double b, double* p, double* err) noexcept nogil:
    # fma rounds a*b - x only once, and a*b - x is representable whenever the
    # low bits of a*b do not fall below 2^-1074 (guaranteed in the exact
    # range), so err is exact.
    cdef double x = a * b
    err[0] = fma(a, b, -x)
    p[0] = x


# ---------------------------------------------------------------------------
# Expansions.  An expansion is an array of doubles h[0..n) whose exact sum is
# the represented value.  Invariant kept by every routine below: components
# are nonzero, sorted by increasing magnitude and non-overlapping (the lowest
# set bit of each component lies above the highest set bit of the previous
# one).  The empty expansion (n == 0) is zero.
# ---------------------------------------------------------------------------

cdef inline int _exp_grow(double* h, int hlen, double b) noexcept nogil:
    # h := h + b, in place.  Shewchuk's grow-expansion (Theorem 10 of the
    # paper): running b up through the components with two-sum keeps the
    # result non-overlapping and sorted whenever h was, with no assumption on
    # b and no tie-breaking requirement.  Zero errors are dropped so lengths
    # stay short; the write index never passes the read index, so working
    # in place is safe.
    cdef double q = b
    cdef double t
    cdef int i
    cdef int k = 0
    if b == 0.0:
        return hlen
    for i in range(hlen):
        _exp_two_sum(q, h[i], &q, &t)
        if t != 0.0:
            h[k] = t
            k += 1
    if q != 0.0:
        h[k] = q
        k += 1
    return k


cdef inline int _exp_add_product(double* h, int hlen,
                                 const double* e, int elen,
                                 const double* f, int flen,
                                 double sign) noexcept nogil:
    # h := h + sign * e * f, sign = +1.0 or -1.0 (negation is exact).  Every
    # pairwise product e[i]*f[j] is split exactly by two-product and both
    # halves are grown into h, so the result is exact and, because it is
    # built only by growing, non-overlapping whatever the shape of e and f.
    # Needs room for hlen + 2*elen*flen components.
    cdef int i, j
    cdef double p, err
    for i in range(elen):
        for j in range(flen):
            _exp_two_product(sign * e[i], f[j], &p, &err)
            hlen = _exp_grow(h, hlen, err)
            hlen = _exp_grow(h, hlen, p)
    return hlen


cdef inline int _exp_sign(const double* h, int hlen) noexcept nogil:
    # In a non-overlapping expansion the smaller components together are
    # smaller than the lowest set bit of the largest, so the largest decides.
    if hlen == 0:
        return 0
    return (h[hlen - 1] > 0.0) - (h[hlen - 1] < 0.0)


cdef inline int _exp_diff(double a, double b, double* h) noexcept nogil:
    # a - b exactly, as an expansion of at most two components.
    cdef double d, err
    _exp_two_sum(a, -b, &d, &err)
    cdef int n = 0
    if err != 0.0:
        h[n] = err
        n += 1
    if d != 0.0:
        h[n] = d
        n += 1
    return n


# ---------------------------------------------------------------------------
# Exact stage building blocks.
# ---------------------------------------------------------------------------

cdef int _pred_cross(const double* p, int plen, const double* q, int qlen,
                     const double* r, int rlen, const double* s, int slen,
                     double* out) noexcept nogil:
    # out := p*q - r*s (a 2x2 minor).  out needs _exp_max_cross components.
    cdef int n = 0
    n = _exp_add_product(out, n, p, plen, q, qlen, 1.0)
    n = _exp_add_product(out, n, r, rlen, s, slen, -1.0)
    return n


cdef int _pred_lift(const double* dx, int dxlen, const double* dy, int dylen,
                    double* out) noexcept nogil:
    # out := dx^2 + dy^2.  out needs _exp_max_lift components.
    cdef int n = 0
    n = _exp_add_product(out, n, dx, dxlen, dx, dxlen, 1.0)
    n = _exp_add_product(out, n, dy, dylen, dy, dylen, 1.0)
    return n


cdef int _pred_orient2d_exact(const double* a, const double* b, const double* c) noexcept nogil:
    # The differences are kept exact as two-component expansions, so the
    # cross product below is the true determinant, not an approximation.
    cdef double bax[_exp_max_diff]
    cdef double cay[_exp_max_diff]
    cdef double bay[_exp_max_diff]
    cdef double cax[_exp_max_diff]
    cdef double det[_exp_max_cross]
    cdef int nbax = _exp_diff(b[0], a[0], bax)
    cdef int ncay = _exp_diff(c[1], a[1], cay)
    cdef int nbay = _exp_diff(b[1], a[1], bay)
    cdef int ncax = _exp_diff(c[0], a[0], cax)
    cdef int n = _pred_cross(bax, nbax, cay, ncay, bay, nbay, cax, ncax, det)
    return _exp_sign(det, n)


cdef int _pred_incircle_exact(const double* a, const double* b, const double* c,
                              const double* d) noexcept nogil:
    # Expansion along the lifted column:
    #   alift * (bdx*cdy - cdx*bdy) + blift * (cdx*ady - adx*cdy)
    #     + clift * (adx*bdy - bdx*ady)
    # with every difference, lift and minor carried exactly.
    cdef double adx[_exp_max_diff]
    cdef double ady[_exp_max_diff]
    cdef double bdx[_exp_max_diff]
    cdef double bdy[_exp_max_diff]
    cdef double cdx[_exp_max_diff]
    cdef double cdy[_exp_max_diff]
    cdef double lift[_exp_max_lift]
    cdef double minor[_exp_max_cross]
    cdef double det[_exp_max_incircle]
    cdef int nadx = _exp_diff(a[0], d[0], adx)
    cdef int nady = _exp_diff(a[1], d[1], ady)
    cdef int nbdx = _exp_diff(b[0], d[0], bdx)
    cdef int nbdy = _exp_diff(b[1], d[1], bdy)
    cdef int ncdx = _exp_diff(c[0], d[0], cdx)
    cdef int ncdy = _exp_diff(c[1], d[1], cdy)
    cdef int nlift, nminor
    cdef int n = 0

    nlift = _pred_lift(adx, nadx, ady, nady, lift)
    nminor = _pred_cross(bdx, nbdx, cdy, ncdy, cdx, ncdx, bdy, nbdy, minor)
    n = _exp_add_product(det, n, lift, nlift, minor, nminor, 1.0)

    nlift = _pred_lift(bdx, nbdx, bdy, nbdy, lift)
    nminor = _pred_cross(cdx, ncdx, ady, nady, adx, nadx, cdy, ncdy, minor)
    n = _exp_add_product(det, n, lift, nlift, minor, nminor, 1.0)

    nlift = _pred_lift(cdx, ncdx, cdy, ncdy, lift)
    nminor = _pred_cross(adx, nadx, bdy, nbdy, bdx, nbdx, ady, nady, minor)
    n = _exp_add_product(det, n, lift, nlift, minor, nminor, 1.0)

    return _exp_sign(det, n)


# ---------------------------------------------------------------------------
# Floating-point filters.  Return -1/0/+1 when the rounded determinant is
# provably correct, _pred_undecided otherwise.
# ---------------------------------------------------------------------------

cdef inline int _pred_orient2d_filter(const double* a, const double* b, const double* c) noexcept nogil:
    cdef double detleft = (b[0] - a[0]) * (c[1] - a[1])
    cdef double detright = (b[1] - a[1]) * (c[0] - a[0])
    cdef double det = detleft - detright
    cdef double bound = _pred_orient2d_errbound() * (fabs(detleft) + fabs(detright))
    # One well-predicted branch; the sign itself is computed branch-free.
    if fabs(det) > bound:
        return (det > 0.0) - (det < 0.0)
    # A zero permanent means both rounded products are 0, and in the exact
    # range a product rounds to 0 only if it is 0: the points are exactly
    # collinear.  This catches axis-aligned degeneracies (e.g. three points
    # on a horizontal boundary) without the exact stage.
    if bound == 0.0:
        return 0
    return _pred_undecided


cdef inline int _pred_incircle_filter(const double* a, const double* b, const double* c,
                                      const double* d) noexcept nogil:
    cdef double adx = a[0] - d[0]
    cdef double ady = a[1] - d[1]
    cdef double bdx = b[0] - d[0]
    cdef double bdy = b[1] - d[1]
    cdef double cdx = c[0] - d[0]
    cdef double cdy = c[1] - d[1]

    cdef double bdxcdy = bdx * cdy
    cdef double cdxbdy = cdx * bdy
    cdef double alift = adx * adx + ady * ady

    cdef double cdxady = cdx * ady
    cdef double adxcdy = adx * cdy
    cdef double blift = bdx * bdx + bdy * bdy

    cdef double adxbdy = adx * bdy
    cdef double bdxady = bdx * ady
    cdef double clift = cdx * cdx + cdy * cdy

    cdef double det = (alift * (bdxcdy - cdxbdy)
                       + blift * (cdxady - adxcdy)
                       + clift * (adxbdy - bdxady))
    cdef double permanent = ((fabs(bdxcdy) + fabs(cdxbdy)) * alift
                             + (fabs(cdxady) + fabs(adxcdy)) * blift
                             + (fabs(adxbdy) + fabs(bdxady)) * clift)
    cdef double bound = _pred_incircle_errbound() * permanent
    if fabs(det) > bound:
        return (det > 0.0) - (det < 0.0)
    # Zero permanent: every lifted term is exactly 0 (see orient2d).
    if bound == 0.0:
        return 0
    return _pred_undecided


# ---------------------------------------------------------------------------
# Public predicates.
# ---------------------------------------------------------------------------

cdef inline int orient2d(const double* a, const double* b, const double* c) noexcept nogil:
    cdef int s = _pred_orient2d_filter(a, b, c)
    if s != _pred_undecided:
        return s
    return _pred_orient2d_exact(a, b, c)


cdef inline int incircle(const double* a, const double* b, const double* c, const double* d) noexcept nogil:
    cdef int s = _pred_incircle_filter(a, b, c, d)
    if s != _pred_undecided:
        return s
    return _pred_incircle_exact(a, b, c, d)


def py_orient2d(double ax, double ay, double bx, double by, double cx, double cy):
    """Exact sign (-1, 0, +1) of the orientation of (a, b, c); +1 = counter-clockwise."""
    cdef double p[6]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy
    return orient2d(&p[0], &p[2], &p[4])


def py_incircle(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy):
    """Exact sign (-1, 0, +1) of incircle(a, b, c, d); +1 = d inside when a, b, c are counter-clockwise."""
    cdef double p[8]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy; p[6] = dx; p[7] = dy
    return incircle(&p[0], &p[2], &p[4], &p[6])


# Test hooks: the two stages separately, and the filter constants.

def _pred_py_orient2d_stages(double ax, double ay, double bx, double by, double cx, double cy):
    """(filter verdict or None if undecided, exact-stage sign)."""
    cdef double p[6]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy
    cdef int f = _pred_orient2d_filter(&p[0], &p[2], &p[4])
    cdef int e = _pred_orient2d_exact(&p[0], &p[2], &p[4])
    return (None if f == _pred_undecided else f), e


def _pred_py_incircle_stages(double ax, double ay, double bx, double by, double cx, double cy,
                             double dx, double dy):
    """(filter verdict or None if undecided, exact-stage sign)."""
    cdef double p[8]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy; p[6] = dx; p[7] = dy
    cdef int f = _pred_incircle_filter(&p[0], &p[2], &p[4], &p[6])
    cdef int e = _pred_incircle_exact(&p[0], &p[2], &p[4], &p[6])
    return (None if f == _pred_undecided else f), e


def _pred_error_bounds():
    """The filter constants (orient2d, incircle) exactly as compiled."""
    return _pred_orient2d_errbound(), _pred_incircle_errbound()
