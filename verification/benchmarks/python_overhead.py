#!/usr/bin/env python3
"""The Python package's cost: (1) a Python call's CPU over the CLI's own for Dynamics I
(target: under 5 % more), (2) sweep throughput (Dynamics II runs) with 1 and 2 local Dask workers (target: 2
workers at least 1.7 times 1 worker), and with 1 and 2 threads (the default since issue 26).

    PYTHONPATH=build/python /usr/bin/python3 verification/benchmarks/python_overhead.py [--repeat 15] [--runs 12]

CPU times, not wall-clock, for (1): the CLI's is its process's user + system time (getrusage of
the child: start-up, loading, solving, writing results.csv and summary.json); the Python call's
is this process's CPU time across mbdae.load(path).run() and building the pandas table. (2) is
wall-clock (a throughput), from the first submit to the last result, the cluster already started;
on a shared machine it shows the contention. Results: docs/python.md."""
import argparse
import os
import resource
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import mbdae

ROOT = Path(__file__).resolve().parents[2]
STEP = ROOT / "cases" / "five_point_suspension" / "dynamics_step.yaml"
POSTER = ROOT / "cases" / "five_point_suspension" / "dynamics_poster.yaml"  # Dynamics II: 1.5 s CPU a run


def cli_cpu(cli, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([str(cli), "run", str(STEP), "--out", str(out), "--quiet"], check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def python_cpu():
    t0 = time.process_time()
    r = mbdae.load(STEP).run()
    r.table
    return time.process_time() - t0, r.cpu_seconds()


def overhead(cli, repeat):
    with tempfile.TemporaryDirectory() as out:
        cli_cpu(cli, out), python_cpu()  # warm the caches
        clis, pys, solver = [], [], []
        for _ in range(repeat):  # interleaved, so both see the same load
            clis.append(cli_cpu(cli, out))
            p, s = python_cpu()
            pys.append(p)
            solver.append(s)
    c, p = statistics.median(clis), statistics.median(pys)
    print(f"Dynamics I, {repeat} runs each, median CPU: CLI process {c * 1e3:.1f} ms (min {min(clis) * 1e3:.1f}), "
          f"Python load+run+table {p * 1e3:.1f} ms (min {min(pys) * 1e3:.1f}); "
          f"integration steps' own cpu_seconds {statistics.median(solver) * 1e3:.1f} ms")
    print(f"  Python over CLI: {100 * (p / c - 1):+.1f} % (median), {100 * (min(pys) / min(clis) - 1):+.1f} % (min)")


def throughput_threads(n_threads, runs):
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        params = [{"rtol": 1e-7, "output_step": 0.001 * (1 + k % 2)} for k in range(runs)]
        table = mbdae.sweep(mbdae.load(POSTER), params, out, workers=n_threads, progress=False)
        wall = time.perf_counter() - t0
    assert (table["status"] == "ok").all()
    rate = len(table) / wall
    print(f"sweep of {len(table)} Dynamics II runs (20 s each), {n_threads} thread(s): {wall:.2f} s wall, "
          f"{rate:.2f} runs/s; task CPU {table['cpu_s'].sum():.2f} s, integration {table['solver_cpu_s'].sum():.2f} s")
    return rate


def throughput(n_workers, runs):
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client, tempfile.TemporaryDirectory() as out:
        client.submit(sum, [1]).result()  # workers up
        t0 = time.perf_counter()
        params = [{"rtol": 1e-7, "output_step": 0.001 * (1 + k % 2)} for k in range(runs)]
        table = mbdae.sweep(mbdae.load(POSTER), params, out, client=client, progress=False)
        wall = time.perf_counter() - t0
    assert (table["status"] == "ok").all()
    rate = len(table) / wall
    print(f"sweep of {len(table)} Dynamics II runs (20 s each), {n_workers} worker(s): {wall:.2f} s wall, "
          f"{rate:.2f} runs/s; task CPU {table['cpu_s'].sum():.2f} s, integration {table['solver_cpu_s'].sum():.2f} s, "
          f"the workers got {100 * table['cpu_s'].sum() / (wall * n_workers):.0f} % of their cores")
    return rate


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default=str(ROOT / "build" / "mbdae"))
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--runs", type=int, default=12)
    ap.add_argument("--threads-only", action="store_true", help="only the threads' throughput")
    a = ap.parse_args()
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    if a.threads_only:
        t1, t2 = throughput_threads(1, a.runs), throughput_threads(2, a.runs)
        print(f"2 threads / 1 thread: {t2 / t1:.2f} x; load average now {os.getloadavg()[0]:.2f}")
        return
    overhead(a.cli, a.repeat)
    r1 = throughput(1, a.runs)
    r2 = throughput(2, a.runs)
    print(f"2 workers / 1 worker: {r2 / r1:.2f} x; load average now {os.getloadavg()[0]:.2f}")
    t1 = throughput_threads(1, a.runs)
    t2 = throughput_threads(2, a.runs)
    print(f"2 threads / 1 thread: {t2 / t1:.2f} x; 2 threads / 2 workers: {t2 / r2:.2f} x; "
          f"load average now {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
