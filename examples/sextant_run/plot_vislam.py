#!/usr/bin/env python3
"""Top view of sextant-vislam's outputs, like seed 004's Fig. 2: every trajectory (*_trajectory.tum,
reference.tum) in the x-y plane and each back-end's landmark map (*_map.csv); one PNG per back-end
with a map and one with all trajectories.
Usage: plot_vislam.py <dir>"""
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from plot_run import read_csv, read_tum  # noqa: E402  (sextant-run's plot script, copied beside this one)


def trajectory_xy(path):
    """A TUM trajectory as two lists, x and y."""
    points = read_tum(path)
    return [p[0] for p in points], [p[1] for p in points]


def main(directory):
    trajectories = {os.path.basename(p)[: -len("_trajectory.tum")]: trajectory_xy(p)
                    for p in sorted(glob.glob(os.path.join(directory, "*_trajectory.tum")))}
    reference = os.path.join(directory, "reference.tum")
    ref = trajectory_xy(reference) if os.path.exists(reference) else None

    fig, ax = plt.subplots(figsize=(8, 8))
    if ref:
        ax.plot(*ref, "k-", lw=2, label="reference")
    for key, xy in trajectories.items():
        ax.plot(*xy, lw=1, label=key)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend()
    ax.set_title("trajectories, top view")
    fig.savefig(os.path.join(directory, "top_view.png"), dpi=120, bbox_inches="tight")
    plt.close(fig)

    for path in sorted(glob.glob(os.path.join(directory, "*_map.csv"))):
        key = os.path.basename(path)[: -len("_map.csv")]
        fig, ax = plt.subplots(figsize=(8, 8))
        landmarks = read_csv(path)
        mx, my = [r["x"] for r in landmarks], [r["y"] for r in landmarks]
        ax.scatter(mx, my, s=2, c="tab:green", label="landmarks (last in the state)")
        if ref:
            ax.plot(*ref, "k-", lw=1.5, label="reference")
        if "dead_reckoning" in trajectories:
            ax.plot(*trajectories["dead_reckoning"], "tab:red", lw=1, label="dead reckoning")
        if key in trajectories:
            ax.plot(*trajectories[key], "tab:blue", lw=1.5, label=key)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend()
        ax.set_title(key + ": trajectory and map, top view")
        fig.savefig(os.path.join(directory, key + "_top_view.png"), dpi=120, bbox_inches="tight")
        plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
