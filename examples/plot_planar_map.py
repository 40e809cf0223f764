#!/usr/bin/env python3
"""Plots poses.csv and landmarks.csv written by sextant-isam (trajectory, landmarks with their
3-sigma ellipses) into a PNG. Needs python3-matplotlib (Debian).
Usage: plot_planar_map.py DIR OUTPUT.png [TITLE]"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Ellipse  # noqa: E402


def read(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def main():
    folder, output = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else "GraphSLAM"
    poses, landmarks = read(f"{folder}/poses.csv"), read(f"{folder}/landmarks.csv")
    fig, ax = plt.subplots(figsize=(9, 8), dpi=110)
    ax.plot([p["x"] for p in poses], [p["y"] for p in poses], lw=0.6, color="tab:blue", label=f"trajectory ({len(poses)} poses)")
    ax.scatter([l["x"] for l in landmarks], [l["y"] for l in landmarks], s=10, color="tab:red", zorder=3,
               label=f"landmarks ({len(landmarks)}), 3-sigma ellipses")
    for l in landmarks:
        a, b, c = l["var_x"], l["cov_xy"], l["var_y"]
        half_trace, root = (a + c) / 2, math.sqrt(((a - c) / 2) ** 2 + b * b)
        major, minor = math.sqrt(max(half_trace + root, 0)), math.sqrt(max(half_trace - root, 0))
        angle = math.degrees(0.5 * math.atan2(2 * b, a - c))
        ax.add_patch(Ellipse((l["x"], l["y"]), 6 * major, 6 * minor, angle=angle, fill=False, color="tab:red", lw=0.5))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    ax.legend(loc="best")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(output)
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
