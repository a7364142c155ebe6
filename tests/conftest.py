"""Shared fixtures: Jiang's tunnel and its virtual stations; one synthesised epoch of the straight
drive for the extraction's bad-input tests."""

from __future__ import annotations

import numpy as np
import pytest

import tunnelkit as tk


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
