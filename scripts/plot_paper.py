#!/usr/bin/python3
# proxima: plots of the paper experiments (bench/paper_experiments) in the style of the paper's figures.
# SPDX-License-Identifier: BSD-3-Clause
#
# Usage: /usr/bin/python3 scripts/plot_paper.py OUT_DIR
# Reads the CSV files that bench/paper_experiments wrote into OUT_DIR and writes PNG
# files next to them. Run it with Debian's interpreter: the python3 first on
# PATH on these machines does not see python3-matplotlib.
#
#   fig1_enhanced_gjk.png  paper fig. 1: Enhanced GJK, time per query against
#                          the vertex count, without (solid) and with (dashed)
#                          tracking, linear axes as in the paper
#   fig2_hybrid.png        paper fig. 2: the same for the hybrid
#   fig12_all_systems.png  the translation experiment for every system, log-log
#   fig3_rotation.png      paper fig. 3: time per query against the rotational
#                          speed, tracking where the system has it
#   cold.png               cold queries against the vertex count, log-log
#   overlap.png            the signed distance through contact (B sweeping
#                          through A), against the vertex count, log-log
#   robustness.png         answers within the accuracy standard, per system
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import ticker  # noqa: E402

# One colour per system, the same in every figure.
COLOURS = {
    "proxima hybrid": "#d62728",
    "proxima Enhanced GJK": "#1f77b4",
    "proxima GJK": "#17becf",
    "FCL libccd": "#2ca02c",
    "FCL libccd scaled": "#8c564b",
    "FCL GJK": "#9467bd",
    "Bullet GJK": "#ff7f0e",
    "FCL libccd signed": "#bcbd22",
}
ORDER = list(COLOURS)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def series(rows, x_key, system, tracking):
    """(x, median us) of one configuration, sorted by x."""
    pts = sorted(
        (float(r[x_key]), float(r["median_ns"]) / 1000.0)
        for r in rows
        if r["system"] == system and r["tracking"] == ("1" if tracking else "0")
    )
    return [p[0] for p in pts], [p[1] for p in pts]


def configurations(rows):
    seen = []
    for r in rows:
        key = (r["system"], r["tracking"] == "1")
        if key not in seen:
            seen.append(key)
    return sorted(seen, key=lambda k: (ORDER.index(k[0]) if k[0] in ORDER else 99, not k[1]))


def paper_figure(rows, system, title, path):
    fig, ax = plt.subplots(figsize=(6, 4.2))
    x, y = series(rows, "n", system, False)
    ax.plot(x, y, "k-", marker="o", ms=3, label="without tracking")
    x, y = series(rows, "n", system, True)
    ax.plot(x, y, "k--", marker="s", ms=3, label="with tracking")
    ax.set_xlabel("number of vertices per body")
    ax.set_ylabel("time per query (µs)")
    ax.set_title(title, fontsize=10)
    ax.set_ylim(bottom=0)
    ax.set_xlim(left=0)
    ax.legend(frameon=False)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def systems_figure(rows, x_key, xlabel, title, path, logx=True):
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for system, tracking in configurations(rows):
        x, y = series(rows, x_key, system, tracking)
        ax.plot(
            x,
            y,
            linestyle="--" if tracking else "-",
            marker="s" if tracking else "o",
            ms=3,
            color=COLOURS.get(system, "grey"),
            label=system + (" (tracking)" if tracking else ""),
        )
    if logx:
        ax.set_xscale("log", base=2 if x_key == "n" else 10)
    ax.set_yscale("log")
    # Labels at 1, 2, 5 per decade: the log axis spans few decades.
    ax.yaxis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda y, _: f"{y:g}"))
    ax.yaxis.set_minor_formatter(ticker.NullFormatter())
    if not logx or x_key == "n":
        ax.xaxis.set_major_formatter(ticker.FuncFormatter(lambda x, _: f"{x:g}"))
    ax.set_xlabel(xlabel)
    ax.set_ylabel("time per query (µs, median)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, frameon=False, loc="center left", bbox_to_anchor=(1.0, 0.5))
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def robustness_figure(rows, path):
    experiments = []
    for r in rows:
        if r["experiment"] not in experiments:
            experiments.append(r["experiment"])
    systems = [s for s in ORDER if any(r["system"] == s for r in rows)]
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    width = 0.8 / max(1, len(experiments))
    for k, e in enumerate(experiments):
        values = []
        for s in systems:
            r = next(r for r in rows if r["experiment"] == e and r["system"] == s)
            cases = int(r["cases"])
            values.append(100.0 * int(r["within_standard"]) / cases if cases else 0.0)
        xs = [i + (k - (len(experiments) - 1) / 2) * width for i in range(len(systems))]
        bars = ax.bar(xs, values, width, label=e, color=["#444444", "#aaaaaa"][k % 2])
        for b, v in zip(bars, values):
            ax.text(b.get_x() + b.get_width() / 2, v + 1, f"{v:.0f}", ha="center", fontsize=7)
    ax.set_xticks(range(len(systems)))
    ax.set_xticklabels([s.replace("proxima ", "proxima\n") for s in systems], fontsize=8)
    ax.set_ylabel("answers within the accuracy standard (%)")
    ax.set_ylim(0, 110)
    ax.set_title("Robustness: paper section 6, experiments 1 and 2 (exact reference)", fontsize=10)
    ax.legend(frameon=False, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        print("usage: plot_paper.py OUT_DIR", file=sys.stderr)
        return 2
    out = sys.argv[1]
    translation = read_csv(os.path.join(out, "translation.csv"))
    rotation = read_csv(os.path.join(out, "rotation.csv"))
    cold = read_csv(os.path.join(out, "cold.csv"))
    robustness = read_csv(os.path.join(out, "robustness.csv"))

    paper_figure(
        translation,
        "proxima Enhanced GJK",
        "Fig. 1: Enhanced GJK, continuous translation,\nwith (dashed) and without (solid) tracking",
        os.path.join(out, "fig1_enhanced_gjk.png"),
    )
    paper_figure(
        translation,
        "proxima hybrid",
        "Fig. 2: hybrid (the paper's algorithm), continuous translation,\nwith (dashed) and without (solid) tracking",
        os.path.join(out, "fig2_hybrid.png"),
    )
    systems_figure(
        translation,
        "n",
        "number of vertices per body",
        "Figs. 1-2 setup, every system: continuous translation (dashed: with tracking)",
        os.path.join(out, "fig12_all_systems.png"),
    )
    systems_figure(
        rotation,
        "omega",
        "rotational speed (rad per step)",
        "Fig. 3: bodies of 50 points, one rotating (tracking where the system has it)",
        os.path.join(out, "fig3_rotation.png"),
    )
    systems_figure(
        cold,
        "n",
        "number of vertices per body",
        "Cold queries: random poses, no coherence",
        os.path.join(out, "cold.png"),
    )
    systems_figure(
        read_csv(os.path.join(out, "overlap.csv")),
        "n",
        "number of vertices per body",
        "Signed distance through contact: B sweeps through A (dashed: with tracking)",
        os.path.join(out, "overlap.png"),
    )
    robustness_figure(robustness, os.path.join(out, "robustness.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
