"""The scenario schema of your own tunnel (no ``paper`` key, family ``user``): a straight tube of
one of :data:`USER_SHAPES`, its mount and arrays, on the plates, blockers, radio, ray-tracing,
odometry and lane tables of :mod:`tunnelkit.schema.tunnel3d`."""

from __future__ import annotations

from .spec import Table, header, key_float, key_int, key_str, key_table, key_tables
from .tunnel3d import (
    ARRAY_KEYS,
    ARRAY_OFFSET,
    BLOCKER,
    HALF_ELLIPSE_FACETS,
    LANE_KEYS,
    PLATE,
    station_keys,
)

USER_SHAPES = ("rectangular", "horseshoe", "semicircular")

USER_ARRAY = Table(
    (
        *ARRAY_KEYS,
        key_float(
            "azimuth_deg",
            "boresight azimuth from +x (along the tunnel) towards +y",
            "deg",
            ge=-360.0,
            le=360.0,
            default=0.0,
        ),
        key_float(
            "tilt_deg",
            "down-tilt of the boresight below the horizontal (90 = straight down)",
            "deg",
            ge=-90.0,
            le=90.0,
            default=0.0,
        ),
        key_float(
            "spacing_wavelengths",
            "element spacing in wavelengths at radio.fc (ignored if spacing_m is given)",
            gt=0.0,
            le=100.0,
            default=0.5,
        ),
        key_float(
            "spacing_m",
            "element spacing in metres (overrides spacing_wavelengths)",
            "m",
            gt=0.0,
            le=10.0,
            optional=True,
        ),
        ARRAY_OFFSET,
    ),
    "one planar array on the mount; element 0 (a corner) is the reference antenna",
)

USER = Table(
    (
        *header(None),
        key_table(
            "tunnel",
            Table(
                (
                    key_str("kind", "cross-section shape", choices=USER_SHAPES),
                    key_float("length", "length along x", "m", gt=0.0, le=100_000.0),
                    key_float("width", "width at the road", "m", gt=0.0, le=1000.0),
                    key_float("height", "height at the centre", "m", gt=0.0, le=1000.0),
                    key_float(
                        "x_start",
                        "where the tunnel starts along x (default -length/2: centred on 0)",
                        "m",
                        optional=True,
                    ),
                    key_str(
                        "wall_material",
                        "walls and roof",
                        choices=("concrete", "metal"),
                        default="concrete",
                    ),
                    key_str(
                        "road_material",
                        "road surface",
                        choices=("concrete", "metal"),
                        default="concrete",
                    ),
                    key_tables("plates", PLATE, optional=True),
                    key_tables("blockers", BLOCKER, optional=True),
                ),
                "your tunnel: a straight tube along x, road at z = 0, centred on y = 0",
                variants={
                    "rectangular": (),
                    "semicircular": (HALF_ELLIPSE_FACETS,),
                    "horseshoe": (
                        key_int(
                            "n_facets", "planar facets of the arched roof", ge=2, le=360, default=12
                        ),
                        key_float(
                            "wall_height",
                            "height of the vertical walls where the arch starts (default: height - width/2, a semicircular roof)",
                            "m",
                            gt=0.0,
                            optional=True,
                        ),
                    ),
                },
            ),
        ),
        *station_keys(
            USER_ARRAY,
            "mount position (x, y, z), inside the tunnel",
            "the base-station mount and its arrays (one [[base_station.arrays]] per array)",
            user=True,
        ),
        key_table(
            "trajectory",
            Table(
                (
                    key_str("kind", "lane (straight) or slalom", choices=("lane", "slalom")),
                    *LANE_KEYS,
                ),
                "ground truth: constant speed along x",
                variants={
                    "lane": (),
                    "slalom": (
                        key_float("amplitude", "lateral swing around the lane centre", "m", ge=0.0),
                        key_float("wavelength", "slalom period along x", "m", gt=0.0),
                    ),
                },
            ),
        ),
    ),
    "your own tunnel (no `paper` key)",
)
