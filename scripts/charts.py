#!/usr/bin/python3
"""Charts of kmbvh's results from the JSON its commands print (Debian's python3-matplotlib).

  scripts/charts.py stress STRESS.json OUT_DIR   # "where methods fail": cases x builders
  scripts/charts.py presets BENCH.json OUT_DIR   # k-means presets: build time against SAH cost
  scripts/charts.py table BENCH.json OUT.md      # the adaptive preset against the best fixed one
  scripts/charts.py scaling BENCH.json OUT_DIR   # build time and memory against triangles, log-log

Each chart is written as PNG and SVG. STRESS.json is `kmbvh stress --json`; BENCH.json is
`kmbvh bench --json` with the k-means presets among its builders.
"""
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, out_dir, name):
    out_dir.mkdir(parents=True, exist_ok=True)
    for ext in ("png", "svg"):
        fig.savefig(out_dir / f"{name}.{ext}", dpi=120, bbox_inches="tight")
    plt.close(fig)


def ordered(values):
    seen = []
    for v in values:
        if v not in seen:
            seen.append(v)
    return seen


def stress_chart(rows, out_dir):
    """Cases down, builders across: a cell's colour is its SAH cost over sweep SAH's (green
    at or below 1, red from 2.5), dark red where the builder failed; the text gives the
    ratio (or the failure) and the tree's depth."""
    cases = ordered(r["case"] for r in rows)
    builders = ordered(r["builder"] for r in rows)
    cell = {(r["case"], r["builder"]): r for r in rows}
    failed = 3.2
    grid = []
    for c in cases:
        line = []
        for b in builders:
            r = cell[(c, b)]
            line.append(failed if r["outcome"] != "ok" else (r["sah_over_sweep"] or 1.0))
        grid.append(line)
    fig, ax = plt.subplots(figsize=(1.0 + 0.8 * len(builders), 0.9 + 0.5 * len(cases)))
    colours = matplotlib.colormaps["RdYlGn_r"].copy()
    colours.set_over("#7b241c")
    ax.imshow(grid, cmap=colours, vmin=0.8, vmax=2.5 + 1e-6, aspect="auto")
    for y, c in enumerate(cases):
        for x, b in enumerate(builders):
            r = cell[(c, b)]
            if r["outcome"] != "ok":
                text = r["outcome"]
            elif r["sah_over_sweep"] > 0:
                text = f"{r['sah_over_sweep']:.2f}\nd{r['max_depth']}"
            else:
                text = f"ok\nd{r['max_depth']}"
            ax.text(x, y, text, ha="center", va="center", fontsize=6.5,
                    color="white" if r["outcome"] != "ok" else "black")
    ax.set_xticks(range(len(builders)), [b.replace("kmeans ", "") for b in builders], rotation=45, ha="right")
    ax.set_yticks(range(len(cases)), [f"{c} ({cell[(c, builders[0])]['triangles']:,})" for c in cases])
    ax.set_title("Where methods fail: SAH cost over sweep SAH and tree depth (d) per case, or the failure")
    save(fig, out_dir, "stress")


def presets_chart(rows, out_dir):
    scenes = ordered(r["scene"] for r in rows)
    cols = min(4, len(scenes))
    lines = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(lines, cols, figsize=(3.4 * cols, 3.0 * lines), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        for r in (r for r in rows if r["scene"] == scene):
            name = r["builder"].replace("kmeans ", "")
            adaptive = name == "QA"
            ax.scatter(r["build_ms"], r["sah_cost"], color="#c0392b" if adaptive else "#2e86c1",
                       marker="*" if adaptive else "o", s=90 if adaptive else 30, zorder=3)
            ax.annotate(name, (r["build_ms"], r["sah_cost"]), fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_title(scene.rsplit(".", 1)[0], fontsize=9)
        ax.set_xlabel("build ms (log)", fontsize=8)
        ax.set_ylabel("SAH cost", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    fig.suptitle("k-means presets: build time against SAH cost (lower left is better); QA is the adaptive preset")
    fig.tight_layout()
    save(fig, out_dir, "presets")


def presets_table(rows, out_path):
    """Per scene: the fixed preset of lowest SAH cost against QA, with QA's ratios."""
    lines = ["| scene | triangles | best fixed | its SAH | its ms | QA SAH | ratio | QA ms | ratio | QA B/tri |",
             "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    met = 0
    scenes = ordered(r["scene"] for r in rows)
    for scene in scenes:
        mine = {r["builder"].replace("kmeans ", ""): r for r in rows if r["scene"] == scene}
        if "QA" not in mine:
            continue
        qa = mine["QA"]
        fixed = [(r["sah_cost"], name) for name, r in mine.items() if name != "QA"]
        if not fixed:
            continue
        best = mine[min(fixed)[1]]
        sah_ratio = qa["sah_cost"] / best["sah_cost"]
        ms_ratio = qa["build_ms"] / best["build_ms"]
        met += sah_ratio <= 1.02 and ms_ratio < 1.0
        lines.append(f"| {scene.rsplit('.', 1)[0]} | {qa['triangles']:,} | {min(fixed)[1]} | {best['sah_cost']:.1f} | "
                     f"{best['build_ms']:.1f} | {qa['sah_cost']:.1f} | {sah_ratio:.3f} | {qa['build_ms']:.1f} | "
                     f"{ms_ratio:.2f} | {qa['build_bytes_per_triangle']:.0f} |")
    lines.append("")
    lines.append(f"QA within 2% of the best fixed preset's SAH cost at a lower build time on {met} of {len(scenes)} scenes.")
    Path(out_path).write_text("\n".join(lines) + "\n")


def scaling_chart(rows, out_dir):
    """Build time and peak memory per triangle against triangle count, one line per builder,
    log-log, with n log n through each builder's smallest scene for reference; and a table
    (scaling.md) of each builder's time over n log2 n, relative to its smallest scene."""
    builders = ordered(r["builder"] for r in rows)
    fig, (time_ax, memory_ax) = plt.subplots(1, 2, figsize=(12, 4.5))
    lines = ["| builder | " + " | ".join(f"{n:,}" for n in sorted({r['triangles'] for r in rows})) +
             " | time / (n log n), largest over smallest |",
             "|---|" + "---:|" * (len({r['triangles'] for r in rows}) + 1)]
    for b in builders:
        mine = sorted((r for r in rows if r["builder"] == b), key=lambda r: r["triangles"])
        n = [r["triangles"] for r in mine]
        ms = [r["build_ms"] for r in mine]
        (line,) = time_ax.plot(n, ms, marker="o", label=b.replace("kmeans ", ""))
        memory_ax.plot(n, [r["build_bytes_per_triangle"] for r in mine], marker="o", color=line.get_color(),
                       label=b.replace("kmeans ", ""))
        per = [t / (k * math.log2(k)) for t, k in zip(ms, n)]
        growth = per[-1] / per[0] if per and per[0] > 0 else float("nan")
        by_n = {r["triangles"]: r["build_ms"] for r in mine}
        cells = " | ".join(f"{by_n[k]:.0f}" if k in by_n else "" for k in sorted({r['triangles'] for r in rows}))
        lines.append(f"| {b} | {cells} | {growth:.2f} |")
    n_all = sorted({r["triangles"] for r in rows})
    time_ax.set(xscale="log", yscale="log", xlabel="triangles", ylabel="build ms (median)",
                title="Build time against scene size")
    memory_ax.set(xscale="log", xlabel="triangles", ylabel="peak bytes per triangle beyond the input",
                  title="Build memory per triangle")
    memory_ax.axhline(100, color="grey", linestyle="--", linewidth=1)
    for ax in (time_ax, memory_ax):
        ax.grid(True, which="both", alpha=0.3)
    time_ax.legend(fontsize=8)
    if len(n_all) > 1:  # n log n, scaled to pass through the median builder's smallest time
        smallest = sorted(r["build_ms"] for r in rows if r["triangles"] == n_all[0])
        t0 = smallest[len(smallest) // 2]
        time_ax.plot(n_all, [t0 * k * math.log2(k) / (n_all[0] * math.log2(n_all[0])) for k in n_all],
                     color="grey", linestyle="--", linewidth=1, label="n log n")
        time_ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, out_dir, "scaling")
    lines.append("")
    lines.append("Time over n log2 n at the largest scene divided by the same at the smallest: "
                 "1 or less means growing no faster than n log n.")
    (Path(out_dir) / "scaling.md").write_text("\n".join(lines) + "\n")


def main(argv):
    if len(argv) != 4 or argv[1] not in ("stress", "presets", "table", "scaling"):
        sys.exit(__doc__)
    path = Path(argv[2])
    try:
        rows = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        sys.exit(f"charts.py: {path}: {e}")
    if not rows:
        sys.exit(f"charts.py: {path}: no rows")
    charts = {"stress": stress_chart, "presets": presets_chart, "table": presets_table, "scaling": scaling_chart}
    charts[argv[1]](rows, Path(argv[3]))


if __name__ == "__main__":
    main(sys.argv)
