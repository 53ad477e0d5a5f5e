# Spatial order of the input points: keys along a Hilbert curve, for the BRIO
# insertion order that keeps point location walks short (src/aftmesh/_order.py).
#
# Uses: libc.stdint only; no triangulation, no predicates.
from libc.stdint cimport int64_t, uint8_t


# The curve two levels at a time.  At each level the quadrant's digit is
# (3 rx) ^ ry of the point's bits seen in the current frame, and the frame turns for
# the next level: a transposition when ry == 0, with a reflection as well when
# rx == 1.  Those two commute and are their own inverses, so a frame is two bits
# (bit 0 transposed, bit 1 reflected), and two levels are a table from the frame and
# the two bits each of x and y (x's in bits 2-3, y's in bits 4-5) to the two digits
# (bits 0-3) and the frame after them (bits 4-5).
cdef uint8_t[64] _HILBERT_PAIR


cdef int _hilbert_level(int frame, int bx, int by, int* digit) noexcept nogil:
    # one level: the digit, and the frame after it
    cdef int rx = by if frame & 1 else bx
    cdef int ry = bx if frame & 1 else by
    if frame & 2:
        rx ^= 1
        ry ^= 1
    digit[0] = (3 * rx) ^ ry
    if ry == 0:
        frame ^= 1 if rx == 0 else 3
    return frame


cdef void _hilbert_pair_fill() noexcept nogil:
    cdef int i, frame, hi, lo
    for i in range(64):
        frame = _hilbert_level(i & 3, (i >> 3) & 1, (i >> 5) & 1, &hi)
        frame = _hilbert_level(frame, (i >> 2) & 1, (i >> 4) & 1, &lo)
        _HILBERT_PAIR[i] = <uint8_t> ((hi << 2) | lo | (frame << 4))


_hilbert_pair_fill()


cdef void hilbert_keys_into(const double* xy, Py_ssize_t n, int bits,
                            int64_t* out) noexcept nogil:
    """out[i] = index of point (xy[2i], xy[2i+1]) along a Hilbert curve of 2**bits
    cells a side laid over the points' bounding square (n > 0, 1 <= bits <= 31)."""
    cdef Py_ssize_t i
    cdef double lox = xy[0], loy = xy[1], hix = xy[0], hiy = xy[1], span, scale
    cdef int64_t side = (<int64_t> 1 << bits) - 1, x, y, d
    cdef int level, frame, digit, entry
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
        frame = 0
        level = bits
        if level & 1:           # an odd level count: the top level alone
            level -= 1
            frame = _hilbert_level(0, <int> ((x >> level) & 1), <int> ((y >> level) & 1),
                                   &digit)
            d = digit
        while level > 0:
            level -= 2
            entry = _HILBERT_PAIR[frame | (<int> ((x >> level) & 3) << 2)
                                  | (<int> ((y >> level) & 3) << 4)]
            d = (d << 4) | (entry & 15)
            frame = entry >> 4
        out[i] = d
