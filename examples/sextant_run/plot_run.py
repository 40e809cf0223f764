#!/usr/bin/env python3
"""Plots of one data set's runs written by `sextant-run --out DIR`, like the thesis's Figures 16-18:
for every back-end, <key>_map.png (estimated and true trajectory, estimated landmarks with their
95% covariance ellipses, true landmarks) and <key>_errors.png (position error and pose NEES over
time with the 95% chi-square bound). Usage: plot_run.py DIR [UNIT]"""
import csv
import math
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Ellipse  # noqa: E402

CHI2_2DOF_95 = 5.991  # ellipse scale for a 95% region of a 2D Gaussian


def read_csv(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def read_tum(path):
    rows = []
    with open(path) as f:
        for line in f:
            values = line.split()
            if len(values) >= 4:
                rows.append((float(values[1]), float(values[2])))
    return rows


def ellipse(row):
    a, b, c = row["cov_xx"], row["cov_xy"], row["cov_yy"]
    half_trace, root = (a + c) / 2, math.sqrt(max(((a - c) / 2) ** 2 + b * b, 0.0))
    l1, l2 = half_trace + root, max(half_trace - root, 0.0)
    angle = math.degrees(0.5 * math.atan2(2 * b, a - c))
    scale = 2 * math.sqrt(CHI2_2DOF_95)
    return Ellipse((row["x"], row["y"]), scale * math.sqrt(l1), scale * math.sqrt(l2), angle=angle,
                   fill=False, color="tab:blue", linewidth=0.8)


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_map(directory, key, steps, landmarks, truth, unit):
    fig, ax = plt.subplots(figsize=(8, 7))
    if truth:
        ax.plot([p[0] for p in truth], [p[1] for p in truth], color="black", linewidth=1.0, label="true trajectory")
    ax.plot([s["x"] for s in steps], [s["y"] for s in steps], color="tab:red", linewidth=1.0,
            label="estimated trajectory")
    known = [l for l in landmarks if math.isfinite(l["true_x"])]  # none without ground truth
    if known:
        ax.scatter([l["true_x"] for l in known], [l["true_y"] for l in known], marker="+", color="tab:green",
                   s=40, label="true landmarks", zorder=3)
    ax.scatter([l["x"] for l in landmarks], [l["y"] for l in landmarks], marker=".", color="tab:blue", s=20,
               label="estimated landmarks (95% ellipses)", zorder=3)
    for l in landmarks:
        ax.add_patch(ellipse(l))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_title(f"{directory.name}: {key} — trajectory and map")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return save(fig, directory / f"{key}_map.png")


def plot_errors(directory, key, steps, unit):
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    k = [s["step"] for s in steps]
    top.plot(k, [s["pose_error"] for s in steps], color="tab:red", linewidth=1.0)
    top.set_ylabel(f"position error [{unit}]")
    top.grid(True, alpha=0.3)
    top.set_title(f"{directory.name}: {key} — error and consistency over time")
    nees = [min(s["pose_nees"], 1e12) for s in steps]
    bottom.semilogy(k, nees, color="tab:blue", linewidth=1.0, label="pose NEES")
    bottom.axhline(steps[0]["nees_bound_95"], color="black", linestyle="--", linewidth=1.0,
                   label="95% chi-square bound")
    bottom.set_xlabel("step")
    bottom.set_ylabel("NEES")
    bottom.grid(True, alpha=0.3, which="both")
    bottom.legend(loc="best", fontsize=8)
    return save(fig, directory / f"{key}_errors.png")


def main():
    directory = pathlib.Path(sys.argv[1])
    unit = sys.argv[2] if len(sys.argv) > 2 else "m"
    truth_path = directory / "ground_truth.tum"
    truth = read_tum(truth_path) if truth_path.exists() else []
    step_files = sorted(directory.glob("*_steps.csv"))
    if not step_files:
        sys.exit(f"{directory}: no *_steps.csv files")
    for step_file in step_files:
        key = step_file.name[: -len("_steps.csv")]
        steps = read_csv(step_file)
        landmarks = read_csv(directory / f"{key}_map.csv")
        plot_map(directory, key, steps, landmarks, truth, unit)
        plot_errors(directory, key, steps, unit)


if __name__ == "__main__":
    main()
