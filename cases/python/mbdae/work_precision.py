"""Work-precision study from Python (the method of docs/work-precision.md): every formulation at
every tolerance tau (rtol = tau, atol = atol_ratio * tau), errors against a reference run at tight
tolerance, CPU from summary.json; the runs go through mbdae.sweep (Dask)."""
import tempfile

import numpy as np

from .sweep import sweep


def max_error(column, reference):
    """max over the output samples of |x - x_ref| (the reference interpolated where the times
    differ); NaN for a run with no samples."""
    t_ref, x_ref = np.array(reference["t"]), np.array(reference[column])

    def f(r):
        t, x = r["t"], r[column]
        if len(t) == len(t_ref) and np.array_equal(t, t_ref):
            return float(np.max(np.abs(x - x_ref)))
        return float(np.max(np.abs(x - np.interp(t, t_ref, x_ref))))
    f.__name__ = f"max_error({column})"
    return f


def work_precision(scene, formulations, tolerances, columns=None, reference=None, out=None, client=None,
                   workers=None, atol_ratio=1e-6, reference_rtol=1e-12, reference_atol=1e-16, progress=True):
    """The work-precision table: one row per (formulation, tolerance) with status, CPU
    (solver_cpu_s: the integration steps' cpu_seconds), steps and err_COLUMN = max |x - x_ref| for
    each of `columns` (default: every output column). `reference` is a Result; by default the
    scene is run here with index3 at reference_rtol / reference_atol."""
    if reference is None:
        reference = scene.run(formulation="index3", rtol=reference_rtol, atol=reference_atol)
    columns = list(columns or [c for c in reference.names if c != "t"])
    runs = [{"formulation": f, "rtol": float(tau), "atol": float(atol_ratio * tau)}
            for f in formulations for tau in tolerances]
    metrics = {f"err_{c}": max_error(c, reference) for c in columns}
    metrics["steps"] = _steps
    out = out or tempfile.mkdtemp(prefix="mbdae-work-precision-")
    return sweep(scene, runs, out, client=client, metrics=metrics, workers=workers, progress=progress)


def _steps(r):
    """Integration steps taken (all dynamics and kinematics steps)."""
    return float(sum(s.get("statistics", {}).get("steps", 0) for s in r.summary.get("steps", [])))
