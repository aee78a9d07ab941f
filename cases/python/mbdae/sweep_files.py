"""A sweep folder's files, all written by the caller:

    OUT/.mbdae.lock        the folder's lock (flock, the CLI's own: one sweep or run at a time)
    OUT/sweep.json         what the sweep is: its runs (keys, parameters), options, metrics, units
    OUT/runs/KEY.h5        a run's samples (t as index, units and summary as attributes) and,
                           asked for, its sensitivities (key "sensitivities", the same form)
    OUT/runs/KEY.json      its row, written last: the mark of a finished run, with the .h5's
                           SHA-256 and row count, checked before the run is reused
    OUT/runs.csv           the table

Every file is written whole to a temporary name and renamed; an HDF5 file is built in memory
(HDF5's core driver) and written by Python, so a full disk is an OSError here, not a crash
inside HDF5."""
import errno
import fcntl
import hashlib
import json
import os
from pathlib import Path

import numpy as np

from .sweep_checks import plain

# Statuses of runs that did not complete for reasons outside the run (a lost worker, a task
# error): a later sweep into the same folder runs them again.
RETRY_STATUSES = ("lost",)
LOCK_NAME = ".mbdae.lock"


class SweepOutputError(OSError):
    """A sweep folder that cannot be written (full disk, no permission): the runs finished before
    are kept whole; the same sweep started again resumes from them."""


class FolderLock:
    """An exclusive flock on OUT/.mbdae.lock (the file the CLI's runs lock), held until release()."""

    def __init__(self, out):
        self.path = Path(out) / LOCK_NAME
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            os.close(self.fd)
            self.fd = -1
            if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
                raise SweepOutputError(errno.EBUSY, f"{out}: folder in use by another sweep or run (its lock "
                                       f"{self.path} is held); wait for it or choose another folder") from None
            raise

    def release(self):
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1


def write_bytes(path, data):
    """`data` written to path.tmp, flushed and renamed to `path`; on failure nothing is left."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise


def write_json(path, obj):
    write_bytes(path, json.dumps(obj, default=str, indent=1).encode())


def read_json(path):
    """The JSON content of path, or None if missing, truncated or not JSON."""
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


def _frame(columns):
    """{name: array} as a DataFrame with the first column as its index."""
    import pandas as pd
    names = list(columns)
    index = pd.Index(np.asarray(columns[names[0]]), name=names[0])
    return pd.DataFrame({n: np.asarray(columns[n]) for n in names[1:]}, index=index)


def h5_image(columns, units, params, summary, sensitivities=None):
    """A run's samples as the bytes of an HDF5 file (pandas.read_hdf): `t` as the index, the other
    columns as columns; units ({column: unit}), parameters and summary.json as attributes. With
    `sensitivities` ({"columns": {name: array}, "units": [...]}, "t" first) they are stored under
    the key "sensitivities" the same way, so a reused run hands them to its metrics again."""
    import pandas as pd
    with pd.HDFStore("mbdae-run-in-memory.h5", mode="w", driver="H5FD_CORE", driver_core_backing_store=0) as store:
        store.put("results", _frame(columns), format="fixed")
        attrs = store.get_storer("results").attrs
        attrs.units = json.dumps(dict(zip(columns, units)))
        attrs.params = json.dumps(params, default=str)
        attrs.summary = summary or "{}"
        if sensitivities:
            store.put("sensitivities", _frame(sensitivities["columns"]), format="fixed")
            store.get_storer("sensitivities").attrs.units = json.dumps(
                dict(zip(sensitivities["columns"], sensitivities["units"])))
        store._handle.flush()
        return store._handle.get_file_image()


def sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_h5(path):
    """(samples DataFrame with t as index and attrs["units"], params, summary) of a run file."""
    import pandas as pd
    with pd.HDFStore(path, mode="r") as store:
        attrs = store.get_storer("results").attrs
        df = store["results"]
        units = json.loads(attrs.units) if "units" in attrs else {}
        df.attrs["units"] = units
        return df, json.loads(attrs.params), json.loads(attrs.summary)


def read_h5_sensitivities(path):
    """The sensitivities of a run file (t as index, columns d(SENSOR)/d(PATH), units in
    attrs["units"]), or None if the run stored none."""
    import pandas as pd
    with pd.HDFStore(path, mode="r") as store:
        if "/sensitivities" not in store.keys():
            return None
        df = store["sensitivities"]
        df.attrs["units"] = json.loads(store.get_storer("sensitivities").attrs.units)
        return df


def record(out, index, key, run, payload, metric_defs):
    """Writes a run's .h5 (if it has samples) then its row (.json); returns the row."""
    row = {"run": index, **{k: plain(v) for k, v in run.items()}, **payload["row"], "key": key, "file": ""}
    if payload.get("columns"):
        image = h5_image(payload["columns"], payload.get("units") or [""] * len(payload["columns"]),
                         {k: plain(v) for k, v in run.items()}, payload.get("summary"), payload.get("sensitivities"))
        name = Path("runs") / f"{key}.h5"
        write_bytes(out / name, image)
        row.update(file=str(name), file_sha256=hashlib.sha256(image).hexdigest())
    row["metric_defs"] = metric_defs
    write_json(out / "runs" / f"{key}.json", row)
    return row


def finished_row(out, key):
    """(row, problem) of a run: the row of a finished run whose files are whole (the .json parses
    and names this key, the .h5 is there with the SHA-256 the row recorded) and "", or None and
    what is wrong ("" if the run never finished). A broken run's files are removed (it runs again)."""
    jpath = out / "runs" / f"{key}.json"
    if not jpath.exists():
        return None, ""
    row = read_json(jpath)
    problem = ""
    if not isinstance(row, dict) or row.get("key") != key:
        problem = "its row is truncated or not JSON"
    elif row.get("status") in RETRY_STATUSES:
        problem = ""  # lost last time: simply run again
    elif row.get("file"):
        h5 = out / row["file"]
        if not h5.is_file():
            problem = f"{row['file']} is missing"
        elif sha256_file(h5) != row.get("file_sha256"):
            problem = f"{row['file']} does not match its recorded SHA-256 (truncated or changed)"
    elif row.get("rows"):
        problem = "its samples file is missing"
    if isinstance(row, dict) and not problem and row.get("status") not in RETRY_STATUSES:
        return row, ""
    for p in (jpath, out / "runs" / f"{key}.h5"):
        try:
            p.unlink()
        except FileNotFoundError:
            pass
    return None, problem
