"""Pose NEES of FastSLAM 2.0 against time, Monte Carlo averaged, with the 95% interval of that
average (the CSV of sextant-fastslam-horizon). Usage: plot_fastslam_horizon.py CSV PNG"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

data = np.genfromtxt(sys.argv[1], delimiter=",", names=True)
fig, ax = plt.subplots(figsize=(9, 4.5))
for name in data.dtype.names:
    if name.startswith("nees_"):
        ax.semilogy(data["step"], data[name], lw=0.8, label=name[5:] + " particles")
ax.fill_between(data["step"], data["lower"], data["upper"], color="0.8", label="95% interval of the average")
ax.set_xlabel("step")
ax.set_ylabel("pose NEES, average over runs")
ax.set_title("FastSLAM 2.0 on the ship: consistency against the horizon")
ax.legend(loc="upper left", fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
