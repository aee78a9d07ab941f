"""Work-precision study from Python (the method of docs/work-precision.md): every formulation at
every tolerance tau (rtol = tau, atol = atol_ratio * tau, or the product's atol rule when
atol_ratio is None), errors against a reference run at tight tolerance with another formulation
(or a reference table), CPU from summary.json; the runs go through mbdae.sweep (Dask) or, with
serial=True, one after the other in this process. `report()` is `python3 -m mbdae
work-precision SCENE`: the table (CSV), the figure (PNG) and each curve's slope and floor."""
import math
import tempfile
from pathlib import Path

import numpy as np

from .sweep import RUN_OPTIONS, run_one, sweep

DEFAULT_TOLERANCES = [10.0 ** -k for k in range(2, 11)]  # 1e-2 ... 1e-10


def max_error(column, reference):
    """max over the output samples of |x - x_ref| (the reference interpolated where the times
    differ); NaN for a run with no samples."""
    t_ref, x_ref = np.asarray(reference["t"], dtype=float), np.asarray(reference[column], dtype=float)

    def f(r):
        t, x = r["t"], r[column]
        if len(t) == len(t_ref) and np.array_equal(t, t_ref):
            return float(np.max(np.abs(x - x_ref)))
        return float(np.max(np.abs(x - np.interp(t, t_ref, x_ref))))
    f.__name__ = f"max_error({column})"
    return f


def estimated_error(column):
    """The run's own global error estimate of `column` (summary error_estimate; NaN without one)."""
    def f(r):
        s = r.summary.get("error_estimate", {}).get("sensors", {}).get(column)
        return float(s["error"]) if s else float("nan")
    f.__name__ = f"estimated_error({column})"
    return f


def _estimate_cpu(r):
    """CPU of the estimate's comparison run(s) (0 without an estimate)."""
    return float(r.summary.get("error_estimate", {}).get("cpu_seconds", {}).get("estimate", 0.0))


def _steps(r):
    """Integration steps taken (all dynamics and kinematics steps)."""
    return float(sum(s.get("statistics", {}).get("steps", 0) for s in r.summary.get("steps", [])))


def _atol(r):
    """The position atol used by the last integration step."""
    steps = [s for s in r.summary.get("steps", []) if "atol" in s]
    return float(steps[-1]["atol"]) if steps else float("nan")


def work_precision(scene, formulations, tolerances, columns=None, reference=None, out=None, client=None,
                   workers=None, atol_ratio=1e-6, reference_rtol=1e-12, reference_atol=1e-16, progress=True,
                   reference_formulation="index2-ggl", estimate=False, serial=False):
    """The work-precision table: one row per (formulation, tolerance) with status, CPU
    (solver_cpu_s: the integration steps' cpu_seconds), steps, atol_used and err_COLUMN =
    max |x - x_ref| for each of `columns` (default: every output column); with estimate=True also
    est_COLUMN (the run's --error-estimate, its warnings off) and estimate_cpu_s. `reference` is a Result or a
    mapping of arrays ("t" and the columns, e.g. a pandas DataFrame read from a CSV); by default
    the scene is run here with `reference_formulation` at reference_rtol / reference_atol (None:
    the product's atol rule). atol_ratio None: rtol only, the atol from the scene's rule."""
    if reference is None:
        reference = scene.run(formulation=reference_formulation, rtol=reference_rtol, atol=reference_atol)
    names = list(reference.names) if hasattr(reference, "names") else list(reference.keys())
    columns = list(columns or [c for c in names if c != "t"])
    missing = [c for c in columns + ["t"] if c not in names]
    if missing:
        raise ValueError(f"the reference has no column {', '.join(missing)} (it has {', '.join(names)})")
    runs = [{"formulation": f, "rtol": float(tau)} | ({} if atol_ratio is None else {"atol": float(atol_ratio * tau)})
            for f in formulations for tau in tolerances]
    metrics = {f"err_{c}": max_error(c, reference) for c in columns}
    if estimate:
        metrics.update({f"est_{c}": estimated_error(c) for c in columns})
        metrics["estimate_cpu_s"] = _estimate_cpu
    metrics["steps"] = _steps
    metrics["atol_used"] = _atol
    options = {"error_estimate": True, "error_warnings": False} if estimate else {}
    if serial:
        return _serial(scene, runs, options, metrics)
    out = out or tempfile.mkdtemp(prefix="mbdae-work-precision-")
    return sweep(scene, runs, out, client=client, metrics=metrics, workers=workers, progress=progress,
                 options=options)


def _serial(scene, runs, options, metrics):
    """The table of `runs` made one after the other in this process (no Dask)."""
    import pandas as pd
    rows = []
    for i, run in enumerate(runs):
        row = dict(run=i, **run)
        row.update(run_one(scene, run, options, metrics)["row"])
        rows.append(row)
    first = ["run", *[k for k in RUN_OPTIONS if any(k in r for r in runs)], "status", "message", "solver_cpu_s"]
    table = pd.DataFrame(rows)
    return table[[c for c in first if c in table] + [c for c in table if c not in first]]


def curve(table, formulation, column):
    """Slope d log(err) / d log(rtol) (least squares over the successful runs) and floor (the
    smallest error reached, and the rtol below which the error stops falling: the first tau whose
    next tighter tau does not reduce the error by a factor 2 or more; None if it always does) of
    one formulation's curve. Returns a dict."""
    rows = table[(table["formulation"] == formulation) & (table["status"] == "ok")].sort_values("rtol", ascending=False)
    tau, err = rows["rtol"].to_numpy(float), rows[f"err_{column}"].to_numpy(float)
    keep = np.isfinite(err) & (err > 0)
    tau, err = tau[keep], err[keep]
    out = {"formulation": formulation, "column": column, "runs": len(tau), "slope": math.nan,
           "min_error": math.nan, "floor_from_rtol": None}
    if len(tau) >= 2:
        out["slope"] = float(np.polyfit(np.log10(tau), np.log10(err), 1)[0])
    if len(tau):
        out["min_error"] = float(err.min())
    for k in range(len(tau) - 1):
        if err[k + 1] > 0.5 * err[k] and all(err[j] > 0.5 * err[k] for j in range(k + 1, len(tau))):
            out["floor_from_rtol"] = float(tau[k])
            break
    return out


def plot(table, column, path, unit=""):
    """error of `column` against CPU time and against rtol, one line per formulation (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for f in dict.fromkeys(table["formulation"]):
        rows = table[(table["formulation"] == f) & (table["status"] == "ok")].sort_values("rtol")
        err = rows[f"err_{column}"]
        a.loglog(rows["solver_cpu_s"], err, "o-", label=f)
        b.loglog(rows["rtol"], err, "o-", label=f)
        if f"est_{column}" in rows:
            b.loglog(rows["rtol"], rows[f"est_{column}"], "x:", color=b.lines[-1].get_color(), label=f"{f} estimate")
    a.set_xlabel("CPU time of the integration [s]")
    b.set_xlabel("rtol")
    b.invert_xaxis()
    for ax in (a, b):
        ax.set_ylabel(f"max |{column} - ref| {unit}".strip())
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def report(scene, out, formulations=None, tolerances=None, columns=None, reference_csv=None, estimate=False,
           atol_ratio=None, workers=None, progress=True, reference_formulation="index2-ggl", reference_rtol=1e-12):
    """`python3 -m mbdae work-precision`: runs the study, writes OUT/work_precision.csv and
    OUT/work_precision_COLUMN.png, and returns (table, curves, notes) where curves are the
    curve() dicts of every formulation and column, notes lines about the reference."""
    from . import _core
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    formulations = list(formulations or _core.formulations())
    tolerances = list(tolerances or DEFAULT_TOLERANCES)
    notes = []
    if reference_csv is not None:
        import pandas as pd
        reference = pd.read_csv(reference_csv)
        notes.append(f"reference: {reference_csv} ({len(reference)} samples)")
    else:
        reference = scene.run(formulation=reference_formulation, rtol=reference_rtol)
        check = scene.run(formulation=reference_formulation, rtol=10 * reference_rtol)
        diffs = ", ".join(f"{c} {np.max(np.abs(np.asarray(check[c]) - np.asarray(reference[c]))):.3g}"
                          for c in (columns or [n for n in reference.names if n != "t"])[:6])
        notes.append(f"reference: {reference_formulation} at rtol {reference_rtol:g} ({reference.rows} samples); "
                     f"its difference from rtol {10 * reference_rtol:g}: {diffs}")
    serial = workers is None
    table = work_precision(scene, formulations, tolerances, columns=columns, reference=reference,
                           out=out / "runs", workers=workers, atol_ratio=atol_ratio, progress=progress,
                           estimate=estimate, serial=serial)
    table.to_csv(out / "work_precision.csv", index=False)
    cols = [c[4:] for c in table.columns if c.startswith("err_")]
    curves = [curve(table, f, c) for c in cols for f in formulations]
    for c in cols:
        plot(table, c, out / f"work_precision_{c}.png")
    return table, curves, notes
