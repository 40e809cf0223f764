#!/usr/bin/env python3
"""Draws an optimized pose graph written by sextant-run (--out DIR --plots): the poses joined in
order, and each loop closure (an edge between non-consecutive poses) as a thin line. 3D graphs are
seen from above (x, y). Usage: plot_pose_graph.py DIR FILE.g2o -> DIR/FILE.png"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_g2o(path):
    poses, edges = {}, []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if not fields:
                continue
            tag = fields[0]
            if tag in ("VERTEX_SE2", "VERTEX_SE3:QUAT"):
                poses[int(fields[1])] = (float(fields[2]), float(fields[3]))
            elif tag in ("EDGE_SE2", "EDGE_SE3:QUAT"):
                edges.append((int(fields[1]), int(fields[2])))
    return poses, edges


def main():
    directory, name = sys.argv[1], sys.argv[2]
    poses, edges = read_g2o(os.path.join(directory, name))
    ids = sorted(poses)
    fig, ax = plt.subplots(figsize=(8, 8))
    loops = [(a, b) for a, b in edges if abs(a - b) != 1]
    for a, b in loops:
        ax.plot([poses[a][0], poses[b][0]], [poses[a][1], poses[b][1]], color="tab:orange", linewidth=0.3, alpha=0.5)
    ax.plot([poses[i][0] for i in ids], [poses[i][1] for i in ids], color="tab:blue", linewidth=0.8)
    ax.set_aspect("equal")
    ax.set_title(f"{name}: {len(ids)} poses, {len(loops)} loop closures (orange)")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    out = os.path.join(directory, os.path.splitext(name)[0] + ".png")
    fig.savefig(out, dpi=120, bbox_inches="tight")


if __name__ == "__main__":
    main()
