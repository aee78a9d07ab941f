#!/usr/bin/python3
"""Work-precision diagram from a work_precision CSV (and its --meta JSON, for the title).

  plot_work_precision.py STUDY.csv OUT.png [--meta STUDY.json] [--title TEXT]

Two log-log panels against the median CPU time of the integration: the wheel_z error (m) and the
wheel_az error (m/s^2), one line per formulation, each point labelled with its tau (rtol = tau).
Dashed, lighter: the same runs timed without output samples (integration alone).
Failed runs are drawn as open markers at the error measured before the failure, and named in the
legend; they are not joined to the line.
"""
import argparse
import csv
import json
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MARKERS = {"index3": "o", "index2-ggl": "s", "index1": "^"}


def num(x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) and v > 0 else None


def main():
    p = argparse.ArgumentParser()
    p.add_argument("csv")
    p.add_argument("png")
    p.add_argument("--meta")
    p.add_argument("--title")
    a = p.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    meta = json.load(open(a.meta)) if a.meta else {}
    title = a.title or meta.get("label", a.csv)
    if meta:
        title += ", t in [0, %g] s%s" % (meta["t_end"], " (shortened)" if meta.get("t_end_shortened") else "")
        ref = meta["reference"]
        title += "; reference %s rtol %g atol %g" % (ref.get("formulation", "index3"), ref["rtol"], ref["atol"])
    forms = []
    for r in rows:
        if r["formulation"] not in forms:
            forms.append(r["formulation"])
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, key, label in ((axes[0], "err_z", "max |wheel_z - ref| (m)"),
                           (axes[1], "err_az", "max |wheel_az - ref| (m/s$^2$)")):
        for k, f in enumerate(forms):
            rs = [r for r in rows if r["formulation"] == f]
            ok = [r for r in rs if r["status"] == "ok" and num(r["cpu_median"]) and num(r[key])]
            bad = [r for r in rs if r["status"] != "ok" and num(r["cpu_median"]) and num(r[key])]
            color = "C%d" % k
            mk = MARKERS.get(f, "D")
            ax.loglog([float(r["cpu_median"]) for r in ok], [float(r[key]) for r in ok], marker=mk, color=color,
                      label=f)
            bare = [r for r in ok if num(r.get("cpu_no_output_median"))]
            if bare:
                ax.loglog([float(r["cpu_no_output_median"]) for r in bare], [float(r[key]) for r in bare],
                          marker=mk, color=color, linestyle="--", alpha=0.45, markersize=4,
                          label="%s, CPU without output samples" % f)
            for r in ok:
                ax.annotate("%g" % float(r["tol"]), (float(r["cpu_median"]), float(r[key])), fontsize=7,
                            textcoords="offset points", xytext=(4, 3))
            if bad:
                ax.loglog([float(r["cpu_median"]) for r in bad], [float(r[key]) for r in bad], linestyle="none",
                          marker=mk, markerfacecolor="none", color=color,
                          label="%s: failed (tau %s)" % (f, ", ".join("%g" % float(r["tol"]) for r in bad)))
                for r in bad:
                    ax.annotate("%g failed at t=%.3g" % (float(r["tol"]), float(r["t_reached"] or "nan")),
                                (float(r["cpu_median"]), float(r[key])), fontsize=7, color=color,
                                textcoords="offset points", xytext=(4, -9))
        ax.set_xlabel("CPU time of the integration, median (s)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)
    print("wrote", a.png)


if __name__ == "__main__":
    main()
