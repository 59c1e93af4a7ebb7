#!/usr/bin/python3
"""Condense prtr overdraw runs into one Markdown table per run (scripts/overdraw_experiments.sh).

For every K and method, the row of the lowest-overdraw strategy at the given budget: the
thesis's columns (clustering time, average overdraw, FPS, Average SE) with the overdraw bound
and ratios to the original row, then image RMSE and the process CPU ms per frame; per K the
best row whose SE and RMSE are within 1.05 x the original's and its gap to the bound; then
the run's fits.

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
    print("Ratios (x) are to the original row at the same K: Average SE, image RMSE and "
          "clustering time. Bound: no grouping of that row's clusters into passes draws less "
          "(cpca/overdraw_bound.h).\n")
    print("| K | method | strategy | clustering time (x) | average overdraw | bound | SE x | RMSE x "
          "| FPS (IQR) | Average SE | image RMSE | CPU ms (IQR) |")
    print("| ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for (k, method), r in best.items():
        o = best.get((k, "original"), r)
        ratio = lambda a, b: a / b if b > 0 else float("nan")
        print(f"| {k} | {method} | {r['strategy']} | {r['clustering_seconds']:.1f} s "
              f"({ratio(r['clustering_seconds'], o['clustering_seconds']):.2f}) "
              f"| {r['average_overdraw']:.3f} | {r.get('overdraw_bound', float('nan')):.3f} "
              f"| {ratio(r['average_se'], o['average_se']):.3f} "
              f"| {ratio(r['image_rmse'], o['image_rmse']):.3f} "
              f"| {r['fps']:.1f} ({r['fps_q3'] - r['fps_q1']:.1f}) "
              f"| {r['average_se']:.3e} | {100 * r['image_rmse_relative']:.2f} % "
              f"| {r['process_cpu_ms']:.1f} ({r['process_cpu_ms_q3'] - r['process_cpu_ms_q1']:.1f}) |")
    for k in sorted({k for k, _ in best}):
        o = best.get((k, "original"))
        ok = [r for (kk, _), r in best.items() if kk == k and o is not None
              and r["average_se"] <= 1.05 * o["average_se"]
              and r["image_rmse"] <= 1.05 * o["image_rmse"]]
        if ok:
            b = min(ok, key=lambda r: r["average_overdraw"])
            low = min(r.get("overdraw_bound", 1.0) for (kk, _), r in best.items() if kk == k)
            print(f"\nK = {k}: best row with SE and RMSE <= 1.05 x original: {b['method']} "
                  f"{b['average_overdraw']:.3f} (its bound {b.get('overdraw_bound', 1.0):.3f}, gap "
                  f"{b['average_overdraw'] - b.get('overdraw_bound', 1.0):.3f}; lowest bound of "
                  f"the table {low:.3f})")
    print()
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
