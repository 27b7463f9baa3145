#!/usr/bin/env python3
"""Which k-means configuration each RTCBuildQuality maps to, chosen by measurement.

Reads the CSV of `kmbvh bench ... --csv FILE` and, for each of Embree's build qualities
(embree-low, embree-medium, embree-high), scores every other builder by how far it is from
dominating Embree's build on each scene: max(time / Embree's time, SAH / Embree's SAH),
which is at most 1 where it dominates (no slower, no dearer). The geometric mean over the
scenes ranks the builders; the best one is the quality's mapping, and the best k-means one
the quality's k-means configuration where k-means is asked for (plugin/plugin_config.cpp:
builder_for), except where Embree's HIGH builds MEDIUM's tree, where HIGH takes the lowest
SAH cost. Prints Markdown. Example:

  build/bin/kmbvh bench default armadillo_libigl bunny_stanford conference fandisk ogre sibenik \\
      sponza_dabrovic spot teapot ww2_cityscene --threads 2 --runs 7 --warmup 1 -q \\
      --builders lbvh,ploc,atrbvh,Q1,Q2,Q3,Q1S,Q2S,Q3S,QA,embree-low,embree-medium,embree-high --csv bench.csv
  scripts/quality_table.py bench.csv
"""
import argparse
import csv
import math
import sys

QUALITIES = [("LOW", "embree-low"), ("MEDIUM", "embree-medium"), ("HIGH", "embree-high")]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help="the rows of kmbvh bench --csv")
    args = parser.parse_args()

    rows = {}  # scene -> builder -> (ms, sah)
    order = []
    with open(args.csv, newline="") as f:
        for r in csv.DictReader(f):
            rows.setdefault(r["scene"], {})[r["builder"]] = (float(r["build_ms"]), float(r["sah_cost"]))
            if r["builder"] not in order:
                order.append(r["builder"])
    scenes = list(rows)
    missing = [(s, ref) for s in scenes for _, ref in QUALITIES if ref not in rows[s]]
    if missing:
        sys.exit(f"{args.csv}: no row for {missing[0][1]} on {missing[0][0]}: bench every Embree quality on every scene")

    for quality, ref in QUALITIES:
        scored = []
        for builder in order:
            if builder.startswith("embree-") or any(builder not in rows[s] for s in scenes):
                continue
            time = [rows[s][builder][0] / rows[s][ref][0] for s in scenes]
            sah = [rows[s][builder][1] / rows[s][ref][1] for s in scenes]
            miss = [max(t, c) for t, c in zip(time, sah)]
            geomean = lambda xs: math.exp(sum(math.log(x) for x in xs) / len(xs))
            scored.append((geomean(miss), builder, geomean(time), geomean(sah), sum(m <= 1.0 for m in miss),
                           max(miss)))
        scored.sort()
        ranked = list(scored)
        rule = "nearest to dominating"
        # Where Embree's HIGH builds MEDIUM's tree (rtcBuildBVH: no spatial splits), nearness
        # to dominating it would choose MEDIUM's configuration again; HIGH asks for the best
        # tree, so it takes the lowest SAH cost, the faster of equals (to 1%).
        if quality == "HIGH" and all(abs(rows[s][ref][1] / rows[s]["embree-medium"][1] - 1) < 0.005 for s in scenes):
            rule = "Embree's HIGH builds MEDIUM's tree: lowest SAH"
            ranked.sort(key=lambda entry: (round(entry[3], 2), entry[2]))
        kmeans = [entry for entry in ranked if entry[1].startswith("kmeans ")]
        chosen = ranked[0][1] if ranked else None
        chosen_kmeans = kmeans[0][1] if kmeans else None
        shown = lambda builder: f"`{builder.removeprefix('kmeans ')}`" if builder else "none"
        print(f"\n**{quality}** against `{ref}` on {len(scenes)} scenes ({rule}); chosen: {shown(chosen)}, "
              f"where k-means is asked for: {shown(chosen_kmeans)}\n")
        print("| builder | from dominating (geomean) | worst scene | time / Embree's | SAH / Embree's | scenes dominated |")
        print("|---|---:|---:|---:|---:|---:|")
        for score, builder, time, sah, dominated, worst in scored:
            name = f"**{builder}**" if builder in (chosen, chosen_kmeans) else builder
            print(f"| {name} | {score:.2f} | {worst:.2f} | {time:.2f} | {sah:.2f} | {dominated} |")


if __name__ == "__main__":
    main()
