#!/usr/bin/python3
"""Plot the overdraw benchmark (`prtr overdraw`) from its overdraw.csv or overdraw.json.

For one register budget, one line per clustering method through its lowest-overdraw
super-cluster strategy at each cluster count K: average triangle overdraw on the left, the
frame rate of that same configuration on the right.

    python3 scripts/plot_overdraw.py out/overdraw/overdraw.csv [-o plot.png] [--budget thesis]

Exit 0 on success, 1 when the input cannot be read or has no rows for the budget, 2 on usage.
"""
import argparse
import csv
import json
import os
import sys
import tempfile


def read_rows(path):
    if path.endswith(".json"):
        with open(path, encoding="utf-8") as f:
            return json.load(f)["rows"]
    with open(path, newline="", encoding="utf-8", errors="replace") as f:
        return list(csv.DictReader(f))


def best_per_method(rows, budget):
    """method -> {K: (overdraw, fps, strategy)}, methods in first-seen order."""
    best = {}
    for row in rows:
        if row["budget"] != budget:
            continue
        k = int(row["clusters"])
        overdraw = float(row["average_overdraw"])
        fps = float(row["fps"]) if row["fps"] not in (None, "") else float("nan")
        by_k = best.setdefault(row["method"], {})
        if k not in by_k or overdraw < by_k[k][0]:
            by_k[k] = (overdraw, fps, row["strategy"])
    return best


def plot(best, budget, output):
    import matplotlib

    # Chosen before pyplot is imported: the plot is written to a file, there is no display.
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_overdraw, ax_fps) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    ks = sorted({k for by_k in best.values() for k in by_k})
    for method, by_k in best.items():
        x = sorted(by_k)
        ax_overdraw.plot(x, [by_k[k][0] for k in x], marker="o", label=method)
        ax_fps.plot(x, [by_k[k][1] for k in x], marker="o", label=method)
    for ax in (ax_overdraw, ax_fps):
        ax.set_xlabel("clusters K")
        ax.set_xticks(ks)
        ax.grid(True, color="0.88")
    ax_overdraw.set_ylabel("average triangle overdraw (draws per triangle)")
    ax_overdraw.set_title("Overdraw, lowest-overdraw strategy per K")
    ax_fps.set_ylabel("frame rate (frames/s)")
    ax_fps.set_title("FPS of the same configuration")
    ax_overdraw.legend(title="method")
    fig.suptitle(f"prtr overdraw, {budget} register budget")

    # Written beside the target and renamed over it, so a reader never sees half a PNG.
    directory = os.path.dirname(os.path.abspath(output))
    fd, temporary = tempfile.mkstemp(prefix=".plot-", suffix=".png", dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            fig.savefig(f, format="png", dpi=100)
        os.replace(temporary, output)
    except BaseException:
        os.unlink(temporary)
        raise
    finally:
        plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input", help="overdraw.csv or overdraw.json from prtr overdraw")
    parser.add_argument("-o", "--output", help="PNG to write (default: overdraw-plot.png beside the input)")
    parser.add_argument("--budget", help="register budget to plot (default: thesis if measured, else the first)")
    args = parser.parse_args()
    output = args.output or os.path.join(os.path.dirname(args.input), "overdraw-plot.png")
    try:
        rows = read_rows(args.input)
    except (OSError, ValueError, KeyError) as e:
        print(f"plot_overdraw: cannot read {args.input}: {e}", file=sys.stderr)
        return 1
    budgets = list(dict.fromkeys(row["budget"] for row in rows))
    budget = args.budget or ("thesis" if "thesis" in budgets else (budgets or [""])[0])
    best = best_per_method(rows, budget)
    if not best:
        print(f"plot_overdraw: {args.input} has no rows for budget '{budget}' (it has: "
              f"{', '.join(budgets) or 'none'})", file=sys.stderr)
        return 1
    try:
        import matplotlib  # noqa: F401  (fail here with advice, not deep in a traceback)
    except ImportError:
        print(f"plot_overdraw: {sys.executable} has no matplotlib; install python3-matplotlib "
              "(Debian) and run this with /usr/bin/python3", file=sys.stderr)
        return 1
    try:
        plot(best, budget, output)
    except OSError as e:
        print(f"plot_overdraw: cannot write {output}: {e}", file=sys.stderr)
        return 1
    print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
