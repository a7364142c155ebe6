"""The design's line-of-sight tracker on the ray-traced channel, the parts that trace nothing:
the tracker's name checked once (and refused on the image channel, naming both), the angles'
information with a sigma per epoch, the CLI's refusal. The traced parts (the survey, the drive of
both kinds, the sweep) are in ``test_design_traced.py``."""

import numpy as np
import pytest

from tunnelkit import design
from tunnelkit.cli import main
from tunnelkit.design.los import los_angle_information
from tunnelkit.design.tracedtracker import TRACED_TRACKERS, checked_tracker


def test_the_tracker_is_named_once_and_the_line_of_sight_needs_the_traced_channel():
    assert TRACED_TRACKERS == ("paths", "los", "auto", "direct")
    assert checked_tracker("los", "channel", "sionna") == "los"
    assert checked_tracker("auto", "channel", "sionna") == "auto"
    for mode in ("bound", "channel"):
        for channel in ("image", "sionna"):
            assert checked_tracker("paths", mode, channel) == "paths"
    for mode, channel in (("bound", "sionna"), ("channel", "image"), ("bound", "image")):
        for name in ("los", "auto", "direct"):
            with pytest.raises(
                ValueError, match=rf"^traced_tracker: '{name}'.*mode '{mode}'.*'{channel}'"
            ):
                checked_tracker(name, mode, channel)
    for bad in ("LOS", "", None, 1):
        with pytest.raises(ValueError, match=r"^traced_tracker"):
            checked_tracker(bad, "channel", "sionna")


def test_the_sweep_refuses_the_line_of_sight_on_the_image_channel_before_any_work():
    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    for call in (
        lambda: design.design_sweep(setup, ["4x4"], mode="channel", units=1, traced_tracker="los"),
        lambda: design.sweep_montecarlo(setup, ["4x4"], 1, 0, mode="channel",
                                        traced_tracker="los"),
        lambda: design.sweep_montecarlo(setup, ["4x4"], 1, 0, traced_tracker="all"),
    ):  # fmt: skip
        with pytest.raises(ValueError, match=r"^traced_tracker"):
            call()


def test_the_cli_refuses_the_line_of_sight_without_the_traced_channel(capsys):
    args = ["design", "italiano2026-straight", "--arrays", "4x4", "--traced-tracker", "los"]
    assert main(args) == 2
    assert "--traced-tracker los" in capsys.readouterr().err
    for name in ("auto", "direct"):
        assert main([*args[:-1], name]) == 2
        assert f"--traced-tracker {name}" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main([*args[:-1], "every"])


def test_a_sigma_per_epoch_is_each_epoch_told_its_own():
    """los_angle_information with one sigma per epoch (a table's) is, epoch by epoch, the
    information with that epoch's sigmas as numbers; the information scales as 1 / sigma^2."""
    bs = np.array([0.0, 0.0, 6.0])
    ue = np.array([[20.0, -1.5, 1.5], [5.0, 2.0, 1.5], [-40.0, 0.5, 1.5], [80.0, 1.0, 1.5]])
    saz = np.radians([0.2, 1.0, 2.5, 4.0])
    sel = np.radians([0.3, 1.5, 2.0, 8.0])
    got = los_angle_information(ue, bs, saz, sel)
    for k in range(len(ue)):
        np.testing.assert_allclose(got[k], los_angle_information(ue[k : k + 1], bs, saz[k],
                                                                 sel[k])[0])  # fmt: skip
    np.testing.assert_allclose(los_angle_information(ue, bs, 2 * saz), got_both(ue, bs, saz) / 4)
    with pytest.raises(ValueError, match="sigma_angle"):
        los_angle_information(ue, bs, saz[:2])
    with pytest.raises(ValueError, match="sigma_elevation"):
        los_angle_information(ue, bs, saz, np.r_[sel[:3], -1.0])
    with pytest.raises(ValueError, match="sigma_elevation"):
        los_angle_information(ue, bs, saz, np.r_[sel[:3], 4.0])


def got_both(ue, bs, s):
    return los_angle_information(ue, bs, s, s)
