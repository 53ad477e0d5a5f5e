# Spatial order of the input points: keys along a Hilbert curve, for the BRIO
# insertion order that keeps point location walks short (src/aftmesh/_order.py).
#
# Uses: libc.stdint only; no triangulation, no predicates.
from libc.stdint cimport int64_t


cdef void hilbert_keys_into(const double* xy, Py_ssize_t n, int bits,
                            int64_t* out) noexcept nogil:
    """out[i] = index of point (xy[2i], xy[2i+1]) along a Hilbert curve of 2**bits
    cells a side laid over the points' bounding square (n > 0, 1 <= bits <= 31)."""
    cdef Py_ssize_t i
    cdef double lox = xy[0], loy = xy[1], hix = xy[0], hiy = xy[1], span, scale
    cdef int64_t side = (<int64_t> 1 << bits) - 1, x, y, s, d, rx, ry, tmp
    for i in range(n):
        lox = min(lox, xy[2 * i])
        hix = max(hix, xy[2 * i])
        loy = min(loy, xy[2 * i + 1])
        hiy = max(hiy, xy[2 * i + 1])
    span = max(hix - lox, hiy - loy)
    if not span > 0:
        for i in range(n):
            out[i] = 0
        return
    scale = side / span
    for i in range(n):
        x = <int64_t> ((xy[2 * i] - lox) * scale)
        y = <int64_t> ((xy[2 * i + 1] - loy) * scale)
        x = min(max(x, 0), side)
        y = min(max(y, 0), side)
        d = 0
        s = <int64_t> 1 << (bits - 1)
        while s > 0:
            rx = 1 if (x & s) else 0
            ry = 1 if (y & s) else 0
            d += s * s * ((3 * rx) ^ ry)
            # rotate the quadrant so the curve inside has the standard orientation
            if ry == 0:
                if rx == 1:
                    x = side - x
                    y = side - y
                tmp = x
                x = y
                y = tmp
            s >>= 1
        out[i] = d
