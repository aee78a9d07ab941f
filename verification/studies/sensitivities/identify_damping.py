"""Worked example of docs/sensitivities.md: identify the suspension damping from a Dynamics I
response by Gauss-Newton, the sensitivities as the Jacobian.

The "measurement" is the wheel height of Dynamics I made with the scene's damping (1400 N s/m);
the fit starts from 700 N s/m and minimizes sum_i (z_i(c) - z_meas_i)^2 with
    c <- c - (J^T r) / (J^T J),   J_i = d(wheel_z_i)/dc (Result.sensitivities), r_i = z_i(c) - z_meas_i,
one run with one sensitivity per iteration.

    PYTHONPATH=build/python /usr/bin/python3 verification/studies/sensitivities/identify_damping.py
"""
import pathlib

import numpy as np

import mbdae

ROOT = pathlib.Path(__file__).resolve().parents[3]
scene = mbdae.load(ROOT / "cases" / "five_point_suspension" / "dynamics_step.yaml")
path = "forces.suspension.damping"
measured = scene.run(rtol=1e-9)["wheel_z"].copy()  # made with the known value, 1400 N s/m

c = 700.0
for it in range(12):
    r = scene.with_params({path: c}).run(rtol=1e-9, sensitivities=[path])
    residual = r["wheel_z"] - measured
    jac = r.sensitivities[("wheel_z", path)].to_numpy()
    step = -(jac @ residual) / (jac @ jac)
    print(f"iteration {it}: c = {c:.9f} N s/m, rms misfit {np.sqrt(np.mean(residual ** 2)):.3e} m, "
          f"step {step:+.3e}, CPU {r.cpu_seconds():.2f} s")
    c += step
    if abs(step) < 1e-9 * c:
        break
print(f"identified damping: {c:.9f} N s/m (true 1400)")
