"""Where a sweep's runs go: threads of this process (the default: the solver releases the GIL, so
runs proceed in parallel, and nothing is spawned, so a script without a `__main__` guard, a
notebook and stdin all work), a Dask LocalCluster of processes (client="processes"), or any
Dask cluster (a distributed.Client or a scheduler address). Each backend submits tasks, waits
for the next finished ones with a timeout, and says when it has had no worker for too long."""
import concurrent.futures
import os
import threading
import time

# Seconds any one call to the Dask scheduler may take here: with its workers killed a scheduler
# can stop answering (dask/distributed#3196), and a sweep must still end in bounded time.
SCHEDULER_CALL_TIMEOUT = 5.0


def _bounded(fn, *args):
    """Calls fn(*args) in a daemon thread and waits for it at most SCHEDULER_CALL_TIMEOUT seconds
    (a call still waiting then is left behind; an error is the lost scheduler's, ignored)."""
    def call():
        try:
            fn(*args)
        except Exception:  # noqa: BLE001 -- a lost scheduler: the caller goes on without it
            pass

    t = threading.Thread(target=call, daemon=True, name="mbdae-sweep-dask-call")
    t.start()
    t.join(SCHEDULER_CALL_TIMEOUT)


class Threads:
    name = "threads"

    def __init__(self, workers):
        self.workers = workers or os.cpu_count() or 1
        self.pool = concurrent.futures.ThreadPoolExecutor(self.workers, thread_name_prefix="mbdae-sweep")

    def submit(self, fn, *args, key=None):
        return self.pool.submit(fn, *args)

    def wait(self, pending, timeout):
        done, pending = concurrent.futures.wait(pending, timeout, concurrent.futures.FIRST_COMPLETED)
        return done, pending

    def result(self, future, timeout):
        return future.result()

    def no_workers_for(self):
        return 0.0

    def cancel(self, futures):
        for f in futures:
            f.cancel()

    def close(self, cancel=False):
        # On an error or Ctrl-C the queued runs are cancelled; runs already solving end with
        # their run (a thread cannot be stopped from outside).
        self.pool.shutdown(wait=not cancel, cancel_futures=cancel)


class Dask:
    def __init__(self, client, workers, retries):
        from distributed import Client, LocalCluster
        self.retries, self.cluster, self.own = retries, None, False
        if isinstance(client, Client):
            self.client = client
        elif client == "processes":
            n = workers or os.cpu_count() or 1
            self.cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None)
            self.client, self.own = Client(self.cluster), True
        else:
            self.client, self.own = Client(client), True
        self.name = f"dask {self.client.scheduler.address}"
        self.since_workers = time.monotonic()

    def submit(self, fn, *args, key=None):
        return self.client.submit(fn, *args, key=key, pure=False, retries=self.retries)

    def wait(self, pending, timeout):
        # The futures' own state, polled: no call to the scheduler (distributed.wait goes through
        # the client's event loop and waits without a limit if that loop stalls).
        deadline = time.monotonic() + timeout
        while True:
            done = {f for f in pending if f.done()}
            if done or time.monotonic() >= deadline:
                return done, set(pending) - done
            time.sleep(0.02)

    def result(self, future, timeout):
        """A finished run's payload, fetched from its worker within `timeout` seconds: a worker
        killed after finishing takes the result with it, and without a limit the fetch would wait
        for a recomputation that no worker is left to make."""
        return future.result(timeout=timeout)

    def no_workers_for(self):
        """Seconds since the cluster last had a worker (0 while it has one)."""
        try:
            has_workers = bool(self.client.nthreads(callback_timeout=SCHEDULER_CALL_TIMEOUT))
        except Exception:  # noqa: BLE001 -- a lost or silent scheduler counts as no workers
            has_workers = False
        now = time.monotonic()
        if has_workers:
            self.since_workers = now
        return now - self.since_workers

    def cancel(self, futures):
        _bounded(self.client.cancel, list(futures))

    def close(self, cancel=False):
        if self.own:
            _bounded(self.client.close)
            if self.cluster is not None:
                _bounded(self.cluster.close)


def backend(client, workers, retries):
    """Threads for client=None or "threads"; Dask otherwise."""
    if client is None or client == "threads":
        return Threads(workers)
    from distributed import Client
    if not (isinstance(client, Client) or isinstance(client, str)):
        raise TypeError(f"client: expected None, 'threads', 'processes', a distributed.Client or a scheduler "
                        f"address, got {client!r}")
    return Dask(client, workers, retries)
