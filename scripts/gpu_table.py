#!/usr/bin/env python3
"""Turns run_gpu.sh's logs into Markdown: the machine, one render_bench table per mesh (FPS,
frame time and its ratio against that mesh's floor in the same run), the thesis
configuration's FPS, and bake throughput by thread count. Standard library only.

usage: gpu_table.py ENV.txt RENDER_BENCH.log BAKE_BENCH.log [INPUTS.log] > results.md
"""
import re
import sys

ROW = re.compile(r"^(.+?)\s+\d+\s+\d+\.\d+\s+\d+\.\d+\s+\d+\.\d+\s")


def render_tables(log):
    meshes, cur, in_rows = [], None, False
    for line in log.splitlines():
        if line.startswith("== bunny"):
            cur = {"name": line.split()[1], "head": [], "rows": [], "thesis": None, "exit": None}
            meshes.append(cur)
            in_rows = False
        elif cur is None:
            continue
        elif line.startswith("== exit"):
            cur["exit"] = line.split()[2]
        elif line.startswith("render_bench:"):
            cur["head"].append(line[len("render_bench:"):].strip())
        elif line.startswith("configuration"):
            in_rows = True
        elif in_rows and not line.strip():
            in_rows = False
        elif in_rows:
            # A name may overflow its 28 columns (", in-draw"); the numbers follow it.
            m = ROW.match(line)
            if m:
                cur["rows"].append((m.group(1).strip(), line[m.end(1):].split()))
        elif "thesis config" in line:
            m = re.search(r"([\d.]+) FPS", line)
            cur["thesis"] = m.group(1) if m else None
    out = []
    for m in meshes:
        out.append(f"### {m['name']}\n")
        for h in m["head"]:
            out.append(f"- {h}")
        if m["exit"] not in ("0", None):
            out.append(f"- exit status {m['exit']} (124: stopped at its time limit)")
        out.append("")
        if not m["rows"]:
            out.append("(no rows)\n")
            continue
        floor = None
        for name, f in m["rows"]:
            if name.startswith("floor (trivial, cull+order)"):
                floor = float(f[3])
        out.append("| configuration | passes | avg overdraw | FPS | frame ms | x floor |")
        out.append("| --- | ---: | ---: | ---: | ---: | ---: |")
        for name, f in m["rows"]:
            ratio = f"{float(f[3]) / floor:.2f}" if floor else "-"
            out.append(f"| {name} | {f[0]} | {f[1]} | {f[2]} | {f[3]} | {ratio} |")
        if m["thesis"]:
            out.append(f"\nthesis configuration (256 x 8, 3 clusters/pass, ILS): "
                       f"**{m['thesis']} FPS**")
        out.append("")
    return "\n".join(out)


def fit(xs, ys):
    """Least-squares y = a + b x: (a, b, R^2); None with fewer than 3 points or no spread."""
    n = len(xs)
    if n < 3:
        return None
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    syy = sum((y - my) ** 2 for y in ys)
    if sxx == 0:
        return None
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    a = my - b * mx
    r2 = 1.0 - sum((y - a - b * x) ** 2 for x, y in zip(xs, ys)) / syy if syy > 0 else 1.0
    return a, b, r2


def overdraw_fits(log):
    """Frame time against average overdraw over each sweep's rows (same passes, different
    groupings), per mesh and clusters per pass."""
    out = ["| mesh | clusters/pass | rows | overdraw | FPS | frame ms = a + b x overdraw | "
           "R^2 |", "| --- | ---: | ---: | --- | --- | --- | ---: |"]
    label = None
    groups = {}
    for line in log.splitlines():
        if line.startswith("== bunny"):
            label = line.split()[1]
        elif label and label.endswith("-sweep") and line.startswith("sweep "):
            m = ROW.match(line)
            if not m:
                continue
            f = line[m.end(1):].split()
            per_pass = m.group(1).split()[1].split("/")[0]
            groups.setdefault((label[:-len("-sweep")], per_pass), []).append(
                (float(f[1]), float(f[3]), float(f[2])))
    if not groups:
        return ""
    for (mesh, per_pass), pts in groups.items():
        xs, ys, fps = [p[0] for p in pts], [p[1] for p in pts], [p[2] for p in pts]
        r = fit(xs, ys)
        line = (f"| {mesh} | {per_pass} | {len(pts)} | {min(xs):.3f}-{max(xs):.3f} | "
                f"{min(fps):.0f}-{max(fps):.0f} | ")
        line += f"{r[0]:.3f} + {r[1]:.3f} x | {r[2]:.2f} |" if r else "- | - |"
        out.append(line)
    return "\n".join(out) + "\n"


def bake_table(log):
    runs, cur = [], None
    for line in log.splitlines():
        if line.startswith("== threads"):
            cur = {"threads": int(line.split()[2]), "b0": None, "b1": None, "bare": None,
                   "note": "skipped" if "skipped" in line else ""}
            runs.append(cur)
        elif cur is None:
            continue
        elif line.startswith("== exit"):
            if line.split()[2] != "0":
                cur["note"] = f"exit {line.split()[2]}"
        elif line.startswith("glossy order 6, 1 bounce"):
            cur["b1"] = re.findall(r"[\d.]+(?= s)", line)
        elif line.startswith("glossy order 6, 0 bounce"):
            cur["b0"] = re.findall(r"[\d.]+(?= s)", line)
        elif line.startswith("bare occlusion"):
            cur["bare"] = re.search(r"bare occlusion: ([\d.]+) s", line).group(1)
    one = next((float(r["b1"][0]) for r in runs if r["threads"] == 1 and r["b1"]), None)
    out = ["| threads | bake, 1 bounce (s) | shadow (s) | bounce (s) | rest (s) | "
           "speed-up vs 1 thread | bake, 0 bounces (s) | bare Embree occlusion (s) | note |",
           "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
    for r in sorted(runs, key=lambda r: r["threads"]):
        b1 = r["b1"] or ["-", "-", "-"]
        b0 = r["b0"] or ["-"]
        up = f"{one / float(b1[0]):.2f}" if one and r["b1"] else "-"
        rest = (f"{float(b1[0]) - float(b1[1]) - float(b1[2]):.2f}" if r["b1"] else "-")
        out.append(f"| {r['threads']} | {b1[0]} | {b1[1]} | {b1[2]} | {rest} | {up} | {b0[0]} | "
                   f"{r['bare'] or '-'} | {r['note']} |")
    return "\n".join(out)


def main():
    env, render, bake = (open(p).read() for p in sys.argv[1:4])
    inputs = open(sys.argv[4]).read() if len(sys.argv) > 4 else ""
    print("# GPU benchmark\n")
    for line in env.splitlines():
        print(f"- {line}")
    for line in inputs.splitlines():
        if line.startswith(("bundle_inputs", "inputs")):
            print(f"- {line}")
    print("\n## render_bench (1280 x 948, median frame)\n")
    print(render_tables(render))
    fits = overdraw_fits(render)
    if fits:
        print("## FPS against overdraw (the sweeps: same passes, every grouping strategy)\n")
        print(fits)
    print("## bake_bench (bunny, glossy order 6)\n")
    print(bake_table(bake))


if __name__ == "__main__":
    main()
