#!/usr/bin/env python3
"""Plots of sextant-run's globe outputs: position and rotation error over time per back-end, their NEES
at the sampled steps against the 95% bound (3 dof), the landmark pool's bookkeeping (in pool,
added, evicted per step; the thesis's Figures 22 and 25) and each back-end's time per frame.
Usage: plot_globe.py <dir with *_steps.csv>"""
import csv
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {key: [float(r[key]) for r in rows] for key in rows[0]} if rows else {}


def series_over_steps(runs, columns, ylabels, path, scale=(1.0, 1.0), log=False, bound=None):
    """Two panels sharing the step axis: columns[0] and columns[1] of every run."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for key, run in runs.items():
        for axis, column, factor in zip(axes, columns, scale):
            plot = axis.semilogy if log else axis.plot
            plot(run["step"], [factor * v for v in run[column]], label=key, linewidth=0.8)
    for axis, ylabel in zip(axes, ylabels):
        axis.set_ylabel(ylabel)
        if bound is not None:
            axis.axhline(bound, color="black", linestyle="--", linewidth=0.8, label="95% bound, 3 dof")
    axes[1].set_xlabel("step")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    directory = pathlib.Path(sys.argv[1])
    runs = {p.name[: -len("_steps.csv")]: read(p) for p in sorted(directory.glob("*_steps.csv"))}
    runs = {k: v for k, v in runs.items() if v}
    if not runs:
        sys.exit(f"{directory}: no *_steps.csv")
    series_over_steps(runs, ("position_error", "rotation_error"), ("position error [mm]", "rotation error [rad]"),
                      directory / "errors.png", scale=(1e3, 1.0))
    nees = {p.name[: -len("_nees.csv")]: read(p) for p in sorted(directory.glob("*_nees.csv"))}
    nees = {k: v for k, v in nees.items() if v}
    if nees:
        series_over_steps(nees, ("position_nees", "rotation_nees"), ("position NEES", "rotation-vector NEES"),
                          directory / "nees.png", log=True, bound=7.81)

    fig, ax = plt.subplots(figsize=(9, 4))
    for key, run in runs.items():
        if "seconds" in run:
            ax.semilogy(run["step"], [1e3 * max(v, 1e-6) for v in run["seconds"]], label=key, linewidth=0.8)
    ax.axhline(1e3 / 15, color="black", linestyle="--", linewidth=0.8, label="15 frames/s")
    ax.set_xlabel("frame")
    ax.set_ylabel("ms per frame")
    ax.set_title("time per frame (GraphSLAM: recording; its global updates are apart)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(directory / "frame_times.png", dpi=120)

    key, run = next(iter(runs.items()))
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(run["step"], run["in_pool"], label="in pool")
    ax.bar(run["step"], run["added"], label="added", color="tab:green", width=1.0)
    ax.bar(run["step"], [-e for e in run["evicted"]], label="evicted (negative)", color="tab:red", width=1.0)
    ax.set_xlabel("step")
    ax.set_ylabel("landmarks")
    ax.set_title(f"landmark pool bookkeeping ({key})")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(directory / "pool.png", dpi=120)


if __name__ == "__main__":
    main()
