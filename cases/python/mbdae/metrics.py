"""Summary metrics of a run for sweep tables: each is a function Result -> float, named by the
caller (sweep(..., metrics={"peak_travel": peak_deviation("wheel_z")})). Any function of a
Result works; these cover the usual ones. Each carries `columns` (what it reads: a sweep checks
them against the scene before its first run), `spec` (its text form, what defines it when a
sweep is resumed) and `unit` (None: its column's unit)."""
import numpy as np


def _named(f, kind, column, unit=None, threshold=None):
    f.__name__ = f"{kind}({column})" if threshold is None else f"{kind}({column}, {threshold:g})"
    f.columns = (column,)
    f.spec = f"{kind}:{column}" + ("" if threshold is None else f":{threshold!r}")
    f.unit = unit
    return f


def peak_deviation(column):
    """max |x(t) - x(t0)|: the largest excursion from the first sample (e.g. wheel-centre travel
    from the static position)."""
    def f(r):
        x = r[column]
        return float(np.max(np.abs(x - x[0]))) if len(x) else float("nan")
    return _named(f, "peak_deviation", column)


def peak(column):
    """max |x(t)|."""
    def f(r):
        x = r[column]
        return float(np.max(np.abs(x))) if len(x) else float("nan")
    return _named(f, "peak", column)


def rms(column):
    """Root mean square over the samples (evenly spaced in time)."""
    def f(r):
        x = r[column]
        return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float("nan")
    return _named(f, "rms", column)


def first_time_at_or_below(column, threshold=0.0):
    """The first sample time at which x <= threshold (e.g. tyre_force 0: first contact loss);
    NaN if never."""
    def f(r):
        hit = np.flatnonzero(r[column] <= threshold)
        return float(r["t"][hit[0]]) if len(hit) else float("nan")
    return _named(f, "first_time_at_or_below", column, "s", threshold)


def time_at_or_below(column, threshold=0.0):
    """Total time with x <= threshold (e.g. tyre_force 0: time without tyre contact), summing the
    sample intervals whose start sample is at or below it."""
    def f(r):
        t, x = r["t"], r[column]
        if len(t) < 2:
            return 0.0
        return float(np.sum(np.diff(t)[x[:-1] <= threshold]))
    return _named(f, "time_at_or_below", column, "s", threshold)


def from_spec(spec):
    """A metric from the shell's text form KIND:COLUMN[:THRESHOLD], KIND one of peak_deviation,
    peak, rms, first_time_at_or_below, time_at_or_below."""
    kinds = {"peak_deviation": peak_deviation, "peak": peak, "rms": rms,
             "first_time_at_or_below": first_time_at_or_below, "time_at_or_below": time_at_or_below}
    parts = spec.split(":")
    if parts[0] not in kinds or len(parts) not in (2, 3):
        raise ValueError(f"metric '{spec}': expected KIND:COLUMN[:THRESHOLD], KIND one of {', '.join(kinds)}")
    return kinds[parts[0]](parts[1], *(float(p) for p in parts[2:]))


def unit_of(f, column_units):
    """The unit of a metric's values: its `unit`, else its column's, else ""."""
    unit = getattr(f, "unit", None)
    if unit is not None:
        return unit
    cols = getattr(f, "columns", ())
    return column_units.get(cols[0], "") if len(cols) == 1 else ""
