#!/usr/bin/env python3
"""Summarises a Google Benchmark JSON file written by nsp_bench (bench/run.sh).

Prints, from the median aggregates: raw lookup rates; the tracking loop's lookup rate and its
ratio to the raw rate (the target is >= 0.7); time and density lookups per sample of every path
estimator; and the cost of counting lookups. With --markdown the same tables are Markdown.
Usage: report.py results.json [--markdown]
"""
import json
import re
import sys

TARGET = 0.7


def load(path):
    """median and cv aggregates by run name: {name: {"median": row, "cv": row}}."""
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data["benchmarks"]:
        name = re.sub(r"/min_time:[0-9.]+", "", b["run_name"])
        if b.get("run_type") == "aggregate":
            runs.setdefault(name, {})[b["aggregate_name"]] = b
        elif b.get("run_type") == "iteration":  # a run without repetitions
            runs.setdefault(name, {})["median"] = b
    return data.get("context", {}), runs


def ns(row):
    """CPU time per iteration in ns."""
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[row["time_unit"]]
    return row["cpu_time"] * scale


def cv(entry, key):
    """Coefficient of variation over the repetitions, in percent, or '-'."""
    row = entry.get("cv")
    if row is None or key not in row:
        return "-"
    return f"{100.0 * row[key]:.1f}%"


def table(md, header, rows):
    if md:
        print("| " + " | ".join(header) + " |")
        print("|" + "|".join("---" for _ in header) + "|")
        for r in rows:
            print("| " + " | ".join(r) + " |")
    else:
        widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
        for r in [header] + rows:
            print("  ".join(str(x).ljust(w) for x, w in zip(r, widths)))
    print()


def title(md, text):
    print(("### " if md else "== ") + text)
    print()


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    md = "--markdown" in sys.argv
    if len(args) != 1:
        sys.exit(__doc__)
    ctx, runs = load(args[0])
    med = {name: e["median"] for name, e in runs.items() if "median" in e}

    # Raw lookups.
    raw = {}
    rows = []
    for name, row in med.items():
        m = re.fullmatch(r"BM_RawLookup(Chained)?<(\w+)(?:, (\w+))?>", name)
        if not m:
            continue
        chained, mode, points = m.groups()
        kind = "chained (latency)" if chained else points.replace("Points", "").lower()
        raw[(mode, kind)] = row["lookups/s"]
        rows.append([mode, kind, f"{row['lookups/s'] / 1e6:.1f}", f"{ns(row) / (1 << 14):.1f}",
                     cv(runs[name], "lookups/s")])
    title(md, "Raw trilinear lookups on the default cloud grid (64^3 floats, 1 MiB)")
    table(md, ["mode", "points", "M lookups/s", "ns/lookup", "cv"], sorted(rows))

    # Tracking.
    rows = []
    overhead = []
    for name, row in med.items():
        m = re.fullmatch(r"BM_Track<(\w+), (\w+)(?:, (\w+))?(?:, (\w+))?>", name)
        if not m or "lookups/s" not in row:
            continue
        tracker, mode, media, _ = m.groups()
        rate = row["lookups/s"]
        if media == "Trivial":
            overhead.append([tracker, mode, f"{row['lookups/call']:.1f}", f"{rate / 1e6:.1f}",
                             f"{ns(row) / row['lookups/call']:.1f}"])
            continue
        r_tracked = rate / raw.get((mode, "tracked"), float("nan"))
        r_uniform = rate / raw.get((mode, "uniform"), float("nan"))
        r_chained = rate / raw.get((mode, "chained (latency)"), float("nan"))
        ok = "yes" if min(r_tracked, r_uniform) >= TARGET else "NO"
        rows.append([tracker, mode, f"{ns(row):.0f}", f"{row['lookups/call']:.1f}",
                     f"{rate / 1e6:.1f}", f"{ns(row) / row['lookups/call']:.1f}",
                     f"{r_tracked:.2f}", f"{r_uniform:.2f}", f"{r_chained:.2f}", ok,
                     cv(runs[name], "lookups/s")])
    title(md, f"Tracking loop vs raw lookups (target: ratio >= {TARGET})")
    table(md, ["tracker", "mode", "ns/call", "lookups/call", "M lookups/s", "ns/lookup",
               "/raw tracked", "/raw uniform", "/raw chained", f">= {TARGET}", "cv"],
          sorted(rows, key=lambda r: (r[1], r[0])))
    if overhead:
        title(md, "Diagnostic: the loop alone (homogeneous medium, same majorant and rays)")
        table(md, ["tracker", "mode", "lookups/call", "M collisions/s", "ns/collision"], sorted(overhead))

    # Estimators: one row per estimator x absorption, columns mode x set-up.
    est = {}
    for name, row in med.items():
        m = re.fullmatch(r"BM_Radiance/([\w:-]+)/([\w-]+)/(\w+)/(\w)", name)
        if m:
            est[m.groups()] = (ns(row), row.get("lookups/sample"), cv(runs[name], "cpu_time"))
    if est:
        cols = [(mode, setup) for mode in ("mono", "rgb") for setup in ("A", "B")]
        order = ["unidirectional", "ratio-nee", "directional-mis", "uni-nee-mis"]
        rank = lambda kind: order.index(kind.split(":")[0]) if kind.split(":")[0] in order else len(order)
        keys = sorted({(k[0], k[1]) for k in est}, key=lambda k: (rank(k[0]), k[0], k[1]))
        rows = []
        for kind, absorb in keys:
            r = [kind, absorb]
            for mode, setup in cols:
                v = est.get((kind, absorb, mode, setup))
                r.append(f"{v[0]:.0f} / {v[1]:.1f}" if v else "-")
            rows.append(r)
        title(md, "Path estimators: median ns per sample / density lookups per sample")
        table(md, ["estimator", "absorption"] + [f"{m} {s}" for m, s in cols], rows)

    # Cost of counting.
    rows = []
    for name, row in med.items():
        m = re.fullmatch(r"(BM_CountCost/.*)/count", name)
        if m and m.group(1) + "/no-count" in med:
            base = med[m.group(1) + "/no-count"]
            rows.append([m.group(1).removeprefix("BM_CountCost/"), f"{ns(base):.0f}", f"{ns(row):.0f}",
                         f"{ns(row) / ns(base):.3f}"])
    for name, row in med.items():
        m = re.fullmatch(r"BM_Track<(\w+), (\w+), Cloud, NoLookupCount>", name)
        counted = med.get(f"BM_Track<{m.group(1)}, {m.group(2)}>") if m else None
        if counted:
            rows.append([f"track {m.group(1)} {m.group(2)}", f"{ns(row):.0f}", f"{ns(counted):.0f}",
                         f"{ns(counted) / ns(row):.3f}"])
    if rows:
        title(md, "Cost of counting lookups (ns per call)")
        table(md, ["benchmark", "NoLookupCount", "LookupCount", "ratio"], sorted(rows))

    if not md:
        print(f"machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, load "
              f"{ctx.get('load_avg')}, library build {ctx.get('library_build_type')}; times are "
              "CPU time, medians over the repetitions")


if __name__ == "__main__":
    main()
