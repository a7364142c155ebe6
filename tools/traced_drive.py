"""Stores the traced design drives the notebooks drive, made afresh from the package.

A design drive on the ray-traced channel (:func:`tunnelkit.design.traced.design_drive`) costs
about a second of CPU per epoch: every epoch's ML extraction runs every re-initialisation there.
This script drives each case of :data:`CASES` now (never reading a stored drive: the ray tracer's
traces come from the cache, ``TUNNELKIT_RT_CACHE``, and are traced where missing) and writes its
record (:func:`tunnelkit.design.traced.drive_record`: the key, the drive's per-epoch measurements
after the geometry pre-filter and before it, the V2X messages, the generator's state after it) to
``data/rt/design/<scenario>-<array>[-T<n>]-drive.json``, which ``design_drive`` reads when a
sweep asks for that drive (:func:`tunnelkit.design.traced.stored_drive`, checked on load). Each
file written is read back through that check and compared with the drive it was made from.

    python tools/traced_drive.py            # drive and write the store
    python tools/traced_drive.py --check    # drive and compare with the stored files
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

#: (scenario, array, epochs, seed, stream): notebook 08 section 9's quick-mode drive, the 4 x 4
#: on the paper tunnel's ray-traced channel, its first 12 epochs, drive stream 0 of the held-out
#: seed 20261202 (the first unit's drive of ``design_sweep(..., seed=20261202)``)
CASES = (("italiano2026-straight", "4x4", 12, 20261202, 0),)


def case_rng(seed: int, stream: int):
    """The generator a design sweep on ``seed`` hands drive stream ``stream`` (its child)."""
    from tunnelkit.runner import spawn_rngs

    return spawn_rngs(seed, stream + 1)[stream]


def measure(case) -> tuple[Path, dict]:
    """One case's path and record, driven now."""
    from tunnelkit import design
    from tunnelkit.design import traced

    scenario, array, n_epochs, seed, stream = case
    setup = design.DesignSetup.from_scenario(scenario, channel="sionna")
    rec = traced.drive_record(setup, array, case_rng(seed, stream), n_epochs)
    rec = {**rec, "made_by": {"tool": "tools/traced_drive.py", "seed": seed, "stream": stream}}
    return traced.stored_drive_path(setup, array, n_epochs), json.loads(json.dumps(rec))


def read_back(case, path: Path) -> None:
    """Read ``path`` as ``design_drive`` would (its key and fields checked) and compare the drive
    with the stored record field by field; raises when it is not used or differs."""
    import numpy as np

    from tunnelkit import design
    from tunnelkit.design import traced
    from tunnelkit.design._drivestore import drive_to_record

    scenario, array, n_epochs, seed, stream = case
    setup = design.DesignSetup.from_scenario(scenario, channel="sionna")
    stored = json.loads(path.read_text())["drives"]
    for kind in traced.DRIVE_KINDS:
        rng = case_rng(seed, stream)
        drive = traced.stored_drive(setup, array, rng, n_epochs, path=path, kind=kind)
        if drive is None:
            raise SystemExit(f"{path}: not read for its own case (its key does not match)")
        if drive_to_record(drive, rng.bit_generator.state) != stored[kind]:
            raise SystemExit(f"{path}: read back, its {kind} drive differs from what was written")
        np.testing.assert_array_equal(drive.truth, setup.trajectory.position[: len(drive.epochs)])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the stored files")
    args = ap.parse_args(argv)
    import os

    from tunnelkit import build_dir
    from tunnelkit.rt.cache import CACHE_ENV

    os.environ.setdefault(CACHE_ENV, str(build_dir("rt", "cache")))  # as the notebooks do
    bad = 0
    for case in CASES:
        path, rec = measure(case)
        if args.check:
            stored = json.loads(path.read_text()) if path.is_file() else None
            if stored != rec:
                print(f"{path}: differs from a fresh drive; run tools/traced_drive.py")
                bad += 1
                continue
            read_back(case, path)
            print(f"{path}: {len(rec['drives']['ml-traced']['epochs'])} epochs, as driven now")
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(rec, indent=1) + "\n")
        read_back(case, path)
        print(f"wrote {path}: {len(rec['drives']['ml-traced']['epochs'])} epochs")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
