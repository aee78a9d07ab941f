"""Toe and camber sensitivity to every chassis hardpoint coordinate over the kinematic sweep
(docs/sensitivities.md): one kinematic run with 18 sensitivities (bp1..bp6, x y z), plotted
against the wheel's vertical travel, and the CPU against the same run without them.

    PYTHONPATH=build/python /usr/bin/python3 verification/studies/sensitivities/hardpoint_figure.py [OUT.png]
"""
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mbdae  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[3]
out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "figures" / "sensitivity_hardpoints.png"

scene = mbdae.load(ROOT / "cases" / "five_point_suspension" / "kinematics.yaml")
paths = [f"bodies.chassis.points.bp{i}.{c}" for i in range(1, 7) for c in range(3)]
plain = scene.run()
r = scene.run(sensitivities=paths)
print(f"kinematic sweep: {plain.rows} samples; CPU {plain.cpu_seconds():.3f} s without sensitivities, "
      f"{r.cpu_seconds():.3f} s with {len(paths)} ({r.cpu_seconds() / plain.cpu_seconds():.1f} times)")

z = 1e3 * (r["wheel_z"] - r["wheel_z"][0])  # wheel travel [mm]
S = r.sensitivities
fig, axes = plt.subplots(2, 3, figsize=(13, 7), sharex=True)
for row, sensor in enumerate(["toe", "camber"]):
    for col, comp in enumerate("xyz"):
        ax = axes[row, col]
        for i in range(1, 7):
            p = f"bodies.chassis.points.bp{i}.{col}"
            ax.plot(z, np.degrees(S[(sensor, p)].to_numpy()) / 1e3, label=f"bp{i}")  # deg/mm
        ax.set_title(f"d({sensor})/d(bp.{comp})")
        ax.grid(True, alpha=0.3)
        if col == 0:
            ax.set_ylabel("deg per mm of hardpoint")
        if row == 1:
            ax.set_xlabel("wheel travel [mm]")
axes[0, 0].legend(fontsize=8)
fig.suptitle("Five-point suspension: toe and camber sensitivity to each chassis hardpoint coordinate over the kinematic sweep")
fig.tight_layout()
fig.savefig(out, dpi=110)
largest = sorted(((np.abs(S[("toe", p)]).max(), p) for p in paths), reverse=True)[:3]
print("largest toe sensitivities [rad/m]: " + ", ".join(f"{p} {v:.3f}" for v, p in largest))
print(f"wrote {out}")
