"""Monte-Carlo trials on Dask: the same seed gives the same numbers serially and on 2 workers,
a scheduler that does not answer fails fast, a dead worker never drops a trial.

One 2-process LocalCluster on 127.0.0.1 is shared by the module (``--scheduler`` path); the CLI
tests start their own with ``--workers 2``. Trial functions live at module level so the worker
processes can import them (pytest puts ``tests/`` on ``sys.path``, which spawned workers inherit).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import os
import socket
import time

import numpy as np
import pytest

pytest.importorskip("distributed")

from distributed import LocalCluster

from tunnelkit.cli import main
from tunnelkit.doppler_drive import load_drive_config
from tunnelkit.reproduce.halili import pooled_errors
from tunnelkit.reproduce.javelin_tables import collect_routes, table_rows
from tunnelkit.runner import SchedulerUnreachable, TrialLost, parallel_options, run_trials


def _local_cluster(n_workers: int, **scheduler):
    """A local cluster of ``n_workers`` single-threaded processes on 127.0.0.1 (free ports, no
    dashboard); ``scheduler``: more scheduler settings (``allowed_failures``)."""
    return LocalCluster(
        n_workers=n_workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        scheduler_kwargs={"dashboard": False, **scheduler},
        silence_logs=40,
    )


@pytest.fixture(scope="module")
def cluster():
    """Two single-threaded worker processes; a trial may kill its worker once (not twice)."""
    with _local_cluster(2, allowed_failures=1) as c:
        yield c


def _noisy_mean(n: int, rng: np.random.Generator) -> float:
    return float(rng.standard_normal(n).mean())


def _draw(rng: np.random.Generator) -> list[float]:
    return rng.standard_normal(3).tolist()


def _die_once(marker: str, n: int, rng: np.random.Generator) -> float:
    """Trial 1 kills its worker process the first time it runs, then behaves."""
    if n == 1 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    return _noisy_mean(n, rng)


def _die_always(n: int, rng: np.random.Generator) -> float:
    if n == 1:
        time.sleep(0.3)  # let the other trials finish on their own workers first
        os._exit(1)
    return _noisy_mean(n, rng)


def _fail(n: int, rng: np.random.Generator) -> float:
    if n == 2:
        raise ArithmeticError("bad draw")
    return _noisy_mean(n, rng)


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_same_seed_same_results_serial_and_on_two_workers(cluster):
    serial = run_trials(_draw, 12, seed=11)
    remote = run_trials(_draw, 12, seed=11, scheduler=cluster.scheduler_address)
    assert remote == serial and len({tuple(r) for r in serial}) == 12
    assert run_trials(_draw, 12, seed=11, workers=1) == serial  # a LocalCluster of one process
    gen = run_trials(_draw, 5, np.random.default_rng(3), scheduler=cluster.scheduler_address)
    assert gen == run_trials(_draw, 5, np.random.default_rng(3))
    sizes = [1, 50, 3, 7, 2, 9]
    trial = functools.partial(_noisy_mean)
    serial = run_trials(trial, 6, seed=2, inputs=sizes)
    assert run_trials(trial, 6, seed=2, inputs=sizes, scheduler=cluster.scheduler_address) == serial
    # trial i always gets child stream i, whatever the inputs: same as a hand loop
    rngs = [np.random.default_rng(s) for s in np.random.SeedSequence(2).spawn(6)]
    assert serial == [_noisy_mean(n, r) for n, r in zip(sizes, rngs)]
    assert run_trials(trial, 6, seed=2, inputs=np.array(sizes)) == serial


def _busy_where(rng: np.random.Generator) -> str:
    """A trial of 0.2 s of CPU that returns its worker's address."""
    from distributed import get_worker

    t = time.process_time()
    while time.process_time() - t < 0.2:
        rng.standard_normal(64)
    return get_worker().address


@pytest.mark.parametrize("desc", ["italiano2026-slalom drives", "trials"])
def test_trials_spread_over_both_workers_whatever_the_description(cluster, desc):
    """A table's ``desc`` (a hyphen, then words with a space) once put the shared trial in the
    tasks' own Dask group: every task ran on the worker holding it, none was stolen."""
    where = run_trials(_busy_where, 24, seed=1, desc=desc, scheduler=cluster.scheduler_address)
    counts = {a: where.count(a) for a in set(where)}
    assert len(counts) == 2 and min(counts.values()) >= 6, counts


def test_worker_death_reruns_the_trial(cluster, tmp_path):
    marker = str(tmp_path / "died")
    sizes = [4, 1, 5, 6]
    trial = functools.partial(_die_once, marker)
    out = run_trials(trial, 4, seed=9, inputs=sizes, scheduler=cluster.scheduler_address)
    assert os.path.exists(marker)  # the worker did die
    assert out == run_trials(_noisy_mean, 4, seed=9, inputs=sizes)  # and nothing was dropped


def test_worker_dying_every_time_stops_the_run_naming_the_trial(cluster):
    # trial 1 kills its worker every time; a trial queued on the same worker can be lost with it
    with pytest.raises(TrialLost, match=r"trial [0-2] of 3 \(trials\) was lost"):
        run_trials(_die_always, 3, seed=0, inputs=[2, 1, 3], scheduler=cluster.scheduler_address)


def test_trial_exception_propagates_with_its_index(cluster):
    with pytest.raises(ArithmeticError, match="bad draw") as info:
        run_trials(_fail, 4, seed=0, inputs=[1, 3, 2, 5], scheduler=cluster.scheduler_address)
    assert any("trial 2 of 4" in n for n in info.value.__notes__)


def test_dead_scheduler_fails_within_the_timeout():
    addr = f"tcp://127.0.0.1:{_closed_port()}"
    t0 = time.perf_counter()
    with pytest.raises(SchedulerUnreachable, match=r"scheduler: no Dask scheduler .* within 1 s"):
        run_trials(_draw, 3, seed=0, scheduler=addr, timeout=1.0)
    assert time.perf_counter() - t0 < 6.0
    assert issubclass(SchedulerUnreachable, ValueError)  # the CLI reports it as bad input


def test_cli_dead_scheduler_is_an_error_not_a_hang(capsys):
    addr = f"tcp://127.0.0.1:{_closed_port()}"
    argv = ["reproduce", "jiang-crlb", "--runs", "10", "--scheduler", addr]
    assert main([*argv, "--connect-timeout", "1"]) == 2
    assert "scheduler: no Dask scheduler answered" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("kwargs", "exc", "match"),
    [
        ({"workers": 0}, ValueError, "workers: must be >= 1"),
        ({"workers": 2.0}, TypeError, "workers: expected an integer"),
        ({"workers": "2"}, TypeError, "workers: expected an integer"),
        ({"workers": True}, TypeError, "workers: expected an integer"),
        ({"workers": 2, "scheduler": "tcp://127.0.0.1:8786"}, ValueError, "workers, scheduler"),
        ({"scheduler": 8786}, TypeError, "scheduler: expected an address"),
        ({"scheduler": "tcp://127.0.0.1"}, ValueError, "scheduler: expected an address"),
        ({"scheduler": "http://127.0.0.1:8786"}, ValueError, "scheduler: expected an address"),
        ({"scheduler": "tcp://:8786"}, ValueError, "scheduler: expected an address"),
        ({"scheduler": "tcp://h:99999"}, ValueError, "scheduler: expected an address"),
        ({"scheduler": "tcp://h:8786/x"}, ValueError, "scheduler: expected an address"),
        ({"inputs": [1, 2]}, ValueError, "inputs: expected 3 items"),
        ({"inputs": "abc"}, TypeError, "inputs: expected a sequence"),
        ({"timeout": 0}, ValueError, "timeout: must be > 0"),
        ({"retries": -1}, ValueError, "retries: must be >= 0"),
    ],
)
def test_bad_parallel_options(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        run_trials(_noisy_mean if "inputs" in kwargs else _draw, 3, seed=0, **kwargs)


def test_scheduler_address_is_normalised():
    assert parallel_options(None, "10.0.0.5:8786") == (None, "tcp://10.0.0.5:8786")
    assert parallel_options(3, None) == (3, None)
    assert parallel_options(None, None) == (None, None)


def _reproduce_json(capsys, *argv: str) -> dict:
    assert main(["reproduce", *argv, "--format", "json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_reproduce_json_identical_serially_and_with_two_local_workers(capsys):
    args = ("jiang-crlb", "--runs", "300", "--seed", "5")
    serial = _reproduce_json(capsys, *args)
    parallel = _reproduce_json(capsys, *args, "--workers", "2")
    assert parallel == serial
    assert serial["rows"][0]["rmse_ls_m"] > 0


def test_reproduce_json_identical_on_a_running_cluster(cluster, capsys):
    args = ("jiang-table3", "--runs", "1", "--seed", "2")
    serial = _reproduce_json(capsys, *args)
    assert _reproduce_json(capsys, *args, "--scheduler", cluster.scheduler_address) == serial


def test_halili_errors_identical_on_a_running_cluster(cluster):
    short = dataclasses.replace(load_drive_config(), duration=8.0, pass_time=4.0)
    serial = pooled_errors(3, 4, config=short)
    remote = pooled_errors(3, 4, config=short, scheduler=cluster.scheduler_address)
    assert serial.keys() == remote.keys()
    assert all(np.array_equal(serial[k], remote[k]) for k in serial)


def test_javelin_drives_identical_on_a_running_cluster(cluster):
    kw = {"n_epochs": 3, "extractions": ("paper",)}
    serial = collect_routes("italiano2026-straight", ("L",), 2, 7, **kw)["paper"]
    remote = collect_routes(
        "italiano2026-straight", ("L",), 2, 7, scheduler=cluster.scheduler_address, **kw
    )["paper"]
    ref = "italiano2026_table1"
    assert table_rows({"paper": remote}, ref) == table_rows({"paper": serial}, ref)


def test_cli_bad_parallel_options(capsys):
    assert main(["reproduce", "jiang-crlb", "--runs", "10", "--workers", "0"]) == 2
    assert "workers: must be >= 1" in capsys.readouterr().err
    assert main(["reproduce", "jiang-crlb", "--scheduler", "tcp://127.0.0.1"]) == 2
    assert "scheduler: expected an address" in capsys.readouterr().err
    with pytest.raises(SystemExit):  # argparse: not allowed with argument --workers
        main(["reproduce", "jiang-crlb", "--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"])
    assert "not allowed with" in capsys.readouterr().err


def _sleep(seconds: float, rng: np.random.Generator) -> float:
    time.sleep(seconds)
    return float(rng.random())


def test_silent_scheduler_fails_within_the_timeout(silent_server):
    """A server that accepts the TCP connection and never answers: a clear error, no hang."""
    addr, held = silent_server
    t0 = time.perf_counter()
    with pytest.raises(SchedulerUnreachable, match=r"no Dask scheduler answered .* within 1 s"):
        run_trials(_draw, 3, seed=0, scheduler=addr, timeout=1.0)
    assert time.perf_counter() - t0 < 10.0  # not the 120 s it hung before (loaded CI: margin)
    assert held  # the connection was accepted: the probe, not the connect, timed out


def test_a_trial_past_its_timeout_stops_the_run_serially_and_on_dask(cluster):
    from tunnelkit.runner import TrialTimeout

    t0 = time.perf_counter()
    with pytest.raises(TrialTimeout, match="trial 1 of 2"):
        run_trials(_sleep, 2, seed=0, inputs=[0.0, 30.0], trial_timeout=0.5)
    assert time.perf_counter() - t0 < 15.0  # the 30 s trial was stopped, not waited for
    # a run whose trials each finish in time is unchanged by the limit (and the workers have
    # imported this module before the clock starts)
    ok = run_trials(_draw, 4, seed=3, scheduler=cluster.scheduler_address, trial_timeout=30.0)
    assert ok == run_trials(_draw, 4, seed=3)
    # the hung trial keeps its worker asleep after the run has stopped: it runs on a cluster of
    # its own, closed here, so that it does not hold up the next tests' trials on the module's
    with _local_cluster(2) as own:
        run_trials(_draw, 4, seed=3, scheduler=own.scheduler_address)  # workers import this module
        t0 = time.perf_counter()
        # the hung trial is named (on a loaded machine the quick ones may be named with it: the
        # limit runs from the last finished trial, and their start may be late)
        with pytest.raises(TrialTimeout, match=r"trials \[(0, )?1(, 2)?\] of 3"):
            run_trials(
                _sleep,
                3,
                seed=0,
                inputs=[0.0, 60.0, 0.0],
                scheduler=own.scheduler_address,
                trial_timeout=3.0,
            )
        assert time.perf_counter() - t0 < 30.0  # the 60 s trial was not waited for


def test_workers_beyond_the_cores_are_capped_with_a_warning(monkeypatch):
    import tunnelkit.runner as mc

    monkeypatch.setattr(mc, "available_cores", lambda: 1)
    with pytest.warns(RuntimeWarning, match="workers: 64 processes on 1 core"):
        out = run_trials(_draw, 2, seed=5, workers=64)
    assert out == run_trials(_draw, 2, seed=5)


def test_trials_sharing_a_stream_see_the_same_numbers():
    with pytest.raises(
        ValueError, match=r"streams: stream 0 is given 2 times.*shared_streams=True"
    ):
        run_trials(_draw, 4, seed=9, streams=[0, 1, 0, 1])
    out = run_trials(_draw, 4, seed=9, streams=[0, 1, 0, 1], shared_streams=True)
    assert out[0] == out[2] and out[1] == out[3] and out[0] != out[1]
    assert out[:2] == run_trials(_draw, 2, seed=9)
    with pytest.raises(ValueError, match="streams: expected 4 values"):
        run_trials(_draw, 4, seed=9, streams=[0, 1])
    with pytest.raises(ValueError, match="streams: must be >= 0"):
        run_trials(_draw, 2, seed=9, streams=[0, -1])
    with pytest.raises(ValueError, match="trial_timeout: must be > 0"):
        run_trials(_draw, 2, seed=9, trial_timeout=0)


def test_a_pool_shares_one_cluster_between_steps_with_the_serial_numbers():
    from tunnelkit.runner import TrialPool, trial_pool

    serial = run_trials(_draw, 6, seed=4)
    with trial_pool() as pool:
        assert isinstance(pool, TrialPool) and not pool.parallel
        assert pool.map(abs, [-1, 2, -3]) == [1, 2, 3]
        assert run_trials(_draw, 6, seed=4, pool=pool) == serial
    with trial_pool(workers=2) as pool:
        assert pool.parallel
        assert pool.map(abs, [-1, 2, -3]) == [1, 2, 3]  # in order
        assert run_trials(_draw, 6, seed=4, pool=pool) == serial
        assert run_trials(_draw, 6, seed=4, pool=pool) == serial  # the same cluster, twice
    with pytest.raises(ValueError, match="pool"), trial_pool() as pool:
        run_trials(_draw, 2, seed=0, pool=pool, workers=1)
    with pytest.raises(TypeError, match="pool"):
        run_trials(_draw, 2, seed=0, pool="cluster")


def _scaled(n: int) -> np.ndarray:
    return np.arange(n, dtype=float)


def _dot(v: np.ndarray, rng: np.random.Generator) -> float:
    return float(v @ rng.standard_normal(v.size))


def test_prepared_inputs_and_chunked_trials_give_the_serial_numbers(cluster):
    # per-item state built on the cluster feeds the trials without a round trip through the
    # client; trials go in several per task (20 trials on 2 threads: 2 per task)
    from tunnelkit.runner import trial_pool

    sizes = [3, 5, 4, 6]
    inputs = [s for s in sizes for _ in range(5)]
    streams = [r for _ in sizes for r in range(5)]
    kw = {"streams": streams, "shared_streams": True}
    serial = run_trials(_dot, 20, 7, inputs=[_scaled(n) for n in inputs], **kw)
    for pool_kw in ({}, {"scheduler": cluster.scheduler_address}):
        with trial_pool(**pool_kw) as pool:
            handles = pool.prepare(_scaled, sizes)
            ins = [handles[sizes.index(n)] for n in inputs]
            assert run_trials(_dot, 20, 7, inputs=ins, pool=pool, **kw) == serial
            assert [len(v) for v in pool.gather(handles)] == sizes
    # a trial that raises inside a task of several is still named
    with pytest.raises(ArithmeticError, match="bad draw") as info:
        run_trials(
            _fail, 20, 0, inputs=[1] * 7 + [2] + [1] * 12, scheduler=cluster.scheduler_address
        )
    assert any("trial 7 of 20" in n for n in info.value.__notes__)


def test_a_cluster_without_workers_stops_the_run_instead_of_hanging(monkeypatch):
    # workers killed and never restarted (seen on a loaded machine) left a run waiting for ever
    import tunnelkit.runner as mc

    monkeypatch.setattr(mc, "NO_WORKER_WAIT_S", 2.0)
    with _local_cluster(0) as empty:
        t0 = time.perf_counter()
        with pytest.raises(TrialLost, match=r"no worker for 2 s"):
            run_trials(_draw, 3, seed=0, scheduler=empty.scheduler_address)
        assert time.perf_counter() - t0 < 60.0


def test_trials_have_a_default_time_limit_and_nested_runs_keep_the_outer_one():
    import inspect

    from tunnelkit.runner import TRIAL_TIMEOUT_S, TrialTimeout

    assert inspect.signature(run_trials).parameters["trial_timeout"].default == TRIAL_TIMEOUT_S
    assert 60.0 <= TRIAL_TIMEOUT_S <= 3600.0
    # an inner run (its own, longer limit) inside an outer trial: the outer limit still fires
    t0 = time.perf_counter()
    with pytest.raises(TrialTimeout, match="trial 0 of 1 \\(outer\\)"):
        run_trials(_nested_sleep, 1, seed=0, trial_timeout=1.0, desc="outer")
    assert time.perf_counter() - t0 < 10.0


def _nested_sleep(rng):
    run_trials(_sleep, 1, seed=0, inputs=[0.0], trial_timeout=600.0, desc="inner")
    time.sleep(30.0)
