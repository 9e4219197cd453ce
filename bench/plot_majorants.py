#!/usr/bin/env python3
"""Plots and tabulates the majorant sweep (bench/bench_majorants.cpp, bench/run_majorants.sh).

Reads the Google Benchmark JSON (median aggregates of the repetitions; the sweep's counters are
the same in every repetition, its times are medians) and writes ONE PNG with four panels:
  1. ns x variance per sample against grid resolution, grey cloud and sparse medium; the global
     majorant as a horizontal line, the non-bounding choices (grid 16 at scale 0.5 under Signed
     and Clamp) as markers at 16;
  2. density lookups per sample, same rows;
  3. RMSE against the reference at equal render time (the time the global majorant takes for
     the sweep's spp), grid rows and the non-bounding choices, global as a horizontal line;
  4. ns x variance per sample of spectral MIS on the chromatic media, ChannelGridMajorant
     against resolution, ChannelMajorant as a horizontal line.
With --markdown it prints the tables of bench/RESULTS.md instead of (or besides) plotting.
Usage: plot_majorants.py majorants.json [out.png] [--markdown]
"""
import json
import math
import re
import sys

PASSES = 256  # samples per pixel of a sweep row (bench_majorants.cpp kPasses)


def load(path):
    """{(family, medium, label): median row}, from aggregates or single runs."""
    with open(path) as f:
        data = json.load(f)
    rows = {}
    for b in data["benchmarks"]:
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        name = re.sub(r"/(iterations|repeats|min_time):[0-9.]+", "", b["run_name"])
        parts = name.split("/")
        if len(parts) == 3:
            rows[tuple(parts)] = b
    return data.get("context", {}), rows


def ns_cpu(b):
    return b["cpu_time"] * {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]]


def resolution(label):
    m = re.fullmatch(r"(?:channel-)?grid(\d+)", label)
    return int(m.group(1)) if m else None


def rmse_equal_time(b, ns_global):
    """RMSE after the time the global majorant takes for PASSES spp: bias^2 + var / n_equal."""
    n_eq = PASSES * ns_global / b["ns/sample"]
    return math.sqrt(max(b.get("bias2", 0.0), 0.0) + b["var"] / n_eq)


MEDIA = ["cloud", "sparse"]
GREY_ORDER = ["global"] + [f"grid{r}" for r in (1, 4, 8, 16, 32, 64)] + [
    "grid16x0.5-signed", "grid16x0.5-clamp", "global-mean-signed", "global-mean-clamp"]
CHROMA_ORDER = ["channel-global"] + [f"channel-grid{r}" for r in (1, 4, 8, 16, 32, 64)]


def fmt(x, digits=3):
    if x == 0:
        return "0"
    if abs(x) >= 1e5:
        return f"{x:.2e}"
    if abs(x) >= 1000:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def markdown(rows):
    for family, order, title in (("BM_Majorant", GREY_ORDER, "Grey media (Mono, set-up B), PathEstimator uni-nee-mis:balance"),
                                 ("BM_ChannelMajorant", CHROMA_ORDER, "Chromatic media (Rgb, C1), SpectralPathEstimator spectral MIS + NEE")):
        grey = family == "BM_Majorant"
        print(f"**{title}; medians of CPU time, {PASSES} spp of a 32x32 image per row**")
        print()
        head = ["medium", "majorant", "lookups/sample", "null/sample", "real/sample", "ratio stops/sample",
                "DDA steps/sample", "ns/sample",
                "var", "LTUV", "ns x var", "lookups vs global", "ns x var vs global"]
        if grey:
            head += ["RMSE at equal time", "bias^2", "mean z", "bad/sample"]
        else:
            head += ["image mean (z vs channel-global)"]
        print("| " + " | ".join(head) + " |")
        print("|" + "|".join("---" for _ in head) + "|")
        for medium in MEDIA:
            base = rows.get((family, medium, order[0]))
            if not base:
                continue
            for label in order:
                b = rows.get((family, medium, label))
                if not b:
                    continue
                r = [medium, label, fmt(b["lookups/sample"]), fmt(b["null/sample"]), fmt(b["real/sample"]),
                     fmt(b["ratio_stops/sample"]), fmt(b["steps/sample"]), f"{b['ns/sample']:.0f}", fmt(b["var"]), fmt(b["LTUV"]),
                     fmt(b["ns*var"]), f"{b['lookups/sample'] / base['lookups/sample']:.3f}",
                     fmt(b["ns*var"] / base["ns*var"])]
                if grey:
                    rm = rmse_equal_time(b, base['ns/sample'])
                    r += [f"{rm:.4f}" if rm < 100 else fmt(rm), f"{b['bias2']:.2e}", f"{b['mean_z']:.1f}",
                          fmt(b["bad/sample"])]
                else:
                    z = (b["img_mean"] - base["img_mean"]) / math.hypot(b["img_mean_se"], base["img_mean_se"]) \
                        if label != order[0] else 0.0
                    r += [f"{b['img_mean']:.4f} ({z:+.1f})"]
                print("| " + " | ".join(r) + " |")
        print()
        checks = [rows[(family, m, l)]["lookups_check"] for m in MEDIA for l in order if (family, m, l) in rows]
        unclassified = sum(rows[(family, m, l)]["unclassified"] for m in MEDIA for l in order if (family, m, l) in rows)
        print(f"Counting pass saw the timed pass's lookups in {int(sum(checks))} of {len(checks)} rows; "
              f"unclassified stopped flights: {int(unclassified)}.")
        print()
    print("**Building a grid majorant (GridMajorant<DenseGridMedium<Mono>>), median CPU time**")
    print()
    print("| medium | cells per axis | cells | memory_bytes | build time (us) |")
    print("|---|---|---|---|---|")
    for medium in MEDIA:
        for r in (1, 4, 8, 16, 32, 64):
            b = rows.get(("BM_MajorantBuild", medium, str(r)))
            if b:
                print(f"| {medium} | {r} | {b['cells']:.0f} | {b['memory_bytes']:.0f} | {ns_cpu(b) / 1e3:.1f} |")
    print()


def plot(rows, out, context):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"cloud": "tab:blue", "sparse": "tab:orange"}
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    panels = [(axes[0][0], "BM_Majorant", "ns*var", "ns x variance per sample (grey, set-up B)"),
              (axes[0][1], "BM_Majorant", "lookups/sample", "density lookups per sample (grey)"),
              (axes[1][0], "BM_Majorant", "rmse_eq", "RMSE vs reference at equal time (grey)"),
              (axes[1][1], "BM_ChannelMajorant", "ns*var", "ns x variance per sample (chromatic, spectral MIS)")]
    for ax, family, key, title in panels:
        # y range from the bounding majorants; a non-bounding choice far outside it (Signed's
        # variance explodes) is drawn at the top edge with its value written beside it.
        bounded = []
        for (f, m, l), b in rows.items():
            glob = rows.get((f, m, "global"))
            if f == family and not l.startswith("grid16x") and not l.startswith("global-mean"):
                bounded.append(rmse_equal_time(b, glob["ns/sample"]) if key == "rmse_eq" else b[key])
        lo, hi = min(bounded) / 3, max(bounded) * 3
        for (f, m, l), b in rows.items():
            if f == family and l in ("grid16x0.5-clamp",):
                glob = rows[(f, m, "global")]
                v = rmse_equal_time(b, glob["ns/sample"]) if key == "rmse_eq" else b[key]
                lo, hi = min(lo, v / 3), max(hi, v * 3)
        for medium in MEDIA:
            glob = rows.get((family, medium, "global" if family == "BM_Majorant" else "channel-global"))
            if not glob:
                continue
            value = (lambda b: rmse_equal_time(b, glob["ns/sample"])) if key == "rmse_eq" else (lambda b: b[key])
            pts = sorted((resolution(l), value(b)) for (f, m, l), b in rows.items()
                         if f == family and m == medium and resolution(l))
            c = colours[medium]
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=c, label=f"{medium}: grid")
            ax.axhline(value(glob), color=c, ls="--", label=f"{medium}: global")
            if family == "BM_Majorant":
                for label, marker in (("grid16x0.5-signed", "^"), ("grid16x0.5-clamp", "s")):
                    b = rows.get((family, medium, label))
                    if b:
                        v = value(b)
                        shown = min(v, hi / 1.5)
                        ax.plot([16], [shown], marker, color=c, ms=9, mfc="none",
                                label=f"{medium}: grid 16 x 0.5, {label.split('-')[1]}")
                        if v > hi:
                            ax.annotate(f"{v:.1e} (off scale)", (16, shown), textcoords="offset points",
                                        xytext=(8, -4 if medium == "cloud" else -14), fontsize=7, color=c)
        ax.set_ylim(lo, hi)
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xticks([1, 4, 8, 16, 32, 64])
        ax.set_xticklabels(["1", "4", "8", "16", "32", "64"])
        ax.set_xlabel("grid majorant cells per axis")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left" if key == "rmse_eq" else "lower left")
    fig.suptitle(f"nsp majorant sweep ({context.get('code', '?')}): lower is better; dashed = global majorant",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    if not args:
        print(__doc__)
        return 2
    context, rows = load(args[0])
    if "--markdown" in argv:
        markdown(rows)
    if len(args) > 1:
        plot(rows, args[1], context)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
