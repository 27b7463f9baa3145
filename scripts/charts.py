#!/usr/bin/python3
"""Charts of kmbvh's results from the JSON its commands print (Debian's python3-matplotlib).

  scripts/charts.py stress STRESS.json OUT_DIR       # "where methods fail": cases x builders
  scripts/charts.py presets BENCH.json OUT_DIR       # k-means presets: build time against SAH cost
  scripts/charts.py table BENCH.json OUT.md          # the adaptive preset against the best fixed one
  scripts/charts.py scaling BENCH.json OUT_DIR       # build time and memory against triangles, log-log
  scripts/charts.py pareto SUITE.json OUT_DIR        # build time against SAH cost, every builder, the Pareto front
  scripts/charts.py speed SUITE.json OUT_DIR         # build time against the path tracer's Mrays/s
  scripts/charts.py tti SUITE.json OUT_DIR           # time to image LQ and HQ over sweep SAH's, bars per scene
  scripts/charts.py targets SUITE.json OUT.md        # the issue's targets, met or not, per scene
  scripts/charts.py paper SUITE.json OUT.md          # the paper's figures beside ours
  scripts/charts.py projection HQ.json OUT.md        # HQ rendered against HQ projected from LQ
  scripts/charts.py iterations ITERS.json OUT_DIR    # SAH cost against Lloyd iterations for each k
  scripts/charts.py phases PHASES.json OUT_DIR       # k-means build time by phase, per preset
  scripts/charts.py beyond BENCH.json OUT_DIR        # k-means beyond the paper against Embree: the Pareto front
  scripts/charts.py beyond_table BENCH.json OUT.md   # its targets per scene: on the front, dominating embree-medium
  scripts/charts.py all DIR                          # every chart whose JSON is in DIR (results.sh's names)

Each chart is written as PNG and SVG. STRESS.json is `kmbvh stress --json`; BENCH.json is
`kmbvh bench --json` with the k-means presets among its builders; SUITE.json is `kmbvh bench
--suite paper --json`; ITERS.json `kmbvh bench --suite iterations --json`; PHASES.json
`kmbvh bench --builders Q1,...,QA --level-loop --json`.
"""
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402


def log_x(ax):
    """A log axis labelled with plain numbers (a short range otherwise gets 2x10^0-style labels)."""
    ax.set_xscale("log")
    plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
    ax.xaxis.set_major_formatter(plain)
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def panel(ax, title, xlabel, ylabel, log_build_ms=False):
    """One scene's panel: its title, axis labels and grid, and build time on a log axis."""
    if log_build_ms:
        log_x(ax)
    ax.set_title(title.rsplit(".", 1)[0], fontsize=9)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="both", alpha=0.3)


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
    fig, axes = scene_grid(scenes, width=3.4, height=3.0)
    for ax, scene in zip(axes, scenes):
        for r in (r for r in rows if r["scene"] == scene):
            name = r["builder"].replace("kmeans ", "")
            adaptive = name == "QA"
            ax.scatter(r["build_ms"], r["sah_cost"], color="#c0392b" if adaptive else "#2e86c1",
                       marker="*" if adaptive else "o", s=90 if adaptive else 30, zorder=3)
            ax.annotate(name, (r["build_ms"], r["sah_cost"]), fontsize=7, xytext=(3, 3), textcoords="offset points")
        panel(ax, scene, "build ms (log)", "SAH cost", log_build_ms=True)
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


def short(builder):
    return builder.replace("kmeans ", "").replace("embree scene", "Embree e2e")


def scene_grid(scenes, width=3.6, height=3.1, cols=4):
    cols = min(cols, len(scenes))
    lines = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(lines, cols, figsize=(width * cols, height * lines), squeeze=False)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    return fig, list(axes.flat)[:len(scenes)]


def colour(row):
    name = row["builder_name"]
    if name == "kmeans":
        return "#c0392b"
    if name.startswith("embree"):
        return "#7d3c98"
    return "#2e86c1"


def pareto_front(points):
    """The points no other point beats on both axes (lower is better on both)."""
    front = []
    for i, (x, y) in enumerate(points):
        dominated = any((x2 <= x and y2 <= y) and (x2 < x or y2 < y) for j, (x2, y2) in enumerate(points) if j != i)
        if not dominated:
            front.append(i)
    return front


def kmeans_on_front(rows):
    """The k-means builders of `rows` (one scene's) on the Pareto front of build time and SAH
    cost, among the rows that have a cost."""
    costed = [r for r in rows if r["sah_cost"] is not None]
    front = [costed[i] for i in pareto_front([(r["build_ms"], r["sah_cost"]) for r in costed])]
    return [short(r["builder"]) for r in front if r["builder_name"] == "kmeans"]


def pareto_chart(rows, out_dir, name="pareto", title="Speed against quality: build time and SAH cost"):
    """Per scene: build time (log) against SAH cost for every builder (Embree end to end has no
    tree to cost), k-means red, the references blue, Embree's builders purple; the Pareto
    front joined by a line."""
    scenes = ordered(r["scene"] for r in rows)
    fig, axes = scene_grid(scenes)
    for ax, scene in zip(axes, scenes):
        mine = [r for r in rows if r["scene"] == scene and r["sah_cost"] is not None]
        points = [(r["build_ms"], r["sah_cost"]) for r in mine]
        for r in mine:
            ax.scatter(r["build_ms"], r["sah_cost"], color=colour(r), s=26, zorder=3)
            ax.annotate(short(r["builder"]), (r["build_ms"], r["sah_cost"]), fontsize=6.5, xytext=(3, 2),
                        textcoords="offset points")
        front = sorted((points[i] for i in pareto_front(points)))
        ax.plot([p[0] for p in front], [p[1] for p in front], color="grey", linestyle="--", linewidth=1, zorder=2)
        panel(ax, scene, "build ms (log)", "SAH cost", log_build_ms=True)
    fig.suptitle(f"{title} (lower left is better; dashed: the Pareto front; red k-means, blue references, "
                 "purple Embree)", fontsize=10)
    fig.tight_layout()
    save(fig, out_dir, name)


def beyond_chart(rows, out_dir):
    pareto_chart(rows, out_dir, "beyond", "k-means beyond the paper against Embree's builders")


def beyond_table(rows, out_path):
    """Per scene (#16's targets): the k-means configurations on the Pareto front of build time
    and SAH cost, those that dominate embree-medium (less time, SAH no higher), and the
    cheapest k-means tree built in no more than embree-medium's time."""
    lines = ["| scene | k-means on the Pareto front | dominating embree-medium | embree-medium ms, SAH | "
             "cheapest k-means within its time: SAH ratio |",
             "|---|---|---|---:|---:|"]
    scenes = ordered(r["scene"] for r in rows)
    on_front = dominating = 0
    for scene in scenes:
        mine = [r for r in rows if r["scene"] == scene]
        km_front = kmeans_on_front(mine)
        medium = next((r for r in mine if r["builder"] == "embree-medium"), None)
        km = [r for r in mine if r["builder_name"] == "kmeans"]
        dom = [short(r["builder"]) for r in km
               if medium and r["build_ms"] < medium["build_ms"] and r["sah_cost"] <= medium["sah_cost"]]
        within = [r for r in km if medium and r["build_ms"] <= medium["build_ms"]]
        best = min(within, key=lambda r: r["sah_cost"]) if within else None
        on_front += bool(km_front)
        dominating += bool(dom)
        lines.append(f"| {scene.rsplit('.', 1)[0]} | {', '.join(km_front) or 'none'} | {', '.join(dom) or 'none'} | "
                     + (f"{medium['build_ms']:.1f}, {medium['sah_cost']:.1f}" if medium else "-") + " | "
                     + (f"{best['sah_cost'] / medium['sah_cost']:.3f} ({short(best['builder'])})" if best else "-")
                     + " |")
    lines.append("")
    lines.append(f"Some k-means configuration on the Pareto front on {on_front} of {len(scenes)} scenes; one dominating "
                 f"embree-medium on {dominating} of {len(scenes)}.")
    Path(out_path).write_text("\n".join(lines) + "\n")


def speed_chart(rows, out_dir):
    """Per scene: build time (log) against the path tracer's Mrays/s in LQ, every system."""
    scenes = ordered(r["scene"] for r in rows)
    fig, axes = scene_grid(scenes)
    for ax, scene in zip(axes, scenes):
        for r in (r for r in rows if r["scene"] == scene and r["lq"]):
            ax.scatter(r["build_ms"], r["lq"]["mrays_per_s"], color=colour(r), s=26, zorder=3,
                       marker="D" if r["traversal"] == "embree" else "o")
            ax.annotate(short(r["builder"]), (r["build_ms"], r["lq"]["mrays_per_s"]), fontsize=6.5, xytext=(3, 2),
                        textcoords="offset points")
        panel(ax, scene, "build ms (log)", "Mrays/s (path tracer, LQ)", log_build_ms=True)
    fig.suptitle("Build time against trace speed (upper left is better; diamond: Embree's own traversal)", fontsize=10)
    fig.tight_layout()
    save(fig, out_dir, "speed")


def tti_chart(rows, out_dir):
    """Time to image over sweep SAH's, LQ above and HQ below: a group of bars per scene, a bar
    per system, as the paper's figures show it; each bar drawn from 1 (sweep SAH) so that
    differences of a few percent stay visible."""
    scenes = ordered(r["scene"] for r in rows)
    systems = ordered(r["builder"] for r in rows)
    cmap = matplotlib.colormaps["tab20"]
    fig, axes = plt.subplots(2, 1, figsize=(min(18.0, max(8.0, 0.08 * len(scenes) * len(systems))), 8.0))
    width = 0.85 / max(1, len(systems))
    for ax, quality in zip(axes, ("lq", "hq")):
        for k, system in enumerate(systems):
            xs, ys = [], []
            for i, scene in enumerate(scenes):
                r = next((r for r in rows if r["scene"] == scene and r["builder"] == system), None)
                value = r and r.get(f"time_to_image_{quality}_over_sweep_sah")
                if value:
                    xs.append(i + (k - (len(systems) - 1) / 2) * width)
                    ys.append(value)
            ax.bar(xs, [y - 1.0 for y in ys], bottom=1.0, width=width, color=cmap(k % 20), label=short(system))
        ax.axhline(1.0, color="grey", linewidth=0.8)
        ax.set_xticks(range(len(scenes)), [s.rsplit(".", 1)[0] for s in scenes], fontsize=8)
        ax.set_ylabel(f"time to image {quality.upper()} / sweep SAH", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(fontsize=6.5, ncol=min(8, len(systems)), loc="upper center", bbox_to_anchor=(0.5, 1.25))
    fig.suptitle("Time to image (build + layout + render, mean over views) over sweep SAH's: lower is better",
                 fontsize=10, y=1.0)
    fig.tight_layout()
    save(fig, out_dir, "time_to_image")


def targets_table(rows, out_path):
    """Per scene: which k-means presets are on the Pareto front of build time and SAH cost, and
    the fastest LQ time to image of k-means against every other builder's (kmbvh traversal)
    and against Embree end to end."""
    lines = ["| scene | k-means on the Pareto front | fastest k-means TTI LQ (ms) | fastest other builder | "
             "k-means fastest? | Embree end to end (ms) |",
             "|---|---|---:|---|---|---:|"]
    scenes = ordered(r["scene"] for r in rows)
    on_front = fastest = 0
    for scene in scenes:
        mine = [r for r in rows if r["scene"] == scene]
        kmeans_front = kmeans_on_front(mine)
        on_front += bool(kmeans_front)
        timed = [r for r in mine if r["lq"] and r["traversal"] == "kmbvh"]
        km = [r for r in timed if r["builder_name"] == "kmeans"]
        others = [r for r in timed if r["builder_name"] != "kmeans"]
        embree = next((r for r in mine if r["traversal"] == "embree" and r["lq"]), None)
        if not km:
            continue
        best_km = min(km, key=lambda r: r["lq"]["time_to_image_ms"])
        best_other = min(others, key=lambda r: r["lq"]["time_to_image_ms"]) if others else None
        wins = best_other is None or best_km["lq"]["time_to_image_ms"] <= best_other["lq"]["time_to_image_ms"]
        fastest += wins
        lines.append(f"| {scene.rsplit('.', 1)[0]} | {', '.join(kmeans_front) or 'none'} | "
                     f"{best_km['lq']['time_to_image_ms']:.0f} ({short(best_km['builder'])}) | "
                     + (f"{short(best_other['builder'])} {best_other['lq']['time_to_image_ms']:.0f}" if best_other else "-")
                     + f" | {'yes' if wins else 'no'} | "
                     + (f"{embree['lq']['time_to_image_ms']:.0f}" if embree else "") + " |")
    lines.append("")
    lines.append(f"Some k-means preset on the Pareto front on {on_front} of {len(scenes)} scenes; k-means' LQ time to "
                 f"image at most every other builder's on {fastest} of {len(scenes)} (all in kmbvh's traversal).")
    Path(out_path).write_text("\n".join(lines) + "\n")


# The paper's SAH cost over full sweep SAH's, averaged over its nine scenes (Meister and
# Bittner 2016; docs/design.md §4).
PAPER_AVERAGE_SAH_OVER_SWEEP = {"Q1": 1.19, "Q2": 1.08, "Q3": 1.01, "Q4": 0.97, "Q5": 0.94, "lbvh": 1.27,
                                "hlbvh": 1.09, "atrbvh": 0.86}


def paper_table(rows, out_path):
    """The paper's figures beside ours: SAH cost over sweep SAH's averaged over scenes, and per
    scene of its Table 1, SAH cost and trace speed over sweep SAH's (its speeds are a GPU's, so
    only ratios compare)."""
    def key(r):
        return short(r["builder"]) if r["builder_name"] == "kmeans" else r["builder_name"]

    lines = ["| builder | SAH / sweep, ours (mean over our scenes) | the paper's (mean over its 9 scenes) |",
             "|---|---:|---:|"]
    for name, theirs in PAPER_AVERAGE_SAH_OVER_SWEEP.items():
        ours = [r["sah_cost_over_sweep_sah"] for r in rows if key(r) == name and r["sah_cost_over_sweep_sah"]]
        if ours:
            lines.append(f"| {name} | {sum(ours) / len(ours):.3f} ({len(ours)} scenes) | {theirs:.2f} |")
    lines += ["", "| scene | builder | SAH ours / paper | SAH / sweep ours / paper | Mrays/s / sweep ours / paper |",
              "|---|---|---:|---:|---:|"]
    for scene in ordered(r["scene"] for r in rows):
        mine = [r for r in rows if r["scene"] == scene]
        sweep = next((r for r in mine if r["builder_name"] == "sweep-sah"), None)
        if not sweep or sweep["paper_sah_cost"] is None:
            continue
        for r in mine:
            if r["paper_sah_cost"] is None or r["sah_cost"] is None:
                continue
            speed = (f"{r['mrays_per_s_over_sweep_sah']:.2f} / {r['paper_mrays_per_s'] / sweep['paper_mrays_per_s']:.2f}"
                     if r["mrays_per_s_over_sweep_sah"] and r["paper_mrays_per_s"] else "")
            lines.append(f"| {scene.rsplit('.', 1)[0]} | {key(r)} | {r['sah_cost']:.0f} / {r['paper_sah_cost']:.0f} | "
                         f"{r['sah_cost_over_sweep_sah']:.2f} / {r['paper_sah_cost'] / sweep['paper_sah_cost']:.2f} | "
                         f"{speed} |")
    Path(out_path).write_text("\n".join(lines) + "\n")


def projection_table(rows, out_path):
    """HQ rendered against HQ projected from LQ: the render time over LQ's, against the ratio
    of their samples per pixel."""
    lines = ["| scene | LQ render ms | HQ render ms | HQ / LQ | spp ratio | projection error |",
             "|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        if not (r["lq"] and r["hq"]) or r["hq"]["projected"]:
            continue
        measured = r["hq"]["render_ms"] / r["lq"]["render_ms"]
        expected = r["hq"]["spp"] / r["lq"]["spp"]
        lines.append(f"| {r['scene'].rsplit('.', 1)[0]} | {r['lq']['render_ms']:.0f} | {r['hq']['render_ms']:.0f} | "
                     f"{measured:.2f} | {expected:.0f} | {100 * (expected / measured - 1):+.1f}% |")
    Path(out_path).write_text("\n".join(lines) + "\n")


def iterations_chart(rows, out_dir):
    """The paper's stabilisation figure: SAH cost against Lloyd iterations, a line per k."""
    scenes = ordered(r["scene"] for r in rows)
    fig, axes = scene_grid(scenes)
    for ax, scene in zip(axes, scenes):
        mine = [r for r in rows if r["scene"] == scene]
        for k in sorted({r["params"]["k"] for r in mine}):
            line = sorted((r["params"]["i"], r["sah_cost"]) for r in mine if r["params"]["k"] == k)
            ax.plot([p[0] for p in line], [p[1] for p in line], marker="o", markersize=3, label=f"k = {k}")
        panel(ax, scene, "Lloyd iterations i", "SAH cost")
        ax.legend(fontsize=7)
    fig.suptitle("SAH cost against k-means iterations (p: 5 for k <= 16, 20 for 32, 30 for 64)", fontsize=10)
    fig.tight_layout()
    save(fig, out_dir, "iterations")


PHASES = ["setup", "initialise", "assign", "update", "partition", "agglomerate", "subtrees", "finish"]


def phases_chart(rows, out_dir):
    """The paper's kernel-time figure: each preset's build time split by phase, stacked."""
    scenes = ordered(r["scene"] for r in rows)
    fig, axes = scene_grid(scenes, width=4.2)
    cmap = matplotlib.colormaps["tab10"]
    for ax, scene in zip(axes, scenes):
        mine = [r for r in rows if r["scene"] == scene]
        names = [short(r["builder"]) for r in mine]
        bottom = [0.0] * len(mine)
        phases = [p for p in PHASES if any(p in r["phases_ms"] for r in mine)]
        phases += [p for r in mine for p in r["phases_ms"] if p not in phases]
        for k, phase in enumerate(ordered(phases)):
            heights = [r["phases_ms"].get(phase, 0.0) for r in mine]
            ax.bar(names, heights, bottom=bottom, color=cmap(k % 10), label=phase)
            bottom = [b + h for b, h in zip(bottom, heights)]
        panel(ax, scene, "", "ms (last run)")
    axes[0].legend(fontsize=7)
    fig.suptitle("k-means build time by phase (the portable level loop, as on the GPU)", fontsize=10)
    fig.tight_layout()
    save(fig, out_dir, "phases")


def load(path):
    try:
        rows = json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        sys.exit(f"charts.py: {path}: {e}")
    if not rows:
        sys.exit(f"charts.py: {path}: no rows")
    return rows


CHARTS = {"stress": stress_chart, "presets": presets_chart, "table": presets_table, "scaling": scaling_chart,
          "pareto": pareto_chart, "speed": speed_chart, "tti": tti_chart, "targets": targets_table, "paper": paper_table,
          "projection": projection_table, "beyond": beyond_chart, "beyond_table": beyond_table,
          "iterations": iterations_chart, "phases": phases_chart}

# What `all DIR` makes: chart, its JSON in DIR, and where the chart goes (a folder, or a file).
ALL = [("stress", "stress.json", "."), ("presets", "presets.json", "."), ("table", "presets.json", "presets.md"),
       ("scaling", "scaling.json", "."), ("pareto", "suite.json", "."), ("speed", "suite.json", "."),
       ("tti", "suite.json", "."), ("targets", "suite.json", "targets.md"), ("paper", "suite.json", "paper.md"),
       ("projection", "hq.json", "projection.md"), ("iterations", "iterations.json", "."),
       ("phases", "phases.json", "."), ("beyond", "beyond.json", "."), ("beyond_table", "beyond.json", "beyond.md")]


def main(argv):
    if len(argv) == 3 and argv[1] == "all":
        folder = Path(argv[2])
        made = 0
        for chart, data, out in ALL:
            if (folder / data).exists():
                CHARTS[chart](load(folder / data), folder / out if out != "." else folder)
                made += 1
        if not made:
            sys.exit(f"charts.py: {folder}: none of the JSON files the charts are made from")
        return
    if len(argv) != 4 or argv[1] not in CHARTS:
        sys.exit(__doc__)
    CHARTS[argv[1]](load(argv[2]), Path(argv[3]))


if __name__ == "__main__":
    main(sys.argv)
