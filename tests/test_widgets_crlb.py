import numpy as np

from tunnelkit.widgets import crlb_explorer, crlb_figure
from tunnelkit.widgets.crlb import crlb_map


def test_crlb_figure_is_pure_and_tracks_noise(jiang):
    f1 = crlb_figure(0.5, 0.1)
    f2 = crlb_figure(2.0, 2.0)
    r1, r2 = np.asarray(f1.data[0].customdata), np.asarray(f2.data[0].customdata)
    assert np.all(np.isfinite(r1)) and np.all(r2 > r1)
    _, _, r = crlb_map(jiang["tunnel"], jiang["vs"], np.radians(0.5), 0.1)
    np.testing.assert_allclose(r1, r)


def test_explorer_redraws_on_slider_moves():
    ex = crlb_explorer()
    before = np.array(ex.figure.data[0].customdata)
    ex.set(sigma_d=2.0)
    after = np.array(ex.figure.data[0].customdata)
    assert np.all(after > before)
    ex.set(los=True)
    assert "LOS" in ex.figure.layout.title.text
    assert np.median(np.array(ex.figure.data[0].customdata)) < np.median(after)
