"""PNG figures: radius-ratio histograms and the scaling plot."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .measure import HIST_BINS
from .meshers import MESHERS


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _hist_axes(ax, rows, title):
    edges = np.linspace(0.0, 1.0, HIST_BINS + 1)
    for r in rows:
        counts = np.asarray(r["stats"]["rr_hist"], dtype=float)
        if counts.sum() == 0:
            continue
        ax.stairs(counts / counts.sum(), edges, label=MESHERS.get(r["mesher"], (r["mesher"],))[0])
    ax.set_yscale("log")
    ax.set_xlabel("radius ratio 2 r_in / r_circ")
    ax.set_ylabel("fraction of triangles")
    ax.set_title(title)
    ax.legend(fontsize=7)


def mesh_histograms(mesh: dict, out: Path) -> list[Path]:
    plt = _plt()
    written = []
    for stale in out.glob("hist_*.png"):
        stale.unlink()
    for cname in dict.fromkeys(r["case"] for r in mesh["rows"]):
        rows = [
            r
            for r in mesh["rows"]
            if r["case"] == cname and "stats" in r and r["mesher"] not in ("aft-greedy", "tri-p")
        ]
        if not rows:
            continue
        fig, ax = plt.subplots(figsize=(6, 4))
        _hist_axes(ax, rows, f"{cname}: radius ratio")
        fig.tight_layout()
        path = out / f"hist_{cname}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


def scaling_plots(sc: dict, out: Path) -> list[Path]:
    plt = _plt()
    written = []
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for mname, fit in sc["fits"].items():
        ok = [r for r in sc["rows"] if r["mesher"] == mname and r.get("median")]
        if not ok:
            continue
        n = np.array([r["triangles"] for r in ok], dtype=float)
        t = np.array([r["median"] for r in ok])
        label = MESHERS.get(mname, (mname,))[0]
        (line,) = ax.loglog(
            n,
            t,
            "o-",
            label=f"{label} (slope {fit['all']:.2f})" if fit["all"] is not None else label,
        )
        if len(n) >= 2:
            k, c = np.polyfit(np.log(n), np.log(t), 1)
            ax.loglog(n, np.exp(c) * n**k, "--", color=line.get_color(), lw=0.8)
    ax.set_xlabel("triangles")
    ax.set_ylabel("wall time (s), median")
    ax.set_title("unit square, uniform size")
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    fig.tight_layout()
    path = out / "scaling.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    written.append(path)

    # radius-ratio histograms at the finest size both meshers reached
    by_h = {}
    for r in sc["rows"]:
        if "stats" in r:
            by_h.setdefault(r["h"], []).append(r)
    common = [h for h, rs in by_h.items() if len(rs) == len(sc["fits"])]
    if common:
        h = min(common)
        fig, ax = plt.subplots(figsize=(6, 4))
        _hist_axes(ax, by_h[h], f"unit square h = {h:g}: radius ratio")
        fig.tight_layout()
        path = out / "scaling_hist.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written
