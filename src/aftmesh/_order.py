"""Insertion order for bulk point insertion: biased randomized insertion order (BRIO)
with a Hilbert curve order inside each round.

Incremental Delaunay insertion walks from the last inserted triangle to the next point;
consecutive points that are close on a Hilbert curve keep those walks short, and the
random rounds keep the expected amount of flipping linear (Amenta, Choi & Rote's BRIO).
The seed is fixed, so the order, and therefore the output, is deterministic.
"""

from __future__ import annotations

import numpy as np

from ._kernel import hilbert_keys


def brio_order(xy: np.ndarray, seed: int = 20231121) -> np.ndarray:
    """Indices of `xy` in BRIO order: rounds of doubling size, Hilbert-sorted within."""
    n = len(xy)
    if n == 0:
        return np.zeros(0, dtype=np.int32)
    rng = np.random.default_rng(seed)
    # round k (k = 0 is the last, largest one) holds about n / 2**(k+1) points
    u = rng.random(n)
    rounds = np.minimum(np.floor(-np.log2(np.maximum(u, 1e-300))), 62).astype(np.int64)
    # one int64 key: the round in the high bits (later rounds first), the curve below
    keys = ((62 - rounds) << 32) | hilbert_keys(np.ascontiguousarray(xy, dtype=np.float64))
    return np.argsort(keys, kind="stable").astype(np.int32)
