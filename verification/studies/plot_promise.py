#!/usr/bin/env python3
"""The tolerance's promise as figures: for every case of promise.csv (run_promise.sh) a row of
four panels, the position and the velocity error (relative to the quantity's scale) against rtol
and against the integration's CPU seconds, one line per formulation; the promise 10 rtol dashed.

    plot_promise.py promise.csv promise.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(src, dst):
    rows = [r for r in csv.DictReader(open(src)) if r["status"] == "ok"]
    cases = list(dict.fromkeys(r["case"] for r in rows))
    forms = list(dict.fromkeys(r["formulation"] for r in rows))
    fig, axes = plt.subplots(len(cases), 4, figsize=(15, 3.0 * len(cases)), squeeze=False)
    for i, case in enumerate(cases):
        for j, (err, against) in enumerate([("err_pos", "rtol"), ("err_vel", "rtol"),
                                            ("err_pos", "cpu_seconds"), ("err_vel", "cpu_seconds")]):
            ax = axes[i][j]
            for k, f in enumerate(forms):
                pts = sorted((float(r[against]), float(r[err])) for r in rows if r["case"] == case and
                             r["formulation"] == f and float(r[err]) > 0)
                if pts:
                    ax.loglog(*zip(*pts), "o-", color="C%d" % k, label=f, ms=4)
            if against == "rtol":
                tols = sorted({float(r["rtol"]) for r in rows if r["case"] == case})
                ax.loglog(tols, [10 * t for t in tols], "k--", lw=1, label="10 rtol")
                ax.invert_xaxis()
            ax.set_xlabel("rtol" if against == "rtol" else "CPU [s]")
            ax.set_ylabel(("position" if err == "err_pos" else "velocity") + " error / scale")
            ax.set_title(case, fontsize=9)
            ax.grid(True, which="both", lw=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(dst, dpi=80)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
