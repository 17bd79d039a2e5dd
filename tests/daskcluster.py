"""A real Dask cluster for the tests: ``dask scheduler`` and ``dask worker`` processes on
127.0.0.1 (not a LocalCluster inside the test process), started and stopped by the tests."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

#: seconds the scheduler and the workers get to start
START_S = 120


class Cluster:
    """A scheduler and ``workers`` single-threaded workers (no nanny: a killed worker stays
    dead, as a lost machine does), their logs in ``where``."""

    def __init__(self, where: Path, workers: int = 2) -> None:
        self.where = Path(where)
        self.where.mkdir(parents=True, exist_ok=True)
        self.file = self.where / "scheduler.json"
        self.procs: list[subprocess.Popen] = []
        self.workers: list[subprocess.Popen] = []
        self.scheduler = self._start(
            "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
            "--no-dashboard", "--scheduler-file", str(self.file), log="scheduler",
        )  # fmt: skip
        deadline = time.monotonic() + START_S
        while not self.file.is_file():
            self._alive_or_fail(deadline)
            time.sleep(0.1)
        time.sleep(0.2)
        self.address = json.loads(self.file.read_text())["address"]
        for k in range(workers):
            self.workers.append(self._start(
                "distributed.cli.dask_worker", self.address, "--nthreads", "1", "--no-nanny",
                "--host", "127.0.0.1", "--no-dashboard", "--memory-limit", "0",
                "--local-directory", str(self.where / f"w{k}"), log=f"worker{k}",
            ))  # fmt: skip
        self.wait_for_workers(workers, deadline)

    def _start(self, module: str, *args: str, log: str) -> subprocess.Popen:
        out = open(self.where / f"{log}.log", "wb")  # noqa: SIM115 - kept open with the process
        p = subprocess.Popen(
            [sys.executable, "-m", module, *args], stdout=out, stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL, env=_env(),
        )  # fmt: skip
        self.procs.append(p)
        return p

    def _alive_or_fail(self, deadline: float) -> None:
        if time.monotonic() > deadline or any(p.poll() is not None for p in self.procs):
            logs = {f.name: f.read_text()[-2000:] for f in self.where.glob("*.log")}
            self.close()
            raise RuntimeError(f"the Dask cluster did not start: {logs}")

    def wait_for_workers(self, n: int, deadline: float) -> None:
        from distributed import Client

        with Client(self.address, timeout="30s") as c:
            while len(c.scheduler_info(n_workers=-1)["workers"]) < n:
                self._alive_or_fail(deadline)
                time.sleep(0.2)
            c.run(_warm)  # compile (or load) the kernels before a test times anything

    def kill_worker(self, k: int = 0) -> None:
        """SIGKILL worker ``k``, as a machine lost mid-task."""
        self.workers[k].send_signal(signal.SIGKILL)
        self.workers[k].wait(30)

    def close(self) -> None:
        for p in self.workers:  # nothing of theirs is kept: no need to wait for a clean exit
            if p.poll() is None:
                p.kill()
        for p in reversed(self.procs):
            if p.poll() is None:
                p.terminate()
        for p in self.procs:
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def _env() -> dict[str, str]:
    """This environment, with the tests' folder importable (for :func:`_warm`)."""
    here = str(Path(__file__).parent)
    path = os.environ.get("PYTHONPATH", "")
    return {**os.environ, "PYTHONPATH": f"{path}{os.pathsep}{here}" if path else here}


def _warm() -> bool:
    import numpy as np

    from spherewarp.maps import Mobius
    from spherewarp.render import warp

    warp(np.zeros((8, 16, 3), np.uint8), Mobius.from_yaw_pitch_roll(10, 0, 0))
    return True
