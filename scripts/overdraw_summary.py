#!/usr/bin/python3
"""Condense prtr overdraw runs into one Markdown table per run (scripts/overdraw_experiments.sh).

For every K and method, the row of the lowest-overdraw strategy at the given budget: the
thesis's columns (clustering time, average overdraw, FPS, Average SE), then image RMSE, the
process CPU ms per frame and the primitives counted; then the run's fits.

    python3 scripts/overdraw_summary.py OUT_DIR/RUN [OUT_DIR/RUN ...] [--budget thesis]
"""
import argparse
import json
import sys


def summarize(run_dir, budget):
    with open(f"{run_dir}/overdraw.json", encoding="utf-8") as f:
        report = json.load(f)
    rows = [r for r in report["rows"] if r["budget"] == budget]
    if not rows:
        raise SystemExit(f"{run_dir}: no rows for budget '{budget}'")
    best = {}
    for r in rows:
        key = (r["clusters"], r["method"])
        if key not in best or r["average_overdraw"] < best[key]["average_overdraw"]:
            best[key] = r
    print(f"**{run_dir.rstrip('/').split('/')[-1]}**: {report['vertices']:,} vertices, {report['bake']}; "
          f"{report['rounds']} rounds x {report['frames']} frames per row\n")
    print("| K | method | strategy | clustering time | average overdraw | FPS (IQR) | Average SE "
          "| image RMSE | CPU ms (IQR) | primitives |")
    print("| ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for (k, method), r in best.items():
        print(f"| {k} | {method} | {r['strategy']} | {r['clustering_seconds']:.1f} s "
              f"| {r['average_overdraw']:.3f} | {r['fps']:.1f} ({r['fps_q3'] - r['fps_q1']:.1f}) "
              f"| {r['average_se']:.3e} | {100 * r['image_rmse_relative']:.2f} % "
              f"| {r['process_cpu_ms']:.1f} ({r['process_cpu_ms_q3'] - r['process_cpu_ms_q1']:.1f}) "
              f"| {r['primitives']:,} |")
    fits = report["fits"]
    print("\nAll " + str(fits["gl_ms"]["points"]) + " rows against overdraw: " + "; ".join(
        f"{name} slope {f['slope']:.3g}, intercept {f['intercept']:.3g}, R² {f['r2']:.3f}"
        for name, f in fits.items()) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--budget", default="thesis")
    args = parser.parse_args()
    for run in args.runs:
        try:
            summarize(run, args.budget)
        except OSError as e:
            print(f"overdraw_summary: {e}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
