"""A sweep's table and its runs read back: the table as a pandas DataFrame with units
(table.attrs["units"]) and a notebook summary, each run's samples with `t` as index, and all
runs as one xarray Dataset (dims run and t, units in attrs)."""
import os
from pathlib import Path

import numpy as np
import pandas as pd

from .sweep_files import read_h5, read_json

# Row fields kept in the run's .json only (bookkeeping, not results).
_PRIVATE = ("metric_defs", "file_sha256", "run_status", "run_message")


class SweepTable(pd.DataFrame):
    """The table of a sweep: one row per run. attrs["units"] maps columns to units; in a
    notebook it shows a summary line (runs by status, CPU) and the units above the rows."""

    @property
    def _constructor(self):
        return SweepTable

    def summary_line(self):
        counts = self["status"].value_counts().to_dict() if "status" in self else {}
        cpu = float(np.nansum(self["solver_cpu_s"])) if "solver_cpu_s" in self else float("nan")
        return (f"{len(self)} runs: " + ", ".join(f"{n} {s}" for s, n in counts.items())
                + f"; integration CPU {cpu:.3g} s")

    def _repr_html_(self):
        units = self.attrs.get("units", {})
        with_units = ", ".join(f"{c} [{u}]" for c, u in units.items() if c in self.columns and u)
        head = f"<p><b>mbdae sweep</b>: {self.summary_line()}<br><small>units: {with_units}</small></p>"
        return head + pd.DataFrame(self)._repr_html_()


def make_table(out, manifest, rows, metric_names, units):
    """The table of the runs of `manifest` (in its order), written to OUT/runs.csv."""
    param_names = list(dict.fromkeys(p for e in manifest["runs"] for p in e["params"]))
    records = []
    for i, e in enumerate(manifest["runs"]):
        row = {k: v for k, v in rows.get(e["key"], {"status": "lost", "message": "not run"}).items()
               if k not in _PRIVATE}
        row.update(run=i, key=e["key"], **e["params"])
        records.append(row)
    first = ["run", *param_names, "status", "message", "cpu_s", "solver_cpu_s", "wall_s", "rows", *metric_names]
    df = pd.DataFrame(records)
    for c in first:
        if c not in df.columns:
            df[c] = np.nan
    df = SweepTable(df[first + [c for c in df.columns if c not in first]])
    df.attrs["units"] = {c: units[c] for c in df.columns if c in units}
    tmp = Path(out) / "runs.csv.tmp"
    try:
        df.to_csv(tmp, index=False)
        os.replace(tmp, Path(out) / "runs.csv")
    except OSError:
        tmp.unlink(missing_ok=True)
        raise
    manifest_path = Path(out) / "sweep.json"
    m = read_json(manifest_path) or manifest
    m["units"] = df.attrs["units"]
    from .sweep_files import write_json
    write_json(manifest_path, m)
    return df


def _manifest(out):
    m = read_json(Path(out) / "sweep.json")
    if not isinstance(m, dict) or "runs" not in m:
        raise FileNotFoundError(f"{out}: not a sweep folder (no readable sweep.json)")
    return m


def read_sweep(out):
    """The table of a sweep folder (OUT/runs.csv) with its units (attrs["units"])."""
    table = SweepTable(pd.read_csv(Path(out) / "runs.csv", float_precision="round_trip"))
    table.attrs["units"] = _manifest(out).get("units", {})
    return table


def read_run(out, run):
    """(samples, params, summary) of run number `run` of a sweep folder: samples is a DataFrame
    with `t` as index and the units in samples.attrs["units"]."""
    runs = _manifest(out)["runs"]
    if not 0 <= int(run) < len(runs):
        raise IndexError(f"{out}: run {run} out of range (0 to {len(runs) - 1})")
    path = Path(out) / "runs" / f"{runs[int(run)]['key']}.h5"
    if not path.exists():
        raise FileNotFoundError(f"{path}: run {run} has no samples (its row says why: read_sweep(out))")
    return read_h5(path)


def runs_dataset(out, columns=None):
    """Every run of a sweep folder as an xarray Dataset: one variable per column, dims (run, t)
    (t the union of the runs' sample times; NaN where a run has no sample), units in each
    variable's attrs, the parameters and status as coordinates along run."""
    import xarray as xr
    m = _manifest(out)
    table = read_sweep(out)
    frames = {}
    for i, e in enumerate(m["runs"]):
        path = Path(out) / "runs" / f"{e['key']}.h5"
        if path.exists():
            frames[i] = read_h5(path)[0]
    t = np.unique(np.concatenate([f.index.to_numpy() for f in frames.values()])) if frames else np.array([])
    names = columns or list(dict.fromkeys(c for f in frames.values() for c in f.columns))
    units = next((f.attrs.get("units", {}) for f in frames.values()), {})
    data = {}
    for c in names:
        a = np.full((len(m["runs"]), len(t)), np.nan)
        for i, f in frames.items():
            if c in f.columns:
                a[i, np.searchsorted(t, f.index.to_numpy())] = f[c].to_numpy()
        data[c] = (("run", "t"), a, {"units": units.get(c, "")})
    coords = {"run": np.arange(len(m["runs"])), "t": ("t", t, {"units": units.get("t", "s")}),
              "status": ("run", table["status"].astype(str).to_numpy())}
    for p in dict.fromkeys(p for e in m["runs"] for p in e["params"]):
        values = [e["params"].get(p, np.nan) for e in m["runs"]]
        try:
            values = np.array(values, dtype=float)  # numbers as numbers (netCDF-writable)
        except (TypeError, ValueError):
            values = np.array([str(v) for v in values])
        coords[p] = ("run", values, {"units": m.get("units", {}).get(p, "")})
    return xr.Dataset(data, coords=coords, attrs={"sweep": str(out)})
