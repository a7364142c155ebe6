"""Shared fixtures: Jiang's tunnel and its virtual stations; one synthesised epoch of the straight
drive for the extraction's bad-input tests."""

from __future__ import annotations

import numpy as np
import pytest

import tunnelkit as tk

#: the test files that take longest (seconds of CPU, or of wall time where a test waits on a
#: timeout, one worker, 2026-12-05): collected first, longest first, the rest after them in name
#: order. `make unit` hands whole files to its two workers in collection order (``--dist
#: loadfile``: a module's fixtures are built once), so no worker starts a long file while the
#: other is finishing.
SLOW_FIRST = (
    "test_montecarlo_dask.py",  # 45 s: local Dask clusters, trials past their time limit
    "test_design_traced.py",  # 35 s: the traced design, ML fits on the ray-traced channel
    "test_contracts.py",  # 33 s: the generated contracts (suite built once, 7,000 cases)
    "test_javelin_experiment.py",  # 17 s
    "test_design_sweep.py",  # 17 s
    "test_rt_crossval.py",  # 12 s: Sionna RT against the image method, 20 positions
    "test_ml_pairs.py",  # 11 s
    "test_tracking_vs.py",  # 10 s
    "test_layout.py",  # 10 s
    "test_design_tunnels.py",  # 9 s
    "test_achievable.py",  # 9 s
)


def pytest_collection_modifyitems(config, items):
    """:data:`SLOW_FIRST` first (a stable sort: each file's tests keep their order)."""
    rank = {name: i for i, name in enumerate(SLOW_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


@pytest.fixture(scope="session")
def jiang():
    sc = tk.load_scenario("jiang2023-straight")
    tunnel = sc.tunnel()
    bs = sc.base_station()
    return {
        "scenario": sc,
        "tunnel": tunnel,
        "bs": bs,
        "vs": tunnel.virtual_stations(bs),
        "start": sc.trajectory(tunnel).position[0],
    }


def random_inside(tunnel, n: int, rng: np.random.Generator, along=(-50.0, 150.0), margin=0.2):
    """Uniform random points inside a 2-D tunnel (tunnel-frame sampling)."""
    a = rng.uniform(*along, n)
    c = rng.uniform(margin, tunnel.width - margin, n)
    return tunnel.from_tunnel_frame(np.stack([a, c], -1))


@pytest.fixture(scope="session")
def epoch():
    """Epoch 10 of the straight drive: ``(H, n_paths, array, config)`` (noise seeded 0)."""
    import tunnelkit as tk

    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight")
    array, paths = route.paths(10)
    snap = tk.channel.synthesize(paths, route.config, np.random.default_rng(0))
    return snap.H, len(paths), array, route.config


@pytest.fixture
def silent_server():
    """A TCP server on 127.0.0.1 that accepts every connection and never answers (a scheduler
    that hangs): yields ``(address "127.0.0.1:PORT", the accepted connections)``; closed after."""
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    held = []

    def accept():
        while True:
            try:
                held.append(srv.accept()[0])
            except OSError:
                return

    threading.Thread(target=accept, daemon=True).start()
    try:
        yield f"127.0.0.1:{srv.getsockname()[1]}", held
    finally:
        srv.close()
        for c in held:
            c.close()
