"""The geometry pre-filter's labels: the kind of surface of the plane each kept path agrees with
(``geometry_labels``), and the planes' kinds (``plane_kinds``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tunnelkit.consistency import plane_kinds, tunnel_planes
from tunnelkit.simulation.drives import scenario_route
from tunnelkit.simulation.prefilter import geometry_keep, geometry_labels, traced_measurements


def test_plane_kinds_follow_tunnel_planes():
    tunnel = scenario_route("italiano2026-straight").tunnel
    planes, kinds = tunnel_planes(tunnel), plane_kinds(tunnel)
    assert len(planes) == len(kinds)
    for s in tunnel.surfaces:  # brute force: every surface's plane carries the surface's kind
        i = [k for k, p in enumerate(planes) if np.allclose(
            np.append(p.normal, p.offset), np.append(s.plane.normal, s.plane.offset), atol=1e-9
        )]  # fmt: skip
        assert len(i) == 1 and kinds[i[0]] == s.kind


def test_the_geometry_test_labels_the_true_kind_on_the_models_own_channel():
    route = scenario_route("italiano2026-straight")
    for k, seed in ((5, 1), (15, 2), (27, 3)):
        ep = route.epoch(k, np.random.default_rng(seed), refine="ml")
        keep, labels = geometry_labels(ep, route)
        assert keep.tolist() == geometry_keep(ep, route).tolist()
        truth = np.asarray(ep.truth_index)[keep]
        hit = truth >= 0
        true_kinds = [ep.paths[t].surface_kind for t in truth[hit]]
        assert labels[hit].tolist() == true_kinds
        pm, _ = traced_measurements(ep, route)  # the adapter feeds the kept rows alone
        assert set(pm.source.tolist()) <= set(keep.tolist())
    m = ep.measurements
    one = replace(ep, measurements=m.subset(np.array([0])))
    keep, labels = geometry_labels(one, route)
    assert keep.tolist() == [0] and labels.tolist() == [""]
