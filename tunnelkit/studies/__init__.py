"""Studies: the research beside the course, above the core and below the command line.

What was measured to choose or to check the core, kept so that it can be measured again; the
core never imports it (``tests/test_layout.py``):

- :mod:`.traced` — the traced error record: the ML route's errors per kind of path on the
  ray-traced channel, measured, stored with its provenance and read back as the traced design
  of ``tunnelkit reproduce javelin-table1|2 --channel sionna`` (notebook 07);
- :mod:`.traced_bound` — the posterior CRLB of a drive at the traced sigmas, beside the traced
  JAVELIN RMSEs;
- :mod:`.misspecified` — the misspecified-model bound: the pseudo-true paths of a channel that
  eq. 1 does not describe and the sandwich bound around them (notebook 07);
- :mod:`.attribution` — what eq. 1 misses on the traced channel: each mechanism of the ray
  tracer switched off in turn, its pseudo-true bias, extraction error and position cost
  (``docs/results/traced-attribution.md``).
- :mod:`.nuisance` — a model that absorbs what eq. 1 misses: the first-order pseudo-true bias on
  the traced channel under eq. 1, an amplitude profile across the aperture and second-order
  nuisance atoms, and the profile's cost where eq. 1 holds (``docs/results/traced-models.md``);
  :mod:`.truth` compares paths with their truth (the models themselves, each path on the elements
  that see it and the direct fit tying every atom to one UE, are the core's
  :mod:`tunnelkit.extraction.direct`, under the tracker :mod:`tunnelkit.design.traceddirect`);
- :mod:`.robust_errors` — errors the tracker can trust: robust statistics of the traced
  per-path errors (median, MAD, gross errors apart) and the traced design told them
  (``docs/results/traced-robust.md``).
- :mod:`.los_only` — the line of sight alone on the traced channel, the variants around the
  design's tracker (the pick and the table are the core's, :mod:`tunnelkit.design.los`): the path
  dropped where the fit flags it, one constant sigma (``docs/results/traced-robust.md``);
- :mod:`.odometry` — dead reckoning's drift against distance driven under the paper's white
  odometry and an automotive model, beside its posterior CRLB (``docs/results/odometry.md``).

The papers' tables (``tunnelkit reproduce``) are :mod:`tunnelkit.reproduce`, the other package of
this layer.
"""
