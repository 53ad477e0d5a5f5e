"""Memory and quality measurements, the same code for every mesher."""

from __future__ import annotations

import gc
import resource

import numpy as np

__all__ = ["MemoryProbe", "quality_stats", "HIST_BINS"]

HIST_BINS = 50


def _status_kib(key: str) -> int | None:
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


class MemoryProbe:
    """Peak resident memory of one call, in this process.

    Linux: the high-water mark VmHWM is reset by writing 5 to /proc/self/clear_refs,
    the baseline is VmRSS right after, the figure is VmHWM after the call minus that
    baseline.  Where the reset is refused the baseline is the VmHWM already reached
    (so the figure is 0 unless the call went higher than importing and building the
    input did); without /proc, ru_maxrss is used the same way."""

    def __init__(self):
        self.method = None
        self.base_kib = None

    def start(self) -> None:
        gc.collect()
        try:
            with open("/proc/self/clear_refs", "w") as f:
                f.write("5")
            self.base_kib = _status_kib("VmRSS")
            self.method = "VmHWM reset"
        except OSError:
            hwm = _status_kib("VmHWM")
            if hwm is not None:
                self.base_kib, self.method = hwm, "VmHWM"
            else:
                self.base_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                self.method = "ru_maxrss"

    def stop_mib(self) -> float:
        if self.method == "ru_maxrss":
            peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        else:
            peak = _status_kib("VmHWM")
        return max(0, peak - self.base_kib) / 1024.0


def unique_edges(tris: np.ndarray, n_points: int) -> np.ndarray:
    """Each edge of the triangles once, as (e, 2) sorted vertex pairs."""
    e = np.concatenate([tris[:, [1, 2]], tris[:, [2, 0]], tris[:, [0, 1]]]).astype(np.int64)
    lo = e.min(axis=1)
    hi = e.max(axis=1)
    key = np.unique(lo * n_points + hi)
    return np.column_stack([key // n_points, key % n_points])


def quality_stats(points: np.ndarray, tris: np.ndarray, target=None) -> dict:
    """Shape statistics of a triangulation (``target(x, y)``: the wanted edge length)."""
    from aftmesh.mesh import triangle_quality

    points = np.asarray(points, dtype=np.float64)
    tris = np.asarray(tris, dtype=np.int64)
    if len(tris) == 0:
        return {"triangles": 0}
    q = triangle_quality(points, tris)
    rr = q["radius_ratio"]
    out = {
        "triangles": int(len(tris)),
        "points": int(len(np.unique(tris))),
        "area": float(np.abs(q["area"]).sum()),
        "min_angle": float(q["min_angle"].min()),
        "max_angle": float(q["max_angle"].max()),
        "rr_mean": float(rr.mean()),
        "rr_min": float(rr.min()),
        "rr_below_0.6": float((rr < 0.6).mean()),
        "rr_above_0.9": float((rr > 0.9).mean()),
        "rr_hist": np.histogram(rr, bins=HIST_BINS, range=(0.0, 1.0))[0].tolist(),
    }
    del q
    if target is not None:
        e = unique_edges(tris, len(points))
        a, b = points[e[:, 0]], points[e[:, 1]]
        length = np.hypot(*(b - a).T)
        mid = 0.5 * (a + b)
        ratio = length / target(mid[:, 0], mid[:, 1])
        out["edge_ratio_mean"] = float(ratio.mean())
        out["edge_ratio_std"] = float(ratio.std())
    return out
