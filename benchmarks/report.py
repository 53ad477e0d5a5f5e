"""Markdown tables from the collected results, and the README block."""

from __future__ import annotations

import re
from pathlib import Path

from .meshers import MESHERS, REFERENCE

START, END = "<!-- bench:start -->", "<!-- bench:end -->"


def _f(x, fmt="{:.3g}", none="-"):
    if x is None:
        return none
    return fmt.format(x)


def _t(sec):
    if sec is None:
        return "-"
    if sec < 0.01:
        return f"{sec * 1000:.2f} ms"
    if sec < 1:
        return f"{sec * 1000:.0f} ms"
    return f"{sec:.2f} s"


def _rate(r):
    if r is None:
        return "-"
    if r >= 1e6:
        return f"{r / 1e6:.2f} M"
    return f"{r / 1e3:.0f} k"


def _pct(x):
    return "-" if x is None else f"{100 * x:.2f} %"


def _esc(s: str) -> str:
    return s.replace("|", "/").replace("\n", " ")[:110]


def _label(m):
    return MESHERS.get(m, (m, ""))[0]


MESH_HEADER = (
    "| mesher | triangles | time (median) | CPU (median) | runs | tri/s | "
    "time / Tri pq30 | CPU / Tri pq30 | tri/s / Tri pq30 | peak mem (MiB) | seg + | "
    "min angle | max angle | "
    "RR mean | RR min | RR < 0.6 | RR > 0.9 | edge/size mean ± std |"
)


def _rule(header: str) -> str:
    return "|" + "|".join(["---"] * (header.count("|") - 1)) + "|"


def mesh_tables(mesh: dict) -> list[str]:
    out = []
    rows = mesh["rows"]
    seen = []
    for r in rows:
        if r["case"] not in seen:
            seen.append(r["case"])
    for cname in seen:
        meta = mesh["cases"].get(cname, {})
        out.append(f"#### {cname}")
        out.append("")
        desc = meta.get("description", "")
        if meta:
            desc += (
                f"; input {meta['vertices']} vertices, {meta['segments']} segments, "
                f"{meta['holes']} hole points"
            )
            if meta.get("notes"):
                desc += "; " + "; ".join(meta["notes"])
        out.append(desc)
        out.append("")
        out.append(MESH_HEADER)
        out.append(_rule(MESH_HEADER))
        area = meta.get("area")
        flags = []
        for r in rows:
            if r["case"] != cname:
                continue
            label = _label(r["mesher"])
            if r.get("skipped"):
                out.append(f"| {label} | {_esc(r['skipped'])} |" + " - |" * 16)
                continue
            if "median" not in r:
                out.append(f"| {label} | ERROR: {_esc(str(r.get('error')))} |" + " - |" * 16)
                continue
            s = r["stats"]
            seg_plus = s["segments_out"] - s["segments_in"]
            note = ""
            if r.get("passes"):
                note = f" ({r['passes']} passes)"
            if area and abs(s["area"] - area) > 1e-6 * area:
                flags.append(
                    f"{label}: meshed area {s['area']:.10g} differs from the domain's {area:.10g}"
                )
            if s["min_angle"] < 1e-3:
                flags.append(
                    f"{label}: degenerate triangle (min angle {s['min_angle']:.3g} deg, "
                    f"RR min {s['rr_min']:.3g})"
                )
            edge = "-"
            if "edge_ratio_mean" in s:
                edge = f"{s['edge_ratio_mean']:.3f} ± {s['edge_ratio_std']:.3f}"
            out.append(
                f"| {label} | {s['triangles']} | {_t(r['median'])}{note} | "
                f"{_t(r.get('cpu_median'))} | {len(r['times'])} | "
                f"{_rate(r['tri_per_s'])} | {_f(r.get('time_ratio'), '{:.2f}')} | "
                f"{_f(r.get('cpu_ratio'), '{:.2f}')} | {_f(r.get('rate_ratio'), '{:.2f}')} | "
                f"{r['mem_mib']:.1f} | {seg_plus:+d} | "
                f"{s['min_angle']:.2f} | {s['max_angle']:.2f} | {s['rr_mean']:.4f} | "
                f"{s['rr_min']:.3f} | {_pct(s['rr_below_0.6'])} | {_pct(s['rr_above_0.9'])} | "
                f"{edge} |"
            )
        out.append("")
        for fl in flags:
            out.append(f"- **check**: {fl}")
        if flags:
            out.append("")
    out += internal_table(mesh)
    return out


def internal_table(mesh: dict) -> list[str]:
    """aftmesh's own split of its time (median over the runs of Mesh.info['timing'])."""
    rows = [r for r in mesh["rows"] if r.get("internal_timing")]
    if not rows:
        return []
    hdr = (
        "| case | mesher | domain + size field + boundary | CDT | Basic_aft | "
        "arrays + markers + Mesh | total in generate | wall (median) |"
    )
    out = [
        "#### aftmesh: where the time goes",
        "",
        "Median of `Mesh.info['timing']` over the runs; the first column is everything "
        "before the CDT (input checks, the size field with its gradation limit, boundary "
        "splitting); 'arrays + markers + Mesh' is what follows Basic_aft (output arrays, "
        "segment markers, the Mesh object).",
        "",
        hdr,
        _rule(hdr),
    ]
    for r in rows:
        t = r["internal_timing"]
        parts = [t.get(k) for k in ("boundary", "cdt", "basic_aft", "after", "total")]
        out.append(
            f"| {r['case']} | {_label(r['mesher'])} | {_t(parts[0])} | "
            f"{_t(parts[1])} | {_t(parts[2])} | {_t(parts[3])} | {_t(parts[4])} | "
            f"{_t(r.get('median'))} |"
        )
    out.append("")
    return out


def cdt_tables(cdt: dict) -> list[str]:
    out = []
    hdr = (
        "| input | tool | triangles | time (median) | CPU (median) | runs | time / Triangle | "
        "CPU / Triangle |"
    )
    out += [hdr, _rule(hdr)]
    names = {"aft": "aftmesh.cdt", "tri": "triangle.triangulate", "scipy": "scipy Delaunay (Qhull)"}
    for r in cdt["rows"]:
        tool = names.get(r["tool"], r["tool"])
        if "median" not in r:
            out.append(
                f"| {r['input']} | {tool} | ERROR: {_esc(str(r.get('error')))} |" + " - |" * 5
            )
            continue
        extra = " (unconstrained)" if r["tool"] == "scipy" and r.get("n_segments") else ""
        out.append(
            f"| {r['input']} | {tool}{extra} | {r['triangles']} | {_t(r['median'])} | "
            f"{_t(r.get('cpu_median'))} | {len(r['times'])} | "
            f"{_f(r.get('time_ratio'), '{:.2f}')} | {_f(r.get('cpu_ratio'), '{:.2f}')} |"
        )
    out.append("")
    hdr = (
        "| 1e6 random points | triangles | time (one run) | peak mem delta (MiB) "
        "| bytes / triangle |"
    )
    out += [hdr, _rule(hdr)]
    for m in cdt.get("memory", []):
        tool = names.get(m["tool"], m["tool"])
        if "error" in m:
            out.append(f"| {tool} | ERROR: {_esc(m['error'])} | - | - | - |")
            continue
        out.append(
            f"| {tool} | {m['triangles']} | {_t(m['time'])} | {m['mem_mib']:.1f} | "
            f"{m['bytes_per_triangle']:.0f} |"
        )
    out.append("")
    return out


def scaling_tables(sc: dict) -> list[str]:
    out = []
    hdr = (
        "| h | mesher | triangles | time (median) | CPU (median) | runs | tri/s | "
        "peak mem (MiB) | bytes / triangle | CPU / aftmesh.cdt of own output | RR mean |"
    )
    out += [hdr, _rule(hdr)]
    for r in sc["rows"]:
        label = _label(r["mesher"])
        if "median" not in r:
            out.append(
                f"| {r['h']:g} | {label} | ERROR: {_esc(str(r.get('error')))} |" + " - |" * 8
            )
            continue
        n = r["triangles"]
        own = r.get("own_cdt_cpu_median")
        out.append(
            f"| {r['h']:g} | {label} | {n} | {_t(r['median'])} | "
            f"{_t(r.get('cpu_median'))} | {len(r['times'])} | "
            f"{_rate(n / r['median'])} | {r['mem_mib']:.1f} | "
            f"{r['mem_mib'] * 1048576 / n:.0f} | "
            f"{_f(r['cpu_median'] / own if own else None, '{:.2f}')} | "
            f"{_f(r.get('stats', {}).get('rr_mean'), '{:.5f}')} |"
        )
    out.append("")
    for m, fit in sc["fits"].items():
        out.append(
            f"- {_label(m)}: wall time ~ triangles^{_f(fit['all'], '{:.3f}')} over all "
            f"sizes, ^{_f(fit['from_1e5'], '{:.3f}')} from 1e5 triangles up; CPU time "
            f"^{_f(fit.get('cpu_all'), '{:.3f}')} and ^{_f(fit.get('cpu_from_1e5'), '{:.3f}')} "
            "(least squares, log-log)"
        )
    out.append("")
    return out


def _section_head(title: str, sec: dict) -> list[str]:
    m = sec.get("meta", {})
    mode = "quick" if m.get("quick") else "full"
    load = ""
    if m.get("load_start") is not None:
        load = f", load average {m['load_start']:.2f} at start, {m.get('load_end', 0):.2f} at end"
    return [
        f"### {title}",
        "",
        f"_{mode} run, {m.get('date', '?')}, {m.get('machine', '')}{load}_",
        "",
    ]


def full_report(results: dict) -> str:
    out = ["# aftmesh benchmarks", ""]
    meta = results.get("meta", {})
    if meta:
        out.append(
            f"Versions: {meta.get('versions', '')}.  "
            "Reference for the ratios: Triangle `pq30a<A>`, A = sqrt(3)/4 h^2, measured "
            "in the same run."
        )
        out.append("")
    if "mesh" in results:
        out += _section_head("Meshing", results["mesh"])
        out += mesh_tables(results["mesh"])
    if "cdt" in results:
        out += _section_head("Delaunay / constrained Delaunay triangulation", results["cdt"])
        out += cdt_tables(results["cdt"])
    if "scaling" in results:
        out += _section_head("Scaling on the unit square", results["scaling"])
        out += scaling_tables(results["scaling"])
    return "\n".join(out).rstrip() + "\n"


def summary(results: dict) -> str:
    """The compact table that goes into the top-level README."""
    out = []
    if "mesh" in results:
        mesh = results["mesh"]
        m = mesh.get("meta", {})
        load = ""
        if m.get("load_start") is not None:
            load = f", load average {m['load_start']:.1f}-{m.get('load_end', 0):.1f}"
        out.append(
            f"Meshing ({'quick' if m.get('quick') else 'full'} run, {m.get('date', '?')}, "
            f"{m.get('machine', '')}{load}); ratios against Triangle `pq30a` in the same "
            "run (CPU ratio: of process CPU time, less sensitive to a busy machine), "
            "RR = radius ratio 2 r_in / r_circ."
        )
        out.append("")
        hdr = (
            "| case | aftmesh triangles | aftmesh time | Triangle pq30a time | time ratio | "
            "CPU ratio | tri/s ratio | Gmsh alg 6 time | RR mean aft / Tri / Gmsh6 | "
            "min angle aft / Tri / Gmsh6 |"
        )
        out += [hdr, _rule(hdr)]
        by = {(r["case"], r["mesher"]): r for r in mesh["rows"]}
        for cname in dict.fromkeys(r["case"] for r in mesh["rows"]):
            a = by.get((cname, "aft"), {})
            t = by.get((cname, REFERENCE), {})
            g = by.get((cname, "gmsh-frontal"), {})

            def q(r, k, fmt):
                return fmt.format(r["stats"][k]) if "stats" in r and "median" in r else "-"

            out.append(
                f"| {cname} | {a.get('triangles', '-') if 'median' in a else 'error'} | "
                f"{_t(a.get('median'))} | {_t(t.get('median'))} | "
                f"{_f(a.get('time_ratio'), '{:.2f}')} | {_f(a.get('cpu_ratio'), '{:.2f}')} | "
                f"{_f(a.get('rate_ratio'), '{:.2f}')} | "
                f"{_t(g.get('median'))} | "
                f"{q(a, 'rr_mean', '{:.3f}')} / {q(t, 'rr_mean', '{:.3f}')} / "
                f"{q(g, 'rr_mean', '{:.3f}')} | "
                f"{q(a, 'min_angle', '{:.1f}')} / {q(t, 'min_angle', '{:.1f}')} / "
                f"{q(g, 'min_angle', '{:.1f}')} |"
            )
        out.append("")
    if "cdt" in results:
        out.append("Delaunay triangulation (median time; ratio to Triangle):")
        out.append("")
        out += cdt_tables(results["cdt"])
    if "scaling" in results:
        for mname, fit in results["scaling"]["fits"].items():
            out.append(
                f"- scaling, {_label(mname)}: time ~ triangles^"
                f"{_f(fit['from_1e5'], '{:.2f}')} (from 1e5 triangles up)"
            )
        out.append("")
    out.append("Full tables: `python -m benchmarks` (see benchmarks/README.md).")
    return "\n".join(out).rstrip() + "\n"


def update_readme(readme: Path, text: str, start: str = START, end: str = END) -> bool:
    """Replace the block between the markers; False (and nothing written) without them."""
    content = readme.read_text()
    if start not in content or end not in content or content.index(start) > content.index(end):
        return False
    pattern = re.compile(re.escape(start) + r".*?" + re.escape(end), re.S)
    new = pattern.sub(lambda _: f"{start}\n{text}{end}", content, count=1)
    readme.write_text(new)
    return True
