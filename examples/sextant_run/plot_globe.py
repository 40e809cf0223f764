#!/usr/bin/env python3
"""Plots of sextant-run's globe outputs: position and rotation error over time per back-end, and the
landmark pool's bookkeeping (in pool, added, evicted per step; the thesis's Figures 22 and 25).
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


def main():
    directory = pathlib.Path(sys.argv[1])
    runs = {p.name[: -len("_steps.csv")]: read(p) for p in sorted(directory.glob("*_steps.csv"))}
    runs = {k: v for k, v in runs.items() if v}
    if not runs:
        sys.exit(f"{directory}: no *_steps.csv")
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for key, run in runs.items():
        top.plot(run["step"], [1e3 * e for e in run["position_error"]], label=key, linewidth=0.8)
        bottom.plot(run["step"], run["rotation_error"], label=key, linewidth=0.8)
    top.set_ylabel("position error [mm]")
    bottom.set_ylabel("rotation error [rad]")
    bottom.set_xlabel("step")
    top.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(directory / "errors.png", dpi=120)

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
