"""The scenario schema of the 3-D tunnels: Italiano et al. (2026), the JAVELIN tunnel
(``paper = "italiano2026"``), and the plates, blockers, radio, ray-tracing, odometry and lane
tables it shares with your own tunnel (:mod:`tunnelkit.schema.user`)."""

from __future__ import annotations

from .._physical import CARRIER_HZ
from .spec import Key, Table, header, key_float, key_floats, key_int, key_str, key_table, key_tables

PLATE = Table(
    (
        key_str("name", "label of the road marking", optional=True),
        key_floats("x_range", "extent along the tunnel (increasing)", "m", shape=(2,)),
        key_float(
            "y", "across position of the plate centre (non-zero: one side of the tunnel)", "m"
        ),
        key_float("z", "height of the plate centre", "m", ge=0.0),
        key_float("width", "extent in the cross-section", "m", gt=0.0),
        key_float(
            "inclination_deg", "angle to the road (90 = vertical on a wall)", "deg", gt=0.0, le=90.0
        ),
    ),
    "metallic radio-reflective road markings (RRMs)",
)

BLOCKER = Table(
    (
        key_str("name", "label", optional=True),
        key_floats("lo", "lower corner (x, y, z)", "m", shape=(3,)),
        key_floats("hi", "upper corner (x, y, z), > lo on every axis", "m", shape=(3,)),
    ),
    "axis-aligned boxes that block rays (trucks)",
)

#: a semicircular cross-section's facets (the JAVELIN tunnel and your own semicircular tunnel)
HALF_ELLIPSE_FACETS = key_int(
    "n_facets", "planar facets approximating the half-ellipse", ge=2, le=360, default=12
)

MAX_SIDE = 256
SHAPE_DOC = "[rows, columns] of the URA (a ULA of n elements is [1, n]); at most 4096 elements"

#: the label and shape of an array, the first keys of every 3-D tunnel's array table
ARRAY_KEYS = (
    key_str("name", "label (e.g. '+x')", optional=True),
    Key("shape", "ints", SHAPE_DOC, shape=(2,), ge=1, le=MAX_SIDE),
)
#: an array's reference antenna, the last key of every 3-D tunnel's array table
ARRAY_OFFSET = key_floats(
    "offset",
    "reference antenna relative to base_station.position",
    "m",
    shape=(3,),
    default=[0.0, 0.0, 0.0],
)

ITALIANO_ARRAY = Table(
    (
        *ARRAY_KEYS,
        key_float(
            "azimuth_deg", "boresight azimuth from +x towards +y", "deg", ge=-360.0, le=360.0
        ),
        key_float(
            "elevation_deg",
            "boresight elevation above the horizontal (-30 = tilted down)",
            "deg",
            ge=-90.0,
            le=90.0,
        ),
        ARRAY_OFFSET,
    ),
    "one planar array (lambda/2 spacing); the reference antenna sits at position + offset",
)


def radio(user: bool) -> Table:
    return Table(
        (
            key_float("fc", "carrier frequency", "Hz", ge=CARRIER_HZ[0], le=CARRIER_HZ[1]),
            key_float("bandwidth", "channel bandwidth", "Hz", gt=0.0),
            key_float("scs", "subcarrier spacing", "Hz", gt=0.0),
            key_int("comb", "SRS comb: one tone in `comb` is used", ge=1, le=64),
            key_int("n_symbols", "SRS symbols per slot (Doppler needs >= 2)", ge=2, le=1024),
            key_float("tx_power_dbm", "UE transmit power", "dBm", ge=-50.0, le=60.0),
            key_float("noise_figure_db", "receiver noise figure", "dB", ge=0.0, le=30.0),
            key_float(
                "t_ant",
                "antenna temperature",
                "K",
                gt=0.0,
                le=1e4,
                **({"default": 298.0} if user else {}),
            ),
            key_int(
                "n_rb",
                "resource blocks of 12 subcarriers ("
                + (
                    "default: as many as fit in 98.3 % of the bandwidth, 273 at 100 MHz / 30 kHz"
                    if user
                    else "default 273"
                )
                + ")",
                ge=1,
                le=10_000,
                optional=True,
            ),
            key_float(
                "clock_bias_sigma_ns",
                "UE clock-bias standard deviation",
                "ns",
                ge=0.0,
                default=50.0,
            ),
            key_float(
                "clock_bias_limit_ns", "UE clock-bias truncation", "ns", ge=0.0, default=100.0
            ),
        ),
        "uplink SRS (5G NR) radio",
    )


#: the ray-traced channel's settings (``tunnelkit.rt.settings.RTSettings``; the same defaults,
#: material names and ranges, checked by tests/test_rt_channel.py)
RT_MATERIALS = (
    "concrete",
    "asphalt",
    "asphalt_concrete",
    "metal",
    "brick",
    "marble",
    "glass",
    "medium_dry_ground",
    "wet_ground",
)
RAYTRACING = Table(
    (
        key_float(
            "scattering_coefficient",
            "diffuse scattering coefficient S of the shell and the road (0: specular only)",
            ge=0.0,
            le=1.0,
            default=0.3,
        ),
        key_float(
            "metal_scattering_coefficient",
            "scattering coefficient of the metal plates and blockers",
            ge=0.0,
            le=1.0,
            default=0.0,
        ),
        key_str(
            "scattering_pattern",
            "lobe of the scattered power",
            choices=("lambertian", "directive"),
            default="lambertian",
        ),
        key_int(
            "alpha_r",
            "width parameter of the directive lobe (larger: narrower)",
            ge=1,
            le=100,
            default=4,
        ),
        key_int("max_depth", "bounces traced (2: second-order specular on)", ge=1, le=5, default=2),
        key_int(
            "samples_per_src", "rays shot from the vehicle", ge=100, le=10_000_000, default=20_000
        ),
        key_str(
            "wall_material",
            "material of the shell (walls and ceiling)",
            choices=RT_MATERIALS,
            default="concrete",
        ),
        key_str(
            "road_material",
            "material of the road ('asphalt': ITU very_dry_ground, 1-10 GHz; 'asphalt_concrete' 1-40 GHz)",
            choices=RT_MATERIALS,
            default="asphalt",
        ),
        key_str(
            "rrm_material", "material of the road markings", choices=RT_MATERIALS, default="metal"
        ),
        key_str("antenna_pattern", "element pattern", choices=("iso", "tr38901"), default="iso"),
        key_str(
            "array_tracing",
            "how the array is traced: one receiver per element, or one ray set at the centroid",
            choices=("element", "centre", "synthetic"),
            default="element",
        ),
    ),
    "the ray-traced channel (Sionna RT, `--channel sionna`): materials, diffuse scattering, depth",
)


#: the V2X speed and heading messages' model (``tunnelkit.scenarios.odometry``): a
#: named model, then any of its terms replaced; the figures in the units automotive data sheets use
ODOMETRY = Table(
    (
        key_str(
            "model",
            "the model the other keys start from: 'automotive' (published automotive figures, "
            "REFERENCES.md) or 'white' (the paper's white noise, section 4.2)",
            choices=("automotive", "white"),
        ),
        key_float(
            "speed_scale",
            "sigma of the wheel-speed scale factor, one draw per drive",
            ge=0.0,
            lt=1.0,
            optional=True,
        ),
        key_float(
            "speed_noise",
            "white speed noise per message (> 0: no sensor is perfect)",
            "m/s",
            gt=0.0,
            le=100.0,
            optional=True,
        ),
        key_float(
            "heading_bias_deg",
            "sigma of the heading bias at the start",
            "deg",
            ge=0.0,
            le=180.0,
            optional=True,
        ),
        key_float(
            "heading_drift_deg_per_sqrt_h",
            "the heading bias's random walk (a gyro's angle random walk)",
            "deg/sqrt(h)",
            ge=0.0,
            le=3600.0,
            optional=True,
        ),
        key_float(
            "yaw_rate_bias_deg_per_h",
            "sigma of a constant yaw-rate bias, one draw per drive",
            "deg/h",
            ge=0.0,
            le=360_000.0,
            optional=True,
        ),
        key_float(
            "heading_noise_deg",
            "white heading noise per message (> 0)",
            "deg",
            gt=0.0,
            le=180.0,
            optional=True,
        ),
        key_float(
            "rate_hz",
            "messages per second (0: one per epoch)",
            "Hz",
            ge=0.0,
            le=10_000.0,
            optional=True,
        ),
        key_float("dropout", "probability that a message is lost", ge=0.0, lt=1.0, optional=True),
    ),
    "the V2X speed and heading messages (odometry): a named model, then any of its terms "
    "replaced; without this section the paper's white model",
)


LANE_KEYS = (
    key_float("x_start", "where the vehicle starts along the tunnel", "m"),
    key_float("x_end", "where it stops (!= x_start)", "m"),
    key_float("speed", "speed along the tunnel", "m/s", gt=0.0, le=100.0),
    key_float("period", "time between epochs (one SRS slot each)", "s", gt=0.0),
    key_float("y", "lane centre across the tunnel", "m"),
    key_float("height", "UE antenna height above the road", "m", gt=0.0),
)


def station_keys(arrays: Table, position: str, doc: str, user: bool = False) -> tuple[Key, ...]:
    """The ``base_station`` (its ``position`` and ``arrays``), ``radio``, ``raytracing`` and
    ``odometry`` keys of a 3-D tunnel's file (``user``: your own tunnel's radio)."""
    station = (key_floats("position", position, "m", shape=(3,)), key_tables("arrays", arrays))
    return (
        key_table("base_station", Table(station, doc)),
        key_table("radio", radio(user)),
        key_table("raytracing", RAYTRACING, optional=True),
        key_table("odometry", ODOMETRY, optional=True),
    )


ITALIANO = Table(
    (
        *header("italiano2026"),
        key_table(
            "tunnel",
            Table(
                (
                    key_str("kind", "tunnel model", choices=("semicircular3d",)),
                    key_float("length", "length, centred on x = 0", "m", gt=0.0),
                    key_float("width", "width at the road", "m", gt=0.0),
                    key_float("height", "height at the centre", "m", gt=0.0),
                    HALF_ELLIPSE_FACETS,
                    key_tables("plates", PLATE, optional=True),
                    key_tables("blockers", BLOCKER, optional=True),
                ),
                "the JAVELIN tunnel: a half-ellipse of planar facets plus the road",
            ),
        ),
        *station_keys(
            ITALIANO_ARRAY,
            "base station (x, y, z), inside the tunnel",
            "the base station and its arrays",
        ),
        key_table(
            "trajectory",
            Table(
                (
                    key_str("kind", "trajectory model", choices=("lane3d",)),
                    *LANE_KEYS,
                    key_float(
                        "slalom_amplitude",
                        "lateral swing around the lane centre",
                        "m",
                        ge=0.0,
                        default=0.0,
                    ),
                    key_float(
                        "slalom_wavelength", "slalom period along x", "m", gt=0.0, default=20.0
                    ),
                ),
                "ground truth: constant speed along x, optional slalom",
            ),
        ),
    ),
    "Italiano et al. (2026): the JAVELIN tunnel",
)
