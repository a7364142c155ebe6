"""A synthetic drive through a road tunnel past one roadside transmitter (Halili et al. 2022, sec. 3).

The measured Beveren-tunnel data of the paper are not public, so notebook 06 rebuilds the drive:
a straight two-lane tube (10 m wide, 5 m high), one transmitter on a wall inside it, a van at
about 90 km/h for 54 s that passes the transmitter near second 37, carrier 1.35 GHz, 80 MHz
bandwidth, one set of channel parameters every 0.8 m.

Measurement model (every term can be dialled in :class:`DriveConfig`):

* **Geometry.** x along the tunnel, y across (walls at ``y = +-width/2``), z up (floor at 0,
  ceiling at ``height``). The vehicle moves in the x-y plane at antenna height ``rx_height``; the
  transmitter sits at ``(tx_x, tx_y, tx_z)``. Ranges are 3-D: ``r = sqrt(|p - T|^2 + dz^2)``.
* **Doppler sign (pinned).** ``f_D = -(f_c / c) v . (p - T) / r``: an approaching vehicle sees a
  *positive* shift, a receding one a negative shift, zero at the closest point. (Halili eq. 5
  prints ``+v . (s - T)``, which is positive when receding; the text says the opposite.)
* **Multipath.** The image method in the rectangular cross-section gives the line of sight plus
  wall/ceiling/floor reflections up to ``max_order`` (amplitude ``reflection_coeff`` per bounce,
  free-space spreading, carrier phase). The *measured* delay is the peak of the band-limited
  channel impulse response (``sinc`` of width 1/B) and the *measured* Doppler the peak of the
  Doppler spectrum of a ``window_snapshots x snapshot_period`` window: paths closer than the
  resolution merge and pull the peak, which is the deterministic multipath bias.
* **Random errors** (drawn from an explicit ``rng``): white noise whose standard deviation grows
  with range as the SNR falls (``sigma(r) = sigma_0 sqrt(1 + (r / noise_ref_range)^2)``); a
  slowly varying Doppler bias from traffic and non-stationary scatterers (first-order
  Gauss-Markov, correlation length ``bias_corr_m`` metres of travel); a positive NLOS excess
  delay with the same correlation; occasional Doppler outliers (the peak locks on a moving
  scatterer, uniform within the Doppler span); dropped epochs (NaN in both streams).
* **Clocks.** The ToA carries an unknown offset ``clock_offset_s`` plus a drift
  ``clock_drift`` (s/s); the Doppler a residual carrier-frequency offset ``cfo_hz`` plus a random
  walk ``cfo_walk_hz`` (Hz/sqrt(s)).

The channel part is deterministic for a given configuration and is cached; each call of
:func:`measure` adds fresh noise from its ``rng``.

One module per job, re-exported here:

- :mod:`.config` — :class:`DriveConfig`, :data:`IDEAL` and :func:`load_drive_config`;
- :mod:`.drive` — the noise-free :class:`Drive` (:func:`make_drive`): route, line-of-sight and
  multipath-peak observables, :func:`delay_doppler_profiles`;
- :mod:`.measurement` — the noisy streams (:func:`measure`) and the GNSS fix (:func:`gnss_fix`).
"""

from __future__ import annotations

from .config import IDEAL, DriveConfig, load_drive_config
from .drive import (
    Drive,
    channel_paths,
    delay_doppler_profiles,
    doppler_shift,
    image_sources,
    make_drive,
    slant_range,
)
from .measurement import DopplerToaMeasurements, GnssFix, gnss_fix, measure

__all__ = [
    "IDEAL",
    "DopplerToaMeasurements",
    "Drive",
    "DriveConfig",
    "GnssFix",
    "channel_paths",
    "delay_doppler_profiles",
    "doppler_shift",
    "gnss_fix",
    "image_sources",
    "load_drive_config",
    "make_drive",
    "measure",
    "slant_range",
]
