"""Insertion order for bulk point insertion: biased randomized insertion order (BRIO)
with a Hilbert curve order inside each round.

Incremental Delaunay insertion walks from the last inserted triangle to the next point;
consecutive points that are close on a Hilbert curve keep those walks short, and the
random rounds keep the expected amount of flipping linear (Amenta, Choi & Rote's BRIO).
The seed is fixed, so the order, and therefore the output, is deterministic.
"""

from __future__ import annotations

import numpy as np

from ._kernel import brio_keys_order

# The default seed of the random rounds.
SEED = 20231121
# The round keys of the first this many points under SEED are kept after the first
# call: drawing them costs more than the rest of ordering a small input.
CACHED_ROUNDS = 4096
_cached_rounds: np.ndarray | None = None


def round_keys(n: int, seed: int = SEED) -> np.ndarray:
    """The BRIO round keys of n points (the high bits of brio_order's keys), for the
    kernel's own BRIO insertions (background_field)."""
    return _round_keys(n, seed)


def _round_keys(n: int, seed: int) -> np.ndarray:
    """The high bits of each point's key: its BRIO round, later rounds first.  A
    generator's first n draws do not depend on how many more are drawn after them,
    so the cached keys of the default seed are a prefix of any longer draw."""
    global _cached_rounds
    if seed == SEED and n <= CACHED_ROUNDS:
        if _cached_rounds is None:  # two threads may both draw it: the same keys
            keys = _draw_round_keys(CACHED_ROUNDS, seed)
            keys.setflags(write=False)
            _cached_rounds = keys
        return _cached_rounds[:n]
    return _draw_round_keys(n, seed)


def _draw_round_keys(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    # round k (k = 0 is the last, largest one) holds about n / 2**(k+1) points
    u = rng.random(n)
    rounds = np.minimum(np.floor(-np.log2(np.maximum(u, 1e-300))), 62).astype(np.int64)
    # one int64 key: the round in the high bits (later rounds first), the curve below
    return (62 - rounds) << 32


def brio_order(xy: np.ndarray, seed: int = SEED) -> np.ndarray:
    """Indices of `xy` in BRIO order: rounds of doubling size, Hilbert-sorted within."""
    n = len(xy)
    if n == 0:
        return np.zeros(0, dtype=np.int32)
    # the Hilbert keys and their stable sort in one compiled call
    return brio_keys_order(np.ascontiguousarray(xy, dtype=np.float64), _round_keys(n, seed))
