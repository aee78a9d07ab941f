#!/usr/bin/env python3
"""Figures 2-9 of the five-point suspension exercise from mbdae's results.csv files.

usage: plot_figures.py OUT_DIR [DOCS_FIGURE_DIR]
OUT_DIR holds kinematics/, dynamics_step/ and dynamics_poster/ (each with results.csv, as
written by `mbdae run`). PNGs go to OUT_DIR/figures and, if given, to DOCS_FIGURE_DIR.
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    cols = rows[0]
    data = {c: [] for c in cols}
    for r in rows[1:]:
        for c, v in zip(cols, r):
            data[c].append(float(v))
    return data


def save(fig, name, dirs):
    for d in dirs:
        os.makedirs(d, exist_ok=True)
        fig.savefig(os.path.join(d, name), dpi=110, bbox_inches="tight")
    plt.close(fig)


def kinematics(out, dirs):
    d = read(os.path.join(out, "kinematics", "results.csv"))
    z0 = d["wheel_z"][0]  # wheel-centre height at q4_0 (t = 0)
    # The second stage (t >= 1 s) sweeps q4 from q_min to q_max: the whole travel, monotonic.
    idx = [i for i, t in enumerate(d["t"]) if t >= 1.0 and abs(d["wheel_z"][i] - z0) <= 0.20]
    z = [d["wheel_z"][i] for i in idx]
    panels = [
        ("fig2_camber.png", "camber", "camber (deg)", lambda v: math.degrees(v), "Figure 2: camber angle"),
        ("fig3_toe.png", "toe", "toe (deg)", lambda v: math.degrees(v), "Figure 3: toe angle"),
        ("fig4_wheel_x.png", "wheel_x", "wheel-centre x (mm)", lambda v: 1000 * v,
         "Figure 4: longitudinal position of the wheel centre"),
        ("fig5_wheel_y.png", "wheel_y", "wheel-centre y (mm)", lambda v: 1000 * v,
         "Figure 5: lateral position of the wheel centre"),
    ]
    for name, col, label, conv, title in panels:
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot([conv(d[col][i]) for i in idx], z, "b-")
        ax.axhline(z0, color="0.6", lw=0.8, ls="--")
        ax.set_xlabel(label)
        ax.set_ylabel("wheel-centre height z (m)")
        ax.set_title(title + " (z0 = %.4f m +- 0.20 m)" % z0, fontsize=9)
        ax.grid(True, alpha=0.3)
        save(fig, name, dirs)


def dynamics_step(out, dirs):
    d = read(os.path.join(out, "dynamics_step", "results.csv"))
    panels = [
        ("fig6_wheel_z.png", "wheel_z", "wheel-centre z (m)", "Figure 6: vertical position of the wheel centre"),
        ("fig7_wheel_vz.png", "wheel_vz", "wheel-centre dz/dt (m/s)", "Figure 7: vertical velocity of the wheel centre"),
        ("fig8_wheel_az.png", "wheel_az", "wheel-centre d2z/dt2 (m/s^2)",
         "Figure 8: vertical acceleration of the wheel centre"),
    ]
    for name, col, label, title in panels:
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(d["t"], d[col], "b-", lw=0.9)
        ax.axvline(0.2, color="0.6", lw=0.8, ls="--")
        ax.set_xlabel("time (s)")
        ax.set_ylabel(label)
        ax.set_title(title + " (ground step -0.10 m at t = 0.2 s)", fontsize=9)
        ax.grid(True, alpha=0.3)
        save(fig, name, dirs)


def dynamics_poster(out, dirs):
    d = read(os.path.join(out, "dynamics_poster", "results.csv"))
    fig, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    for ax, (col, label) in zip(axes, [("wheel_z", "wheel z (m)"), ("wheel_vz", "wheel dz/dt (m/s)"),
                                       ("wheel_az", "wheel d2z/dt2 (m/s^2)"), ("chassis_z", "chassis z (m)")]):
        ax.plot(d["t"], d[col], "b-", lw=0.5)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title("Figure 9: wheel centre and chassis on the vibrating poster (sweep 1 Hz + 0.9 Hz/s, 5 mm)",
                      fontsize=9)
    save(fig, "fig9_poster.png", dirs)


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 1
    out = sys.argv[1]
    dirs = [os.path.join(out, "figures")] + sys.argv[2:3]
    kinematics(out, dirs)
    dynamics_step(out, dirs)
    dynamics_poster(out, dirs)
    print("figures written to " + ", ".join(dirs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
