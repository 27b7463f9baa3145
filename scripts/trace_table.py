#!/usr/bin/env python3
"""Trace speed of kmbvh's traversal against Embree's, as a Markdown table.

Runs `kmbvh trace --compare-embree --json` for each scene, builder and thread count, and
prints, per ray kind, kmbvh's Mrays/s on the chosen layout, Embree's rtcIntersect1 /
rtcOccluded1 Mrays/s on the very same rays (from the same process), their ratio, and the
mismatch count. Example:

  scripts/trace_table.py --scenes sponza_dabrovic sibenik conference --builders Q2 Q5 embree-medium lbvh

A builder may carry its own options: --builders "Q2" "Q2 --wide --k 8" --layout bvh8 compares
the collapsed binary k-means tree with the k-ary one laid out as built.
"""
import argparse
import json
import shlex
import subprocess
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--kmbvh", default="build/bin/kmbvh")
    parser.add_argument("--scenes", nargs="+", default=["sponza_dabrovic", "sibenik", "conference"])
    parser.add_argument("--builders", nargs="+", default=["Q2", "Q5", "embree-medium", "lbvh"])
    parser.add_argument("--threads", nargs="+", type=int, default=[1, 2])
    parser.add_argument("--layout", default="bvh8")
    parser.add_argument("--count", type=int, default=100000)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()

    kinds = ["primary", "shadow", "diffuse"]
    print(f"| scene | builder | threads | " + " | ".join(f"{k} kmbvh / Embree (ratio)" for k in kinds) + " | mismatches |")
    print("|---|---|---:|" + "---:|" * len(kinds) + "---:|")
    for scene in args.scenes:
        for threads in args.threads:
            for builder in args.builders:
                command = [args.kmbvh, "trace", scene, "--builder", *shlex.split(builder), "--layout", args.layout, "--count",
                           str(args.count), "--threads", str(threads), "--runs", str(args.runs), "--compare-embree",
                           "--json", "-q"]
                run = subprocess.run(command, capture_output=True, text=True)
                if run.returncode not in (0, 4):
                    sys.exit(f"{' '.join(command)} failed ({run.returncode}): {run.stderr.strip()}")
                result = json.loads(run.stdout)
                layout = result["layouts"][0]
                cells = []
                for k in layout["kinds"]:
                    cells.append(f"{k['kmbvh_mrays_per_s']:.2f} / {k['embree_mrays_per_s']:.2f} ({k['ratio_to_embree']:.2f})")
                name = result["builder"] + (" (k-ary, as built)" if not layout["collapsed"] and args.layout != "bvh2" else "")
                print(f"| {result['scene']} | {name} | {threads} | " + " | ".join(cells) +
                      f" | {result['mismatches']} |", flush=True)


if __name__ == "__main__":
    main()
