#!/usr/bin/env python3
"""Plots benchmark JSON lines as SVG, with no dependency beyond the Python standard library
(so the plots come out wherever the benchmarks ran).

  plot_results.py RESULTS.jsonl [--out-dir DIR]
      every known plot that RESULTS has data for: time against size on log-log axes for the
      RBF scaling family, the compact-vs-dense RBF peer, the 3D bump levels and the
      compact-vs-direct evaluation; one SVG per plot. And one quality histogram per mesh of
      the curving bench (rows with a "histogram" field): the certified scaled Jacobian's
      counts per bin on [0, 1], a bar per method, log counts, the invalid cells as a separate
      bar at the left; named curving_hist_<mesh>.svg.
  plot_results.py RESULTS.jsonl --x FIELD --y FIELD[,FIELD...] [--where KEY=VALUE ...]
                  [--group FIELD] [--linear] [--title TEXT] --out FILE.svg
      one plot of the rows matching every --where, a line per --y field (or per value of
      --group), log-log unless --linear.

RESULTS is what benchmarks/run_all.sh writes (or any file with one JSON object per line;
other lines are ignored).
"""
import argparse
import json
import math
import os
import re
import sys

COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f",
           "#bcbd22"]


def read_rows(path, baseline=False):
    """The JSON rows of a results file; run_all.sh --baseline's older-build rows only if asked."""
    rows = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if line.startswith("{"):
                try:
                    row = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a table line that happens to start with a brace
                if baseline or row.get("build") != "baseline":
                    rows.append(row)
    return rows


def matches(row, where):
    return all(str(row.get(k)) == v for k, v in where)


def series_from(rows, x, ys, group):
    """{label: [(x, y), ...]} with non-positive or missing values dropped (log axes)."""
    series = {}
    for row in rows:
        if not isinstance(row.get(x), (int, float)):
            continue
        for y in ys:
            value = row.get(y)
            if not isinstance(value, (int, float)) or value <= 0:
                continue
            label = str(row.get(group)) if group else y
            series.setdefault(label, []).append((float(row[x]), float(value)))
    for points in series.values():
        points.sort()
    return series


def svg_plot(series, title, x_label, y_label, log=True, width=760, height=420):
    """The SVG text of a line plot with markers; axes log10 when `log`."""
    left, right, top, bottom = 70, 250, 40, 55
    pw, ph = width - left - right, height - top - bottom
    xs = [p[0] for pts in series.values() for p in pts]
    ys = [p[1] for pts in series.values() for p in pts]
    tx = (lambda v: math.log10(v)) if log else (lambda v: v)
    x0, x1 = tx(min(xs)), tx(max(xs))
    y0, y1 = tx(min(ys)), tx(max(ys))
    if log:
        x0, x1, y0, y1 = math.floor(x0), math.ceil(x1), math.floor(y0), math.ceil(y1)
    if x1 == x0:
        x1 = x0 + 1
    if y1 == y0:
        y1 = y0 + 1
    px = lambda v: left + (tx(v) - x0) / (x1 - x0) * pw
    py = lambda v: top + ph - (tx(v) - y0) / (y1 - y0) * ph
    esc = lambda s: s.replace("&", "&amp;").replace("<", "&lt;")
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">',
           '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="{left}" y="22" font-size="14">{esc(title)}</text>',
           f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="black"/>']

    def ticks(lo, hi):
        if log:
            return [10.0 ** k for k in range(int(lo), int(hi) + 1)]
        step = 10 ** math.floor(math.log10((hi - lo) / 4 or 1))
        return [lo + k * step for k in range(int((hi - lo) / step) + 1)]

    for v in ticks(x0, x1):
        x = px(v)
        out.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{top + ph}" stroke="#ddd"/>')
        out.append(f'<text x="{x:.1f}" y="{top + ph + 16}" text-anchor="middle">{v:g}</text>')
    for v in ticks(y0, y1):
        y = py(v)
        out.append(f'<line x1="{left}" y1="{y:.1f}" x2="{left + pw}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{v:g}</text>')
    out.append(f'<text x="{left + pw / 2}" y="{height - 12}" text-anchor="middle">{esc(x_label)}</text>')
    out.append(f'<text transform="translate(16 {top + ph / 2}) rotate(-90)" text-anchor="middle">{esc(y_label)}</text>')
    for k, (label, pts) in enumerate(sorted(series.items())):
        colour = COLOURS[k % len(COLOURS)]
        path = " ".join(f"{'M' if i == 0 else 'L'}{px(x):.1f} {py(y):.1f}" for i, (x, y) in enumerate(pts))
        out.append(f'<path d="{path}" fill="none" stroke="{colour}" stroke-width="1.8"/>')
        for x, y in pts:
            out.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3" fill="{colour}"/>')
        ly = top + 14 + 18 * k
        out.append(f'<line x1="{left + pw + 10}" y1="{ly - 4}" x2="{left + pw + 28}" y2="{ly - 4}" stroke="{colour}" stroke-width="2"/>')
        out.append(f'<text x="{left + pw + 32}" y="{ly}">{esc(label)}</text>')
    out.append("</svg>\n")
    return "\n".join(out)


def histogram_groups(rows):
    """{mesh: [(method label, invalid, [count per bin]), ...]} from the curving bench's rows, in
    the order they were printed. The 30P30N table names the mesh "mesh" and the method "case";
    the Gmsh comparison names the mesh "case" and the method "tool" + "method"."""
    groups = {}
    for row in rows:
        counts = row.get("histogram")
        if not isinstance(counts, list) or not counts or not isinstance(row.get("invalid"), int):
            continue  # a failed run has no histogram
        if row.get("bench") == "curving":
            mesh, label = "30p30n_" + str(row.get("mesh")), str(row.get("case"))
            if row.get("steps", 1) != 1:
                label += f", {row['steps']} steps"
        elif row.get("bench") == "curving_vs_gmsh":
            mesh, label = str(row.get("case")), f"{row.get('tool')}: {row.get('method')}"
        else:
            continue
        groups.setdefault(mesh, []).append((label, row["invalid"], counts))
    return groups


def svg_histogram(series, title, plot_width=700, height=460):
    """The SVG text of grouped bars: for each method the invalid count, then the count per
    equal bin on [0, 1]; log10 counts (a count of 1 still shows a bar, 0 shows none)."""
    bins = max(len(counts) for _, _, counts in series)
    legend = [f"{label} ({invalid} invalid)" for label, invalid, _ in series]
    left, top, bottom = 70, 40, 60
    right = 50 + 7 * max(len(text) for text in legend)  # legend labels are long ("gmsh: elastic (HOO=3) nl=40")
    width, pw = left + plot_width + right, plot_width
    height = max(height, top + 18 * len(series) + 20)
    ph = height - top - bottom
    groups = bins + 1  # the invalid bar first
    gap = 0.6  # extra space (in groups) between the invalid group and the bins
    group_w = pw / (groups + gap)
    bar_w = group_w * 0.85 / len(series)
    largest = max([inv for _, inv, _ in series] + [c for _, _, counts in series for c in counts] + [1])
    y0, y1 = math.log10(0.5), math.ceil(math.log10(largest) + 1e-9)
    py = lambda v: top + ph - (math.log10(v) - y0) / (y1 - y0) * ph
    esc = lambda s: s.replace("&", "&amp;").replace("<", "&lt;")
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">',
           '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="{left}" y="22" font-size="14">{esc(title)}</text>']
    for k in range(0, int(y1) + 1):
        y = py(10.0 ** k)
        out.append(f'<line x1="{left}" y1="{y:.1f}" x2="{left + pw}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{10 ** k:g}</text>')

    def group_x(g):  # left edge of group g (0: invalid)
        return left + (g + (gap if g > 0 else 0.0)) * group_w + group_w * 0.075

    for g in range(groups):
        label = "invalid" if g == 0 else f"{(g - 1) / bins:g}–{g / bins:g}"
        fill = "#c00" if g == 0 else "black"
        out.append(f'<text x="{group_x(g) + group_w * 0.425:.1f}" y="{top + ph + 16}" text-anchor="middle"'
                   f' font-size="10" fill="{fill}">{label}</text>')
    sep = left + (1 + gap / 2) * group_w
    out.append(f'<line x1="{sep:.1f}" y1="{top}" x2="{sep:.1f}" y2="{top + ph}" stroke="#888" stroke-dasharray="4 3"/>')
    for k, (label, invalid, counts) in enumerate(series):
        colour = COLOURS[k % len(COLOURS)]
        for g, count in enumerate([invalid] + list(counts)):
            if count > 0:
                x, y = group_x(g) + k * bar_w, py(count)
                out.append(f'<rect x="{x:.1f}" y="{y:.1f}" width="{bar_w:.1f}" height="{top + ph - y:.1f}" fill="{colour}">'
                           f'<title>{esc(label)}: {count}</title></rect>')
        ly = top + 14 + 18 * k
        out.append(f'<rect x="{left + pw + 12}" y="{ly - 10}" width="14" height="10" fill="{colour}"/>')
        out.append(f'<text x="{left + pw + 32}" y="{ly}">{esc(legend[k])}</text>')
    out.append(f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="black"/>')
    out.append(f'<text x="{left + pw / 2}" y="{height - 14}" text-anchor="middle">'
               'certified scaled Jacobian (min det J / det J of the straight element)</text>')
    out.append(f'<text transform="translate(16 {top + ph / 2}) rotate(-90)" text-anchor="middle">cells (log scale)</text>')
    out.append("</svg>\n")
    return "\n".join(out)


def write(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)  # never a half-written picture
    print(f"wrote {path}")


# Known plots: (file name, title, where, x, ys, group, x label, y label)
KNOWN = [
    ("rbf_scaling.svg", "RBF (Wendland C2, k-d tree): 3D box family", [("case", "scaling")], "nodes",
     ["setup_seconds", "move_seconds", "direct_seconds"], None, "nodes", "seconds"),
    ("dense_rbf_peer_box.svg", "Compact vs dense RBF, 3D box bump", [("case_family", "box")], "nodes", ["seconds"],
     "method", "nodes", "seconds"),
    ("dense_rbf_peer_ellipse.svg", "Compact vs dense RBF, rotating ellipse 60°", [("case_family", "ellipse")], "nodes",
     ["seconds"], "method", "nodes", "seconds"),
    ("bump3d_levels.svg", "Curving the 3D bump (thesis table 4.3)", [("bench", "bump3d")], "points",
     ["total_seconds", "thesis_seconds"], None, "points of the P2 mesh", "seconds"),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results")
    parser.add_argument("--out-dir", default=None)
    parser.add_argument("--x")
    parser.add_argument("--y")
    parser.add_argument("--where", action="append", default=[])
    parser.add_argument("--group")
    parser.add_argument("--linear", action="store_true")
    parser.add_argument("--title", default="")
    parser.add_argument("--out")
    args = parser.parse_args()
    rows = read_rows(args.results)
    for row in rows:  # "ellipse128_rot60" -> family "ellipse", to group peer rows by case
        if isinstance(row.get("case"), str):
            row.setdefault("case_family", re.match(r"[A-Za-z]*", row["case"]).group(0))
    if args.x or args.y:
        if not (args.x and args.y and args.out):
            parser.error("--x, --y and --out go together")
        where = [tuple(w.split("=", 1)) for w in args.where]
        series = series_from([r for r in rows if matches(r, where)], args.x, args.y.split(","), args.group)
        if not series:
            sys.exit(f"plot_results: no row of {args.results} has positive {args.y} against {args.x}")
        write(args.out, svg_plot(series, args.title or args.y, args.x, args.y, log=not args.linear))
        return
    out_dir = args.out_dir or os.path.dirname(os.path.abspath(args.results))
    os.makedirs(out_dir, exist_ok=True)
    made = 0
    for name, title, where, x, ys, group, x_label, y_label in KNOWN:
        series = series_from([r for r in rows if matches(r, where)], x, ys, group)
        if sum(len(p) for p in series.values()) >= 2:
            write(os.path.join(out_dir, name), svg_plot(series, title, x_label, y_label))
            made += 1
    for mesh, series in histogram_groups(rows).items():
        name = "curving_hist_" + re.sub(r"[^A-Za-z0-9_.-]", "_", mesh) + ".svg"
        title = f"Certified scaled Jacobian of the P2 mesh: {mesh}"
        write(os.path.join(out_dir, name), svg_histogram(series, title))
        made += 1
    if made == 0:
        print(f"plot_results: nothing to plot in {args.results} (no known benchmark series)")


if __name__ == "__main__":
    main()
