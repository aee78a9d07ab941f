#!/usr/bin/env python3
"""The tolerance's promise against an independent reference (issue 21): runs `mbdae run SCENE
--rtol R --formulation F` (default absolute tolerances, or the scene's scaled with rtol) for
each formulation and rtol, and compares the output sensors with a reference CSV at the same
times. Errors: the largest |x - x_ref| over the samples of the position sensors (--pos) and of
the velocity sensors (--vel), each divided by its group's scale (the largest |x_ref| over the
samples and the group's sensors). Appends one CSV row per run to --csv, in the columns of
docs/studies/promise.csv (run_promise.sh, make_tables.py):
case,formulation,rtol,steps,residual_evals,cpu_seconds,err_pos,err_vel,worst_pos,worst_vel,status,
ref_check_pos,ref_check_vel (the worst sensors; the reference's own check, --ref-check P,V).

  promise_study.py --mbdae BIN --scene S --ref REF.csv --pos a,b --vel c,d --label L
                   [--formulations index3,...] [--tols 1e-2,...] [--csv OUT] [--ref-check P,V]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd

ap = argparse.ArgumentParser()
ap.add_argument("--mbdae", required=True)
ap.add_argument("--scene", required=True)
ap.add_argument("--ref", required=True)
ap.add_argument("--pos", required=True)
ap.add_argument("--vel", required=True)
ap.add_argument("--label", required=True)
ap.add_argument("--formulations", default="index3,index2-ggl,index1,penalty")
ap.add_argument("--tols", default="1e-2,1e-4,1e-6,1e-8,1e-10")
ap.add_argument("--csv", default="")
ap.add_argument("--ref-check", default=",")
ap.add_argument("--timeout", type=float, default=600, help="seconds per run")
ap.add_argument("--extra", default="", help="extra mbdae arguments, space separated")
a = ap.parse_args()

ref = pd.read_csv(a.ref)
pos, vel = a.pos.split(","), a.vel.split(",")
scale = {g: max(np.abs(ref[c]).max() for c in cols) for g, cols in (("pos", pos), ("vel", vel))}
out = open(a.csv, "a") if a.csv else None
for f in a.formulations.split(","):
    for tol in a.tols.split(","):
        with tempfile.TemporaryDirectory() as d:
            cmd = [a.mbdae, "run", a.scene, "--out", d, "--rtol", tol, "--formulation", f, "--quiet"] + a.extra.split()
            status, steps, res, cpu, ep, ev = "failed", 0, 0, 0.0, float("nan"), float("nan")
            wp = wv = ""
            try:
                subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout)
            except subprocess.TimeoutExpired:
                print("%s,%s,%s: timed out after %g s" % (a.label, f, tol, a.timeout), file=sys.stderr)
            sj = os.path.join(d, "summary.json")
            rc = None
            for root, _, files in os.walk(d):
                if "results.csv" in files and rc is None:
                    rc = os.path.join(root, "results.csv")
                if "summary.json" in files:
                    sj = os.path.join(root, "summary.json")
            if os.path.exists(sj):
                s = json.load(open(sj))
                status = s.get("status", "?")
                for st in s.get("steps", []):
                    if "statistics" in st:
                        steps += st["statistics"].get("steps", 0)
                        res += st["statistics"].get("residual_evaluations", 0)
                        cpu += st["statistics"].get("cpu_seconds", 0.0)
            if rc:
                r = pd.read_csv(rc)
                tcol = "t" if "t" in r.columns else r.columns[0]
                m = pd.merge_asof(ref.sort_values("time"), r.rename(columns={tcol: "time"}).sort_values("time"),
                                  on="time", suffixes=("_ref", ""), tolerance=1e-9, direction="nearest").dropna()
                dp = {c: np.abs(m[c] - m[c + "_ref"]).max() for c in pos}
                dv = {c: np.abs(m[c] - m[c + "_ref"]).max() for c in vel}
                wp, wv = max(dp, key=dp.get), max(dv, key=dv.get)
                ep, ev = dp[wp] / scale["pos"], dv[wv] / scale["vel"]
            t = float(tol)
            line = "%s,%s,%g,%d,%d,%.4g,%.3g,%.3g,%s,%s,%s,%s" % (a.label, f, t, steps, res, cpu, ep, ev, wp, wv, status,
                                                             a.ref_check)
            print(line, flush=True)
            if out:
                out.write(line + "\n")
                out.flush()
