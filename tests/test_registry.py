"""The registry: every member of a family is built and run through the family's one protocol."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tunnelkit import doppler_drive as dv
from tunnelkit.tracking import registry
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.tracking.doppler import DopplerSetup, Track

EPOCHS = 12


def _jiang2023(name, cls):
    exp = vs.experiment("jiang2023-straight", level=2)
    truth = exp.truth[:EPOCHS]
    m = exp.model
    Z = m.simulate(truth[:, :2], np.random.default_rng(0), size=2)
    x0 = vs.initial_states(truth[0], exp.P0, np.random.default_rng(1), size=2)
    est = cls(m, x0[0], exp.P0, rng=np.random.default_rng(2))
    states = [est.step(None if k == 3 else Z[0, k], first=(k == 0)) for k in range(EPOCHS)]
    assert np.array(states).shape == (EPOCHS, 4) and np.all(np.isfinite(states))
    assert np.asarray(est.P).shape == (4, 4) and est.position.shape == (2,)
    est.predict()
    est.update(Z[0, 0])
    batch = cls.run(m, Z, x0, exp.P0, rng=np.random.default_rng(3))
    assert batch.shape == (2, EPOCHS, 4) and np.all(np.isfinite(batch))
    assert np.array_equal(
        batch, vs.run_estimator(name, m, Z, x0, exp.P0, rng=np.random.default_rng(3))
    )


def _halili2022(name, cls):
    drive = dv.make_drive()
    rng = np.random.default_rng(0)
    meas, fix = dv.measure(drive, rng), dv.gnss_fix(drive, rng)
    setup = DopplerSetup.from_drive(drive)
    # one set of keywords for the whole family: members ignore what they do not use
    kw = {"sigma_hz": 32.79, "q": 0.5, "adaptive": False, "sigma_toa": 3e-9, "gate": 0.999}
    trk = cls(setup, fix, **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = trk.run(meas)
    assert isinstance(tr, Track)
    assert tr.position.shape == (len(meas.t), 2) and np.all(np.isfinite(tr.position))
    assert tr.speed.shape == (len(meas.t),) and np.all(np.isfinite(tr.speed))
    p = cls(setup, fix, **kw).step(meas.doppler[1], meas.toa[1])
    assert p.shape == (2,) and np.all(np.isfinite(p))
    assert np.isfinite(trk.speed()) and isinstance(trk.n_rejected, int)


def _italiano2026(name, cls):
    from tunnelkit import simulation

    drive = simulation.simulate_drive(
        "italiano2026-straight", np.random.default_rng(0), condition="L", n_epochs=3
    )
    trk = cls.for_drive(drive)
    est, details = trk.track(drive)
    assert est.shape == (3, 3) and np.all(np.isfinite(est))
    assert len(details.estimates if hasattr(details, "estimates") else details) == 3
    np.testing.assert_array_equal(est, simulation.evaluate(drive, method=name).estimates)


#: family -> how one member is built and run (the protocol of ``registry``'s docstring)
PROTOCOLS = {"jiang2023": _jiang2023, "halili2022": _halili2022, "italiano2026": _italiano2026}
#: families whose members share no protocol yet (listed in ``registry``'s docstring)
WITHOUT_PROTOCOL: set[str] = set()


def test_every_family_has_a_protocol_or_is_listed_without_one():
    assert set(registry.families()) == set(PROTOCOLS) | WITHOUT_PROTOCOL


@pytest.mark.parametrize(
    ("family_name", "name"),
    [(f, n) for f in PROTOCOLS for n in registry.family(f)],
)
def test_member_follows_the_family_protocol(family_name, name):
    cls = registry.get(family_name, name)
    assert cls.name == name
    PROTOCOLS[family_name](name, cls)


def test_unknown_family_and_member_name_the_parameter():
    with pytest.raises(ValueError, match=r"^family_name"):
        registry.family("nobody2000")
    with pytest.raises(ValueError, match=r"^name"):
        registry.get("jiang2023", "nothing")


def test_get_loads_only_the_modules_it_needs():
    """Looking up JAVELIN imports its tracker, not the TeNFiLoc baseline beside it; the family
    lists both (a fresh process, so nothing else has loaded them)."""
    import subprocess
    import sys

    code = (
        "import sys; from tunnelkit.tracking import registry\n"
        "j = registry.get('italiano2026', 'JAVELIN')\n"
        "print(j.__name__, 'tunnelkit.tracking.javelin.tenfiloc' in sys.modules)\n"
        "print(list(registry.family('italiano2026')))\n"
    )
    # the family's order is its providers', whichever module was imported first
    late = (
        "import tunnelkit.tracking.javelin.tenfiloc, tunnelkit.tracking.upf\n"
        "from tunnelkit.tracking import registry\n"
        "print(list(registry.family('italiano2026')), list(registry.family('jiang2023')))\n"
    )
    got = subprocess.run([sys.executable, "-c", late], capture_output=True, text=True, check=True)
    assert got.stdout.strip() == "['JAVELIN', 'TeNFiLoc'] ['TSWLS', 'EKF', 'UKF', 'UPF']"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    first, second = out.stdout.splitlines()
    assert first == "Javelin False"
    assert second == "['JAVELIN', 'TeNFiLoc']"
