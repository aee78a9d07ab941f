"""A sweep through a separate Dask scheduler and two workers, started here as `dask scheduler`
and `dask worker` processes on 127.0.0.1."""
import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import mbdae
from conftest import STEP


@pytest.fixture
def scheduler(tmp_path):
    file = tmp_path / "scheduler.json"
    procs = [subprocess.Popen(["dask", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(file)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.time() + 60
        while not file.exists() and time.time() < deadline:
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen(["dask", "worker", address, "--host", "127.0.0.1", "--nworkers", "1",
                                           "--nthreads", "1", "--no-dashboard", "--local-directory", str(tmp_path)],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                          env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))))
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


def test_sweep_through_a_scheduler_address(scheduler, tmp_path):
    from distributed import Client
    with Client(scheduler) as c:
        c.wait_for_workers(2, timeout=60)
        assert len(c.scheduler_info()["workers"]) == 2
    params = {"rtol": [1e-6, 1e-7, 1e-8, 1e-9], "formulation": ["index3", "index1"]}
    table = mbdae.sweep(mbdae.load(STEP), params, out=tmp_path / "out", client=scheduler,
                        metrics={"travel": mbdae.metrics.peak_deviation("wheel_z")})
    assert list(table["status"]) == ["ok"] * 8
    for i in range(8):
        alone = mbdae.load(STEP).run(rtol=table["rtol"][i], formulation=table["formulation"][i])
        samples, _, _ = mbdae.read_run(tmp_path / "out", i)
        assert np.array_equal(samples["wheel_z"].to_numpy(), alone["wheel_z"])
        assert table["travel"][i] == np.max(np.abs(alone["wheel_z"] - alone["wheel_z"][0]))
