"""Stores the residual test's noise-only calibrations of the notebooks' arrays.

The ML extraction's residual test is calibrated per array, carrier and tensor shape by
:func:`tunnelkit.extraction.ml.residual.calibrated_threshold` (200 noise-only tensors: seconds for
a 6 x 6 array at 28 GHz, once per process). This script drives one epoch of each route in
:data:`CASES` with the calibration store ignored, so every calibration that epoch meets runs
afresh, and writes them to ``data/extraction/residual-null.json``
(:data:`~tunnelkit.extraction.ml.residual.STORE`), which ``calibrated_threshold`` reads, each
entry checked on load against its first draw.

    python tools/residual_null.py            # measure and write the store
    python tools/residual_null.py --check    # measure and compare with the stored file
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

#: (scenario, array) design routes whose calibrations are stored: notebook 08's section 7 (the
#: 6 x 6 at 28 GHz) and section 9 (the paper tunnel's 4 x 4, image and ray-traced channel alike),
#: and the paper's 10 x 10 of notebooks 03, 04, 04b and 07
CASES = (
    ("example-rectangular-28ghz", "6x6"),
    ("italiano2026-straight", "4x4"),
    ("italiano2026-straight", "10x10"),
)


def measure(cases=CASES) -> dict:
    """The store's record: one epoch of each case's design route on the image channel (the ML
    extraction, every calibration it needs run now)."""
    import numpy as np

    from tunnelkit import design
    from tunnelkit.extraction.ml import residual
    from tunnelkit.simulation import simulate_drive

    residual._STORED["entries"] = {}  # nothing read from the store: every calibration runs
    for scenario, array in cases:
        route = design.DesignSetup.from_scenario(scenario).signal_route(array)
        simulate_drive(route, np.random.default_rng(0), condition=None, extraction="route",
                       n_epochs=1)  # fmt: skip
    residual._STORED.clear()
    return residual.calibration_store()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the stored file")
    args = ap.parse_args(argv)
    from tunnelkit.extraction.ml.residual import STORE
    from tunnelkit.scenarios import data_dir

    path = data_dir() / STORE
    rec = measure()
    if args.check:
        stored = json.loads(path.read_text())
        if stored != rec:
            print(f"{path}: differs from a fresh calibration; run tools/residual_null.py")
            return 1
        print(f"{path}: {len(rec['entries'])} calibrations, as measured now")
        return 0
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(rec, indent=1) + "\n")
    print(f"wrote {path}: {len(rec['entries'])} calibrations")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
