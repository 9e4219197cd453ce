#!/usr/bin/env python3
"""Summarises the Google Benchmark JSON files written by nsp_bench (bench/run.sh).

Prints, from the median aggregates of one run: raw lookup rates; the tracking loop's lookup rate
and its ratio to the raw rate (the target is >= 0.7); time and density lookups per sample of
every grey path estimator; the cost of counting lookups; time and lookups per sample of every
spectral path estimator on the chromatic scene; and what each spectral mode costs on the grey
cloud against Mono. With --ab DIR it also prints the two before/after Mono tables: time, from
the pairs old-<round>-<i>.json / new-<round>-<i>.json in DIR (one benchmark, one repetition
each, run back to back), and work, from work-{old,new}.txt and ir-{old,new}.txt
(bench/work_count.cpp under callgrind).
With --markdown the tables are Markdown.
Usage: report.py results.json [--ab DIR] [--markdown]
"""
import glob
import json
import os
import re
import statistics
import sys

TARGET = 0.7
MODE_ORDER = {"Mono": 0, "Rgb": 1, "Hero4": 2, "mono": 0, "rgb": 1, "hero": 2}
MODE_LABEL = {"Mono": "Mono", "Rgb": "Rgb", "Hero4": "Hero<4>"}
TRACKERS = ["DeltaEvent", "DeltaWeight", "RatioPlain", "RatioNullEvent", "RatioNullWeight"]


def run_name(b):
    return re.sub(r"/min_time:[0-9.]+", "", b["run_name"])


def load(path):
    """median and cv aggregates by run name: {name: {"median": row, "cv": row}}."""
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data["benchmarks"]:
        name = run_name(b)
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


def lookups(row):
    """Density lookups per iteration (per call or per sample), or None."""
    for key in ("lookups/call", "lookups/sample"):
        if key in row:
            return row[key]
    return None


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


def note(text):
    if text:
        print(text)
        print()


def cv_summary(runs, names):
    """'cv of CPU time over the repetitions: median x%, max y% (name)' over the given runs."""
    vals = [(runs[n]["cv"]["cpu_time"], n) for n in names if "cv" in runs[n] and "cpu_time" in runs[n]["cv"]]
    if not vals:
        return ""
    worst = max(vals)
    return (f"cv of CPU time over the repetitions: median {100 * statistics.median(v for v, _ in vals):.1f}%, "
            f"max {100 * worst[0]:.1f}% ({worst[1]})")


def report_raw_and_tracking(md, runs, med):
    raw = {}
    rows = []
    for name, row in med.items():
        m = re.fullmatch(r"BM_RawLookup(Chained)?<(\w+)(?:, (\w+))?>", name)
        if not m:
            continue
        chained, mode, points = m.groups()
        kind = "chained (latency)" if chained else points.replace("Points", "").lower()
        raw[(mode, kind)] = row["lookups/s"]
        rows.append([MODE_LABEL.get(mode, mode), kind, f"{row['lookups/s'] / 1e6:.1f}",
                     f"{ns(row) / (1 << 14):.1f}", cv(runs[name], "lookups/s"), MODE_ORDER.get(mode, 9)])
    if rows:
        title(md, "Raw trilinear lookups on the default cloud grid (64^3 floats, 1 MiB)")
        rows.sort(key=lambda r: (r[-1], r[1]))
        table(md, ["mode", "points", "M lookups/s", "ns/lookup", "cv"], [r[:-1] for r in rows])

    rows = []
    overhead = []
    for name, row in med.items():
        m = re.fullmatch(r"BM_Track<(\w+), (\w+)(?:, (\w+))?(?:, (\w+))?>", name)
        if not m or "lookups/s" not in row:
            continue
        tracker, mode, media, _ = m.groups()
        rate = row["lookups/s"]
        if media == "Trivial":
            overhead.append([tracker, MODE_LABEL.get(mode, mode), f"{row['lookups/call']:.1f}",
                             f"{rate / 1e6:.1f}", f"{ns(row) / row['lookups/call']:.1f}"])
            continue
        grid = re.fullmatch(r"CloudGrid(\d+)", media or "")
        majorant = f"grid {grid.group(1)}" if grid else "global"
        steps = f"{row['steps/call']:.1f}" if "steps/call" in row else "-"
        r_tracked = rate / raw.get((mode, "tracked"), float("nan"))
        r_uniform = rate / raw.get((mode, "uniform"), float("nan"))
        r_chained = rate / raw.get((mode, "chained (latency)"), float("nan"))
        ok = "yes" if min(r_tracked, r_uniform) >= TARGET else "NO"
        rows.append([tracker, MODE_LABEL.get(mode, mode), majorant, f"{ns(row):.0f}", f"{row['lookups/call']:.1f}", steps,
                     f"{rate / 1e6:.1f}", f"{ns(row) / row['lookups/call']:.1f}",
                     f"{r_tracked:.2f}", f"{r_uniform:.2f}", f"{r_chained:.2f}", ok,
                     cv(runs[name], "lookups/s"), (MODE_ORDER.get(mode, 9), tracker, int(grid.group(1)) if grid else 0)])
    if rows:
        title(md, f"Tracking loop vs raw lookups (target: ratio >= {TARGET})")
        rows.sort(key=lambda r: r[-1])
        table(md, ["tracker", "mode", "majorant", "ns/call", "lookups/call", "DDA steps/call", "M lookups/s", "ns/lookup",
                   "/raw tracked", "/raw uniform", "/raw chained", f">= {TARGET}", "cv"], [r[:-1] for r in rows])
    if overhead:
        title(md, "Diagnostic: the loop alone (homogeneous medium, same majorant and rays)")
        table(md, ["tracker", "mode", "lookups/call", "M collisions/s", "ns/collision"], sorted(overhead))


def report_grey_estimators(md, runs, med):
    est = {}
    for name, row in med.items():
        m = re.fullmatch(r"BM_Radiance/([\w:-]+)/([\w-]+)/(\w+)/(\w)", name)
        if m:
            est[m.groups()] = (ns(row), row.get("lookups/sample"))
    if not est:
        return
    modes = sorted({k[2] for k in est}, key=lambda m: MODE_ORDER.get(m, 9))
    cols = [(mode, setup) for mode in modes for setup in ("A", "B")]
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
    title(md, "Path estimators (grey cloud): median ns per sample / density lookups per sample")
    table(md, ["estimator", "absorption"] + [f"{m} {s}" for m, s in cols], rows)


def report_count_cost(md, med):
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


def report_spectral(md, runs, med):
    spec = {}
    for name, row in med.items():
        m = re.fullmatch(r"BM_Spectral/([\w-]+)/([\w:-]+)/(\w+)/(C\d)", name)
        if m:
            spec[m.groups()] = (ns(row), row.get("lookups/sample"), name)
    if not spec:
        return
    policies = ["independent", "spectral-tracking-max", "spectral-tracking-avg", "spectral-mis", "grey-majorant"]
    strategies = ["unidirectional", "ratio-nee", "uni-nee-mis:balance"]
    majorant = {"independent": "per channel", "spectral-mis": "per channel"}
    cols = [("rgb", "C1"), ("rgb", "C2"), ("hero", "C1"), ("hero", "C2")]
    keys = sorted({(k[0], k[1]) for k in spec},
                  key=lambda k: (policies.index(k[0]) if k[0] in policies else 9,
                                 strategies.index(k[1]) if k[1] in strategies else 9))
    rows = []
    for pol, st in keys:
        r = [pol, st, majorant.get(pol, "grey")]
        for mode, scene in cols:
            v = spec.get((pol, st, mode, scene))
            r.append(f"{v[0]:.0f} / {v[1]:.1f}" if v else "-")
        rows.append(r)
    title(md, "Spectral path estimators, chromatic scene (absorb-weight): median ns per sample / "
              "density lookups per sample")
    table(md, ["channel policy", "strategy", "majorant"] + [f"{m} {s}" for m, s in cols], rows)
    note(cv_summary(runs, [v[2] for v in spec.values()]))


def report_mode_cost(md, runs, med):
    """Each spectral mode on the grey cloud against Mono, same run."""
    modes = [("Mono", "mono"), ("Rgb", "rgb"), ("Hero4", "hero")]
    rows = []
    names = []

    def add(label, unit, cells, div=1.0):
        # cells: one (run name or None) per mode in `modes`; the first is the reference.
        vals = [med.get(n) if n else None for n in cells]
        if vals[0] is None and all(v is None for v in vals):
            return
        names.extend(n for n, v in zip(cells, vals) if v is not None)
        ref = ns(vals[0]) / div if vals[0] is not None else None
        r = [label, unit]
        digits = 1 if div != 1.0 else 0
        for v in vals:
            r.append(f"{ns(v) / div:.{digits}f}" if v else "-")
        for v in vals[1:]:
            r.append(f"{ns(v) / div / ref:.2f}" if v and ref else "-")
        lk = [lookups(v) if v else None for v in vals]
        r.append(" / ".join(f"{x:.1f}" if x is not None else "-" for x in lk) if any(x is not None for x in lk) else "-")
        rows.append(r)

    add("raw lookups, tracked points", "ns/lookup", [f"BM_RawLookup<{m}, TrackedPoints>" for m, _ in modes], 1 << 14)
    for t in TRACKERS:
        add(f"track {t}", "ns/call", [f"BM_Track<{t}, {m}>" for m, _ in modes])
    for kind in ("unidirectional", "ratio-nee", "uni-nee-mis:balance"):
        for setup in ("A", "B"):
            add(f"PathEstimator {kind} {setup}", "ns/sample",
                [f"BM_Radiance/{kind}/absorb-weight/{m}/{setup}" for _, m in modes])
    for setup in ("A", "B"):
        # Mono column: the grey Mono estimator of the same strategy (spectral MIS needs channels).
        add(f"SpectralPathEstimator spectral-mis uni-nee-mis:balance {setup} (Mono: PathEstimator)", "ns/sample",
            [f"BM_Radiance/uni-nee-mis:balance/absorb-weight/mono/{setup}"] +
            [f"BM_Spectral/spectral-mis/uni-nee-mis:balance/{m}/{setup}" for _, m in modes[1:]])
    if rows:
        title(md, "Cost of each spectral mode on the grey cloud (absorb-weight), medians of one run")
        table(md, ["benchmark", "unit", "Mono", "Rgb", "Hero<4>", "Rgb/Mono", "Hero/Mono",
                   "lookups mono / rgb / hero"], rows)
        note(cv_summary(runs, names))


def report_ab(md, directory):
    """Step 2: before/after in time, from pairs of runs (old-<round>-<i>.json, new-<round>-<i>.json)."""
    pairs = {}  # name -> [(old ns, new ns)]
    work = {}   # (side, name) -> [lookups per iteration]
    for path in sorted(glob.glob(os.path.join(directory, "old-*-*.json"))):
        other = path.replace(os.sep + "old-", os.sep + "new-")
        if not os.path.exists(other):
            continue
        rows = {}
        for side, p in (("old", path), ("new", other)):
            with open(p) as f:
                data = json.load(f)
            it = [b for b in data["benchmarks"] if b.get("run_type", "iteration") == "iteration"]
            if len(it) == 1:
                rows[side] = it[0]
        if len(rows) != 2 or run_name(rows["old"]) != run_name(rows["new"]):
            continue
        name = run_name(rows["old"])
        pairs.setdefault(name, []).append((ns(rows["old"]), ns(rows["new"])))
        for side in ("old", "new"):
            if lookups(rows[side]) is not None:
                work.setdefault((side, name), []).append(lookups(rows[side]))
    if not pairs:
        return
    rows, ratios = [], []
    n_pairs = min(len(v) for v in pairs.values())
    for name in sorted(pairs):
        old = statistics.median(o for o, _ in pairs[name])
        new = statistics.median(n for _, n in pairs[name])
        rr = sorted(n / o for o, n in pairs[name])
        ratio = statistics.median(rr)
        ratios.append(ratio)
        lo, ln = work.get(("old", name)), work.get(("new", name))
        lk = f"{statistics.median(lo):.2f} / {statistics.median(ln):.2f}" if lo and ln else "-"
        rows.append([name.removeprefix("BM_"), f"{old:.0f}", f"{new:.0f}", f"{ratio:.3f}",
                     f"{rr[0]:.2f} - {rr[-1]:.2f}", lk])
    title(md, f"Before/after, Mono, time: ns per call or sample, medians over {n_pairs} back-to-back pairs "
              "(old and new binary on the same benchmark)")
    table(md, ["benchmark", "before", "after", "after/before (median of pairs)", "pair ratios min - max",
               "lookups before / after"], rows)
    note(f"after/before over the {len(ratios)} benchmarks: geometric mean {statistics.geometric_mean(ratios):.3f}, "
         f"median {statistics.median(ratios):.3f}, min {min(ratios):.3f}, max {max(ratios):.3f}")


def read_lines(path):
    """{first field: remaining fields} of a whitespace-separated text file, or {}."""
    if not os.path.exists(path):
        return {}
    with open(path) as f:
        return {p[0]: p[1:] for p in (line.split() for line in f) if p}


def report_work(md, directory):
    """Step 3: bench/work_count.cpp before and after, instructions per call under callgrind."""
    work = {side: read_lines(os.path.join(directory, f"work-{side}.txt")) for side in ("old", "new")}
    ir = {side: read_lines(os.path.join(directory, f"ir-{side}.txt")) for side in ("old", "new")}
    if not work["old"] or not work["new"]:
        return
    rows, ratios, differ = [], [], []
    for name, (calls, lk, checksum) in work["new"].items():
        old = work["old"].get(name)
        same = old is not None and old == [calls, lk, checksum]
        if not same:
            differ.append(name)
        r = [name, calls, f"{int(lk) / int(calls):.2f}", "yes" if same else "NO"]
        if name in ir["old"] and name in ir["new"]:
            i_old = int(ir["old"][name][0]) / int(calls)
            i_new = int(ir["new"][name][0]) / int(calls)
            ratios.append(i_new / i_old)
            r += [f"{i_old:.0f}", f"{i_new:.0f}", f"{i_new / i_old:.4f}"]
        else:
            r += ["-", "-", "-"]
        rows.append(r)
    title(md, "Before/after, Mono: work (bench/work_count.cpp, fixed seeds and call counts; "
              "instructions per call counted by callgrind)")
    table(md, ["kernel", "calls", "lookups/call", "same lookups and checksum", "instructions before",
               "instructions after", "after/before"], rows)
    if ratios:
        note(f"after/before instructions over the {len(ratios)} kernels: min {min(ratios):.4f}, "
             f"max {max(ratios):.4f}; kernels whose results differ: {', '.join(differ) or 'none'}")


def main():
    argv = sys.argv[1:]
    md = "--markdown" in argv
    ab = None
    if "--ab" in argv:
        i = argv.index("--ab")
        if i + 1 >= len(argv):
            sys.exit(__doc__)
        ab = argv[i + 1]
        del argv[i:i + 2]
    args = [a for a in argv if not a.startswith("--")]
    if len(args) != 1:
        sys.exit(__doc__)
    ctx, runs = load(args[0])
    med = {name: e["median"] for name, e in runs.items() if "median" in e}

    report_raw_and_tracking(md, runs, med)
    report_grey_estimators(md, runs, med)
    report_count_cost(md, med)
    report_spectral(md, runs, med)
    report_mode_cost(md, runs, med)
    if ab:
        report_ab(md, ab)
        report_work(md, ab)

    if not md:
        print(f"code: {ctx.get('code', '?')}; machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, "
              f"load {ctx.get('load_avg')}, library build {ctx.get('library_build_type')}; times are "
              "CPU time, medians over the repetitions")


if __name__ == "__main__":
    main()
