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
# Three stages, each run only when the previous one cannot decide.
#   A. Filter (inline): evaluate the determinant in plain floating point and
#      compare it with an error bound relative to the permanent (the same
#      expression with every product replaced by its absolute value).  If
#      |det| exceeds the bound, the rounded det has the true sign.
#   B. Adaptive stage (non-inline, "stage B"; see STAGE B below): compute
#      the coordinate differences with two-diff.  By Sterbenz's lemma
#      x - y is exact whenever y/2 <= x <= 2y, so for nearby points the
#      differences are almost always exact, and then the determinant is a
#      polynomial in six doubles: stage B evaluates it exactly with a few
#      dozen two-products and two-sums, mostly straight-line code, and
#      returns its sign (orient2d: by a monotonicity argument, without any
#      sums).  With inexact differences, orient2d's stage B abstains;
#      incircle's evaluates the determinant of the rounded differences
#      exactly, adds the first-order effect of the rounding errors (tails),
#      and returns the sign when the result clears a proven bound of order
#      eps^2 times the permanent, else abstains.
#      Measured (x86-64, filter-undecided inputs): incircle's stage B takes
#      75-90 ns on nearly cocircular points of rounded equilateral lattices
#      and small circles, 150-200 ns on exactly cocircular full-width
#      inputs and with inexact differences; stage C 0.6-1.1 us on the same
#      inputs.  orient2d: stage B about 5 ns, stage C 20-30 ns.
#   C. Exact stage (non-inline): recompute the determinant from
#      two-component differences as a floating-point expansion (a sum of
#      non-overlapping doubles) and read its sign off the largest component.
#      Reached only when stage B abstains: for orient2d, inexact
#      differences (points on both sides of an axis, coordinates of very
#      different magnitude); for incircle, inexact differences with a
#      determinant within the bound (in practice: exactly zero), or lifts or
#      minors that do not fit in three doubles (differences spanning far
#      more than 53 bits together).
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
# STAGE B
# -------
# incircle: let D be the six true differences (adx, ady, ..., cdy), d their
# rounded values and t = D - d the tails (two-diff).  Each lift dx^2 + dy^2
# and minor (e.g. bdx*cdy - cdx*bdy) of d is written exactly as a sum of two
# doubles (three if the two-product tails do not fit in one; else stage B
# abstains), and the two-products of the parts, lift_k part i times minor_k
# part j, give n = 24 (or 54) doubles z[0..n).  Then two-sum sweeps run
# over z until the sign can be certified.  The proofs use only the
# following facts, and no structure of the intermediate values (which only
# makes the certificate succeed early):
#   (V) Exact value.  Two-sum and two-product (fma) are error-free
#       transformations in the exact range below, negation is exact, and a
#       lift or minor is split into parts only after checking that the
#       remainder is 0.  So the exact sum of z is det(d), the determinant of
#       the rounded differences.  Sweeps keep the exact sum.
#   (C) Certificate.  T = fl(|z[0]| + ... + |z[n-2]|) summed recursively:
#       every addition of non-negative values rounds to nearest with
#       relative error < eps (no underflow: the partial sums are 0 or at
#       least the smallest nonzero |z[i]|, and in the exact range every
#       nonzero component is >= 2^-968), so T >= (1-eps)^(n-2) *
#       (|z[0]| + ... + |z[n-2]|), i.e. that exact sum is < 2T (n <= 55),
#       or 0 if T == 0.  Hence if |z[n-1]| > 2T, or T == 0, the exact sum
#       of z has the sign of z[n-1].  2T and 4T are exact (no overflow in
#       the range).  NaN fails every comparison.
#   (G) Growing.  If the certificate still fails after a few sweeps (this
#       happens for some exactly zero determinants), the n doubles are
#       grown one by one into a fresh expansion with _exp_grow, which is
#       non-overlapping whatever it is fed (Theorem 10 of Shewchuk's paper,
#       exactly as in stage C), and the sign is read off its largest
#       component.
#   Exact differences (t = 0): det(d) is the true determinant, so the sign
#   from (C) or (G) is exact; no error bound on an approximation is used.
#   (T) Inexact differences.  |t_i| <= eps |d_i| (round to nearest; d_i is
#       normal or 0 in the range).  The determinant is a sum of 12 monomials
#       +-D_i D_j D_k D_l (the cofactor expansion, multiplied out); P, the
#       sum of their magnitudes |d_i d_j d_k d_l|, is the exact permanent of
#       d.  Multiplying out D = d + t, det(D) = det(d) + F + R with F the
#       terms with one tail and R those with two or more:
#       |R| <= (6 eps^2 + 4 eps^3 + eps^4) P, and the terms of F have
#       magnitudes summing to F_abs <= 4 eps P.  F is evaluated in floating
#       point by the cofactor form (_pred_incircle_first_order_term, then a
#       sum of three), with at most 10 roundings on every path of the
#       expression tree, so |fl(F) - F| <= gamma_10 F_abs with
#       gamma_10 = 10 eps / (1 - 10 eps) (the standard bound: every term of
#       the multiplied-out expression picks up at most 10 factors 1 + delta,
#       |delta| <= eps), i.e. <= 40.0001 eps^2 P.  Hence
#       |det(D) - (det(d) + fl(F))| <= 46.001 eps^2 P.  The permanent
#       computed in floating point, perm, has at most 7 roundings on every
#       path, all of non-negative values, so P <= perm / (1-eps)^7 and the
#       error is <= 46.01 eps^2 perm <= fl(48 eps^2 perm) =: bound (the
#       last rounding loses at most a factor 1 - eps; perm >= 2^-900 is
#       required so that bound is a normal number).  fl(F) is appended to z,
#       which then sums exactly to S = det(d) + fl(F), with
#       |det(D) - S| <= bound.  After a sweep, if |z[n-1]| >= 4T and
#       |z[n-1]| > 2 bound, then by (C) |S - z[n-1]| <= 2T <= |z[n-1]|/2,
#       so S has the sign of z[n-1] and |S| >= |z[n-1]|/2 > bound, hence
#       det(D) has that sign too.  Otherwise stage B abstains.
# orient2d (exact differences only): det = P - R with P = bax*cay and
#   R = bay*cax real products and (p, perr), (r, rerr) their two-products.
#   (M) Rounding is monotone, so p > r implies P > R (and p < r implies
#   P < R); if p == r, det = perr - rerr exactly, compared directly.
#
# PLATFORM ASSUMPTIONS
# --------------------
# IEEE-754 binary64 with round-to-nearest-even (the default mode), no
# extended-precision intermediates (SSE2 on x86-64, not x87), a correctly
# rounded fma() (C99; glibc uses the hardware instruction or an exact
# software emulation), and no contraction of a*b+c into fma or any other
# value-changing optimisation: setup.py passes -ffp-contract=off and never
# -ffast-math.

# Uses: nothing else of the kernel (the predicates never touch topology).
from libc.math cimport fabs, fma


# Capacities of the fixed stack buffers used by the exact stage (C).  Every call
# to _exp_grow adds at most one component, so a buffer never needs more
# components than the number of doubles grown into it:
#   a 2x2 cross term p*q - r*s of two-component differences:
#       2 products * (2*2 component pairs) * 2 doubles per two-product = 16;
#   a lifted term dx^2 + dy^2: the same count, 16;
#   the incircle determinant: 3 terms * (16*16 pairs) * 2 doubles = 1536.
# The range of EXACT RANGE above, as numbers: the Python layer refuses
# coordinates outside it (aftmesh.pslg.check_range reads it from the kernel).
cdef double EXACT_MIN_COORDINATE = 1e-57
cdef double EXACT_MAX_COORDINATE = 1e75

cdef enum:
    _exp_max_diff = 2
    _exp_max_cross = 16
    _exp_max_lift = 16
    _exp_max_incircle = 1536

# Stage B of incircle sums the two-products of the parts of 3 lifts and 3
# minors: 3 * 2*2 * 2 = 24 doubles with 2 parts each, 3 * 3*3 * 2 = 54 with 3,
# plus one for the first-order tail term when differences are inexact.
cdef enum:
    _exp_max_sweep = 55

# Stage outcome meaning "cannot decide, run the next stage".
cdef enum:
    _pred_undecided = 2


# The filter constants, written as their defining formulas with
# eps = 2^-53 (the literal below is exactly 2^-53).  Every step is exact, so
# the C compiler folds each to the exact constant.

cdef inline double _pred_orient2d_errbound() noexcept nogil:
    return (3.0 + 16.0 * 1.1102230246251565e-16) * 1.1102230246251565e-16


cdef inline double _pred_incircle_errbound() noexcept nogil:
    return (10.0 + 96.0 * 1.1102230246251565e-16) * 1.1102230246251565e-16


cdef inline double _pred_incircle_errbound_tails() noexcept nogil:
    # Stage B with inexact differences: 48 eps^2, bound (T) in the header.
    return (48.0 * 1.1102230246251565e-16) * 1.1102230246251565e-16


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
# Stage C (exact) building blocks.
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
# Stage B: the determinant of the rounded differences, exactly.  Returns
# -1/0/+1 or _pred_undecided (then stage C runs).  See "STAGE B" in the
# header for the proofs.
# ---------------------------------------------------------------------------

cdef inline bint _pred_diff_exact(double a, double b, double* d) noexcept nogil:
    # d := fl(a - b); true iff the two-diff error is 0, i.e. d == a - b
    # exactly.  A NaN or infinite operand gives a NaN error: false.
    cdef double err
    _exp_two_sum(a, -b, d, &err)
    return err == 0.0


cdef inline bint _pred_diff_tail(double a, double b, double* d, double* tail) noexcept nogil:
    # d + tail == a - b exactly (two-diff); true iff tail == 0.  A NaN or
    # infinite operand gives a NaN tail: false.
    _exp_two_sum(a, -b, d, tail)
    return tail[0] == 0.0


cdef int _pred_orient2d_adapt(const double* a, const double* b, const double* c) noexcept nogil:
    # Exact differences only (fact (M) in the header); else abstain.
    cdef double bax, cay, bay, cax, p, perr, r, rerr
    cdef bint exact = _pred_diff_exact(b[0], a[0], &bax)
    exact &= _pred_diff_exact(c[1], a[1], &cay)
    exact &= _pred_diff_exact(b[1], a[1], &bay)
    exact &= _pred_diff_exact(c[0], a[0], &cax)
    if not exact:
        return _pred_undecided
    # det = bax*cay - bay*cax = (p + perr) - (r + rerr) exactly.
    _exp_two_product(bax, cay, &p, &perr)
    _exp_two_product(bay, cax, &r, &rerr)
    if p != r:
        return (p > r) - (p < r)
    return (perr > rerr) - (perr < rerr)


# Sweeps tried before growing (exact differences) or abstaining (inexact).
cdef enum:
    _pred_max_sweeps = 4
    _pred_max_sweeps_tails = 2

# Which part of incircle's stage B decided (reported by a test hook).
cdef enum:
    _pred_path_inexact = 0      # inexact differences, (T) not met: abstained
    _pred_path_split = 1        # a lift or minor needs > 3 parts: abstained
    _pred_path_sweep1 = 2       # certified after one sweep
    _pred_path_sweeps = 3       # certified after 2.._pred_max_sweeps sweeps
    _pred_path_grown = 4        # certificate failed: grown
    _pred_path_tails = 5        # inexact differences, decided by bound (T)


cdef inline int _pred_two_two_parts(double a, double b, double c, double d,
                                    double* part) noexcept nogil:
    # Write a*b + c*d as part[0] + part[1] + part[2] exactly, if possible:
    #   a*b + c*d = p1 + e1 + p2 + e2       (two-products)
    #             = s + t + e1 + e2         (s, t = two-sum(p1, p2))
    #             = s + w + x + e2          (w, x = two-sum(t, e1))
    #             = s + lo + x + y          (lo, y = two-sum(w, e2))
    #             = s + lo + r + u          (r, u = two-sum(x, y))
    # with part = (s, lo, r).  Returns 0 if r == u == 0 (two parts
    # suffice, part[2] == 0), 1 if only u == 0 (three parts), 2 if the
    # three parts are not exact (u != 0).  Two parts usually suffice: t,
    # e1, e2 are multiples of the products' unit and at most about an ulp
    # of them, so their sum fits in one double unless the products span
    # more than about 105 bits; three parts cover about 158 bits.
    cdef double p1, e1, p2, e2, t, w, x, y, u
    _exp_two_product(a, b, &p1, &e1)
    _exp_two_product(c, d, &p2, &e2)
    _exp_two_sum(p1, p2, &part[0], &t)
    _exp_two_sum(t, e1, &w, &x)
    _exp_two_sum(w, e2, &part[1], &y)
    _exp_two_sum(x, y, &part[2], &u)
    return (u != 0.0) * 2 + ((u == 0.0) & (part[2] != 0.0))


cdef inline int _pred_incircle_products(const double* lift, const double* minor, int nparts,
                                        double* z) noexcept nogil:
    # z := the two-products lift[3k+i] * minor[3k+j] for k < 3 and
    # i, j < nparts (part i of lift k times part j of minor k), both halves
    # of each; returns their number, 2 * 3 * nparts^2.  By (V) their exact
    # sum is sum_k lift_k * minor_k, the determinant.  Stored roughly large
    # to small: by level i + j, the products of a level, then their errors;
    # so the three hi*hi products come first, and their cancellation (often
    # exact by Sterbenz's lemma) happens first in a sweep.
    cdef int level, k, i, j
    cdef int n = 0
    cdef int m
    for level in range(2 * nparts - 1):
        m = 0
        for k in range(3):
            for i in range(nparts):
                j = level - i
                if 0 <= j < nparts:
                    m += 1
        for k in range(3):
            for i in range(nparts):
                j = level - i
                if 0 <= j < nparts:
                    _exp_two_product(lift[3 * k + i], minor[3 * k + j], &z[n], &z[n + m])
                    n += 1
        n += m
    return n


cdef inline void _exp_sweep(double* z, int n) noexcept nogil:
    # One distillation sweep, in place: carry a running sum from z[0] up
    # with two-sum, leaving each addition's exact error behind; the sum
    # ends in z[n-1].  The exact total of z is unchanged.
    cdef double q = z[0]
    cdef int i
    for i in range(1, n):
        _exp_two_sum(q, z[i], &q, &z[i - 1])
    z[n - 1] = q


cdef inline int _exp_certified_sign(const double* z, int n) noexcept nogil:
    # Sign of the exact sum of z[0..n) if z[n-1] provably dominates, else
    # _pred_undecided.  Fact (C) in the header: with T = fl(|z[0]| + ... +
    # |z[n-2]|), |z[n-1]| > 2T or T == 0 implies that the sum has the sign
    # of z[n-1].  2T is exact; NaN fails.
    cdef double tot = 0.0
    cdef double top = z[n - 1]
    cdef int i
    for i in range(n - 1):
        tot += fabs(z[i])
    if fabs(top) > 2.0 * tot or tot == 0.0:
        return (top > 0.0) - (top < 0.0)
    return _pred_undecided


cdef inline int _exp_bounded_sign(const double* z, int n, double bound) noexcept nogil:
    # z[0..n) sums exactly to S, and |det - S| <= bound for the wanted det.
    # Returns sign(det) or _pred_undecided.  By fact (C) the components
    # below the top sum to at most 2T in magnitude, so |top| >= 4T gives
    # |S - top| <= |top|/2: S has the sign of top and |S| >= |top|/2; then
    # |top| > 2 bound gives |S| > bound >= |det - S|, so det has the sign
    # of S.  4T and 2 bound are exact; NaN fails.
    cdef double tot = 0.0
    cdef double top = fabs(z[n - 1])
    cdef int i
    for i in range(n - 1):
        tot += fabs(z[i])
    if top >= 4.0 * tot and top > 2.0 * bound:
        return (z[n - 1] > 0.0) - (z[n - 1] < 0.0)
    return _pred_undecided


cdef int _pred_grown_sign(const double* h, int n) noexcept nogil:
    # Fact (G): sign of the exact sum of h[0..n) for ANY doubles, by growing
    # them one by one into a fresh expansion (non-overlapping by Theorem 10,
    # whatever it is fed) and reading its largest component, exactly as
    # stage C does.  Each grow adds at most one component: n slots suffice.
    cdef double g[_exp_max_sweep]
    cdef int i
    cdef int m = 0
    for i in range(n):
        m = _exp_grow(g, m, h[i])
    return _exp_sign(g, m)


cdef inline double _pred_incircle_permanent(const double* dd) noexcept nogil:
    # The filter's permanent of the rounded differences dd = (adx, ady, bdx,
    # bdy, cdx, cdy), same expression and evaluation order (at most 7
    # roundings on every path, all of non-negative values).
    cdef double alift = dd[0] * dd[0] + dd[1] * dd[1]
    cdef double blift = dd[2] * dd[2] + dd[3] * dd[3]
    cdef double clift = dd[4] * dd[4] + dd[5] * dd[5]
    return ((fabs(dd[2] * dd[5]) + fabs(dd[4] * dd[3])) * alift
            + (fabs(dd[4] * dd[1]) + fabs(dd[0] * dd[5])) * blift
            + (fabs(dd[0] * dd[3]) + fabs(dd[2] * dd[1])) * clift)


cdef inline double _pred_incircle_first_order_term(const double* dd, const double* tl,
                                                   int p, int e, int f) noexcept nogil:
    # First-order (in the tails) part of lift_p * minor_ef, in floating
    # point: lift' * minor + lift * minor' with lift' = 2 (px pxt + py pyt)
    # and minor' = ext fy + ex fyt - fxt ey - fx eyt.  Roundings on any path:
    # minor 2, lift 2, lift'/2 2, minor' 4; products 5 and 7; the sum 8.
    cdef double m = dd[e] * dd[f + 1] - dd[f] * dd[e + 1]
    cdef double lift = dd[p] * dd[p] + dd[p + 1] * dd[p + 1]
    cdef double lp = dd[p] * tl[p] + dd[p + 1] * tl[p + 1]
    cdef double mp = (((tl[e] * dd[f + 1] + dd[e] * tl[f + 1]) - tl[f] * dd[e + 1])
                      - dd[f] * tl[e + 1])
    return (2.0 * lp) * m + lift * mp


cdef inline int _pred_incircle_adapt_path(const double* a, const double* b, const double* c,
                                          const double* d, int* path) noexcept nogil:
    # With exact differences the determinant is the cofactor expansion
    #   alift * (bdx*cdy - cdx*bdy) + blift * (cdx*ady - adx*cdy)
    #     + clift * (adx*bdy - bdx*ady)
    # of six doubles.  Each lift and minor is written exactly as a sum of 2
    # (or, if needed, 3) doubles, the two-products of their parts give 24
    # (54) doubles summing exactly to the determinant, and the sign of that
    # sum is certified after one or more sweeps, else found by growing.
    # Straight-line code up to the sweeps.
    cdef double dd[6]
    cdef double tl[6]
    cdef double lift[9]
    cdef double minor[9]
    cdef double z[_exp_max_sweep]
    cdef double perm, bound
    cdef int k, n, sgn, need
    cdef bint exact = _pred_diff_tail(a[0], d[0], &dd[0], &tl[0])
    exact &= _pred_diff_tail(a[1], d[1], &dd[1], &tl[1])
    exact &= _pred_diff_tail(b[0], d[0], &dd[2], &tl[2])
    exact &= _pred_diff_tail(b[1], d[1], &dd[3], &tl[3])
    exact &= _pred_diff_tail(c[0], d[0], &dd[4], &tl[4])
    exact &= _pred_diff_tail(c[1], d[1], &dd[5], &tl[5])

    # Lifts dx^2 + dy^2 and minors (cyclic: b,c for a; c,a for b; a,b for c).
    need = _pred_two_two_parts(dd[0], dd[0], dd[1], dd[1], &lift[0])
    need |= _pred_two_two_parts(dd[2], dd[2], dd[3], dd[3], &lift[3])
    need |= _pred_two_two_parts(dd[4], dd[4], dd[5], dd[5], &lift[6])
    need |= _pred_two_two_parts(dd[2], dd[5], -dd[4], dd[3], &minor[0])
    need |= _pred_two_two_parts(dd[4], dd[1], -dd[0], dd[5], &minor[3])
    need |= _pred_two_two_parts(dd[0], dd[3], -dd[2], dd[1], &minor[6])
    if need == 0:
        n = _pred_incircle_products(lift, minor, 2, z)
    elif need == 1:
        n = _pred_incircle_products(lift, minor, 3, z)
    else:
        path[0] = _pred_path_split
        return _pred_undecided

    if exact:
        # The determinant of the differences is the true determinant.
        for k in range(_pred_max_sweeps):
            _exp_sweep(z, n)
            sgn = _exp_certified_sign(z, n)
            if sgn != _pred_undecided:
                path[0] = _pred_path_sweep1 + (k > 0)
                return sgn
        path[0] = _pred_path_grown
        return _pred_grown_sign(z, n)

    # Inexact differences: z sums to the determinant of the rounded
    # differences; add the first-order tail term and use bound (T).  Below
    # 2^-900 the bound could underflow: leave such inputs to stage C (a NaN
    # permanent fails the test too).
    perm = _pred_incircle_permanent(dd)
    if not perm >= 1.1830521861667747e-271:            # 2^-900
        path[0] = _pred_path_inexact
        return _pred_undecided
    bound = _pred_incircle_errbound_tails() * perm
    z[n] = ((_pred_incircle_first_order_term(dd, tl, 0, 2, 4)
             + _pred_incircle_first_order_term(dd, tl, 2, 4, 0))
            + _pred_incircle_first_order_term(dd, tl, 4, 0, 2))
    n += 1
    for k in range(_pred_max_sweeps_tails):
        _exp_sweep(z, n)
        sgn = _exp_bounded_sign(z, n, bound)
        if sgn != _pred_undecided:
            path[0] = _pred_path_tails
            return sgn
    path[0] = _pred_path_inexact
    return _pred_undecided


cdef int _pred_incircle_adapt(const double* a, const double* b, const double* c,
                              const double* d) noexcept nogil:
    cdef int path
    return _pred_incircle_adapt_path(a, b, c, d, &path)


# ---------------------------------------------------------------------------
# Floating-point filters.  Return -1/0/+1 when the rounded determinant is
# provably correct, _pred_undecided otherwise.
# ---------------------------------------------------------------------------

cdef inline int _pred_orient2d_filter(const double* a, const double* b,
                                      const double* c) noexcept nogil:
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


cdef inline bint surely_acute(const double* a, const double* b,
                              const double* p) noexcept nogil:
    """True only if the angle at p of the triangle (a, b, p) is certainly below 90
    degrees: (a - p).(b - p) > 0 exactly.  The dot product has the form of orient2d's
    determinant (two products of differences from one point, added instead of
    subtracted), so orient2d's filter bound holds for it, over the same exact range
    of coordinates (see test_predicates.py); False when unsure.  (Two
    such angles facing an edge sum to less than 180 degrees, so the edge is strictly
    locally Delaunay: no incircle test is needed.)"""
    cdef double xx = (a[0] - p[0]) * (b[0] - p[0])
    cdef double yy = (a[1] - p[1]) * (b[1] - p[1])
    return xx + yy > _pred_orient2d_errbound() * (fabs(xx) + fabs(yy))


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


cdef bint _pred_axis_rectangle(const double* a, const double* b, const double* c,
                               const double* d) noexcept nogil:
    """The four points are the corners of an axis-parallel rectangle, in any order:
    cocircular, so incircle is exactly 0.  Input split evenly along parallel walls (a
    channel, a comb's teeth, a rectangle's sides) gives these by the thousand, and the
    filter cannot decide a zero: the adaptive stage took some 1,900 instructions for
    each.  d shares its x with exactly one of a, b, c (p) and its y with exactly one
    other (q); the third (o) then has q's x and p's y, which differ from d's."""
    cdef const double* pts[3]
    cdef int i, ip = -1, iq = -1, io = 0
    pts[0] = a
    pts[1] = b
    pts[2] = c
    for i in range(3):
        if pts[i][0] == d[0]:
            if ip >= 0:
                return False
            ip = i
        if pts[i][1] == d[1]:
            if iq >= 0:
                return False
            iq = i
    if ip < 0 or iq < 0 or ip == iq:
        return False
    io = 3 - ip - iq
    return pts[io][0] == pts[iq][0] and pts[io][1] == pts[ip][1]


# ---------------------------------------------------------------------------
# Public predicates.
# ---------------------------------------------------------------------------

cdef inline int orient2d(const double* a, const double* b, const double* c) noexcept nogil:
    cdef int s = _pred_orient2d_filter(a, b, c)
    if s != _pred_undecided:
        return s
    s = _pred_orient2d_adapt(a, b, c)
    if s != _pred_undecided:
        return s
    return _pred_orient2d_exact(a, b, c)


cdef inline int incircle(const double* a, const double* b, const double* c,
                         const double* d) noexcept nogil:
    cdef int s = _pred_incircle_filter(a, b, c, d)
    if s != _pred_undecided:
        return s
    if _pred_axis_rectangle(a, b, c, d):
        return 0
    s = _pred_incircle_adapt(a, b, c, d)
    if s != _pred_undecided:
        return s
    return _pred_incircle_exact(a, b, c, d)


def py_orient2d(double ax, double ay, double bx, double by, double cx, double cy):
    """Exact sign (-1, 0, +1) of the orientation of (a, b, c); +1 = counter-clockwise."""
    cdef double p[6]
    p[:] = [ax, ay, bx, by, cx, cy]
    return orient2d(&p[0], &p[2], &p[4])


def py_incircle(double ax, double ay, double bx, double by, double cx, double cy,
                double dx, double dy):
    """Exact sign (-1, 0, +1) of incircle(a, b, c, d); +1 = d inside when a, b, c are
    counter-clockwise."""
    cdef double p[8]
    p[:] = [ax, ay, bx, by, cx, cy, dx, dy]
    return incircle(&p[0], &p[2], &p[4], &p[6])


# Test hooks: the stages separately, and the filter constants.

def _pred_py_orient2d_stages(double ax, double ay, double bx, double by, double cx, double cy):
    """(filter verdict or None if undecided, exact-stage sign)."""
    cdef double p[6]
    p[:] = [ax, ay, bx, by, cx, cy]
    cdef int f = _pred_orient2d_filter(&p[0], &p[2], &p[4])
    cdef int e = _pred_orient2d_exact(&p[0], &p[2], &p[4])
    return (None if f == _pred_undecided else f), e


def _pred_py_incircle_stages(double ax, double ay, double bx, double by, double cx, double cy,
                             double dx, double dy):
    """(filter verdict or None if undecided, exact-stage sign)."""
    cdef double p[8]
    p[:] = [ax, ay, bx, by, cx, cy, dx, dy]
    cdef int f = _pred_incircle_filter(&p[0], &p[2], &p[4], &p[6])
    cdef int e = _pred_incircle_exact(&p[0], &p[2], &p[4], &p[6])
    return (None if f == _pred_undecided else f), e


def _pred_py_surely_acute(double ax, double ay, double bx, double by, double px,
                          double py):
    """surely_acute(a, b, p): True only if the angle at p of (a, b, p) is acute."""
    cdef double q[6]
    q[:] = [ax, ay, bx, by, px, py]
    return bool(surely_acute(&q[0], &q[2], &q[4]))


def _pred_error_bounds():
    """The filter constants (orient2d, incircle) exactly as compiled."""
    return _pred_orient2d_errbound(), _pred_incircle_errbound()


def _pred_error_bound_tails():
    """Incircle's stage-B constant for inexact differences, exactly as compiled."""
    return _pred_incircle_errbound_tails()


def py_orient2d_stage_b(double ax, double ay, double bx, double by, double cx, double cy):
    """Exact-differences stage of orient2d alone: its sign, or None if it abstains."""
    cdef double p[6]
    p[:] = [ax, ay, bx, by, cx, cy]
    cdef int s = _pred_orient2d_adapt(&p[0], &p[2], &p[4])
    return None if s == _pred_undecided else s


def py_incircle_stage_b(double ax, double ay, double bx, double by, double cx, double cy,
                        double dx, double dy):
    """Exact-differences stage of incircle alone: its sign, or None if it abstains."""
    cdef double p[8]
    p[:] = [ax, ay, bx, by, cx, cy, dx, dy]
    cdef int s = _pred_incircle_adapt(&p[0], &p[2], &p[4], &p[6])
    return None if s == _pred_undecided else s


def _pred_py_incircle_stage_b_path(double ax, double ay, double bx, double by,
                                   double cx, double cy, double dx, double dy):
    """(verdict or None, path): which part of incircle's stage B decided.
    Abstained: 'inexact' (inexact differences and bound (T) not met), 'split'
    (a lift or minor is not a sum of three doubles).  Decided, exact
    differences: 'sweep1', 'sweeps' (certified after one / more sweeps),
    'grown' (certificate failed, components grown); inexact differences:
    'tails' (bound (T))."""
    cdef double p[8]
    cdef int path = -1
    p[:] = [ax, ay, bx, by, cx, cy, dx, dy]
    cdef int s = _pred_incircle_adapt_path(&p[0], &p[2], &p[4], &p[6], &path)
    names = ("inexact", "split", "sweep1", "sweeps", "grown", "tails")
    return (None if s == _pred_undecided else s), names[path]


def _pred_py_sum_sign(values, int sweeps):
    """Stage B's sign readers on a list of at most 54 doubles: (certified sign
    after `sweeps` sweeps or None, the swept list, the sign by growing the
    original list).  The swept list has the same exact sum as `values`."""
    cdef double z[_exp_max_sweep]
    cdef double orig[_exp_max_sweep]
    cdef int n = len(values)
    cdef int i
    cdef int cert = _pred_undecided
    if not 1 <= n <= _exp_max_sweep:
        raise ValueError("need 1 to %d values" % _exp_max_sweep)
    for i in range(n):
        z[i] = values[i]
        orig[i] = z[i]
    for i in range(sweeps):
        _exp_sweep(z, n)
    if sweeps > 0:
        cert = _exp_certified_sign(z, n)
    return ((None if cert == _pred_undecided else cert), [z[i] for i in range(n)],
            _pred_grown_sign(orig, n))
