"""Result: what a run produced, as numpy arrays (views of the C++ columns, no copies), a pandas
table and the summary dict."""
import json

import numpy as np


class Result:
    """A run's samples and summary. `columns` maps each column name ("t", then the scene's output
    sensors) to a read-only numpy array; `table` is a pandas DataFrame of the same; `summary` is
    the content of summary.json as a dict; `status` is "ok" or the failure."""

    def __init__(self, status, message, names, arrays, units, summary_json, q=(), sensitivity=((), (), ())):
        self.status = status
        # Scene.run(sensitivities=[...]): column names ("t", then "d(SENSOR)/d(PATH)"), units, arrays.
        self._sens_names, self._sens_units, self._sens_arrays = (list(x) for x in sensitivity)
        self._sens_table = None
        self.message = message
        self.names = list(names)
        self.units = list(units)
        self.q = np.asarray(q, dtype=float)
        self._arrays = list(arrays)
        self._summary_json = summary_json
        self._summary = None
        self._table = None

    @classmethod
    def _from_core(cls, r):
        # r.column(k) is a numpy view over the C++ vector and holds r alive.
        names = list(r.sensitivity_names)
        sensitivity = (names, list(r.sensitivity_units), [r.sensitivity_column(k) for k in range(len(names))])
        return cls(r.status, r.message, r.names, [r.column(k) for k in range(len(r.names))], r.units,
                   r.summary_json, r.q, sensitivity)

    @property
    def ok(self):
        return self.status == "ok"

    @property
    def rows(self):
        return len(self._arrays[0]) if self._arrays else 0

    @property
    def columns(self):
        """{name: numpy array}: the samples of each column, not copied."""
        return dict(zip(self.names, self._arrays))

    def __getitem__(self, name):
        try:
            return self._arrays[self.names.index(name)]
        except ValueError:
            raise KeyError(f"no column named '{name}' (columns: {', '.join(self.names)})") from None

    @property
    def table(self):
        """A pandas DataFrame: `t`, then one column per output sensor (a copy, built once)."""
        if self._table is None:
            import pandas as pd
            self._table = pd.DataFrame(self.columns, columns=self.names)
        return self._table

    @property
    def summary(self):
        """summary.json's content (statistics, solved coordinates, status) as a dict."""
        if self._summary is None:
            self._summary = json.loads(self._summary_json) if self._summary_json else {}
        return self._summary

    @property
    def sensitivities(self):
        """Scene.run(sensitivities=[paths]): a pandas DataFrame indexed by `t` with one column per
        (sensor, parameter) pair, d(sensor)/d(parameter) in the units of
        `sensitivity_units[(sensor, parameter)]` (docs/sensitivities.md); None without them. Fewer
        rows than `table` where they failed (summary["sensitivities"]["status"])."""
        if not self._sens_names:
            return None
        if self._sens_table is None:
            import pandas as pd
            params = [p["path"] for p in self.summary.get("sensitivities", {}).get("parameters", [])]
            sensors = self.names[1:]
            index = pd.MultiIndex.from_tuples([(s, p) for s in sensors for p in params], names=["sensor", "parameter"])
            data = np.column_stack(self._sens_arrays[1:]) if len(self._sens_arrays) > 1 else np.empty((0, 0))
            self._sens_table = pd.DataFrame(data, index=pd.Index(self._sens_arrays[0], name="t"), columns=index)
        return self._sens_table

    def normalized_sensitivities(self):
        """The sensitivities relative to the parameters' values and the sensors' scales:
        (p / max|y|) dy/dp, max|y| each sensor's largest magnitude over the run (a pointwise
        (p / y) dy/dp is unbounded where y crosses zero). A DataFrame like `sensitivities`; a
        sensor that is zero throughout gets no column, a run without samples (static steps only,
        their sensitivities in summary["steps"]) every column and no rows. None without
        sensitivities. The rule of
        the CLI's sensitivities_normalized.csv (cases/run/sensitivities.cpp), kept alike by
        test_api.py::test_normalized_sensitivities_are_the_clis."""
        table = self.sensitivities
        if table is None:
            return None
        if not self.rows:  # no samples, no scales: every column, empty (as the CLI's file)
            return table.copy()
        values = {p["path"]: p["value"] for p in self.summary["sensitivities"]["parameters"]}
        keep = [c for c in table.columns if np.abs(self[c[0]]).max() > 0]
        scale = np.array([values[p] / np.abs(self[s]).max() for s, p in keep])
        return table[keep] * scale

    @property
    def sensitivity_units(self):
        """{(sensor, parameter): unit} of the sensitivities' columns ("m/(N/m)", ...)."""
        table = self.sensitivities
        return {} if table is None else dict(zip(table.columns, self._sens_units[1:]))

    def cpu_seconds(self):
        """The integration steps' CPU time (sum of the steps' statistics.cpu_seconds): the clock of
        the thread that solved them, so runs in parallel threads each report their own cost."""
        return sum(s.get("statistics", {}).get("cpu_seconds", 0.0) for s in self.summary.get("steps", []))

    def __repr__(self):
        return f"<mbdae.Result {self.status}: {self.rows} rows x {len(self.names)} columns>"

    def _repr_html_(self):
        from html import escape
        steps = self.summary.get("steps", [])
        nsteps = sum(s.get("statistics", {}).get("steps", 0) for s in steps)
        est = self.summary.get("error_estimate")
        cols = ", ".join(f"{escape(n)} [{escape(u)}]" for n, u in zip(self.names, self.units))
        msg = f" ({escape(self.message)})" if self.message else ""
        extra = f"<br>error estimate: {escape(json.dumps(est))}" if est else ""
        return (f"<p><b>mbdae.Result</b> {escape(self.status)}{msg}<br>{self.rows} rows; {nsteps} integration "
                f"steps; CPU {self.cpu_seconds():.3g} s{extra}<br>columns: {cols}</p>")

    def __reduce__(self):  # pickles as plain arrays (Dask, multiprocessing)
        return (Result, (self.status, self.message, self.names, [np.array(a) for a in self._arrays], self.units,
                         self._summary_json, self.q,
                         (self._sens_names, self._sens_units, [np.array(a) for a in self._sens_arrays])))

    # ---- Writers over the result ------------------------------------------------------------
    animation_dir = None  # set by Scene.run(animation=...)

    def animation(self, out, **options):
        """Draws the run's animation (Scene.run(animation=...)) into `out`, an .mp4 (ffmpeg) or
        .gif, with matplotlib: options fps, start, end, max_frames, size, elev, azim, title
        (cases/animation/video.py). Returns `out`."""
        if not self.animation_dir:
            raise ValueError("this result has no animation: run the scene with animation=True or animation=DIR")
        from . import _video
        return _video.animation(self.animation_dir, str(out), **options)
