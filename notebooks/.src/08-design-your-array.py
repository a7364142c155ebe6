# %% [markdown]
# # 08 · Design your array: how many antennas for *your* tunnel?
#
# *Italiano et al. (2026), eq. 1 (the channel tensor), section 3.1 (the SR-NF validity bound) and
# section 4 (JAVELIN); the position error bound is ours, built from the same model.*
#
# **What you will learn**
#
# - how to ask the engineer's question — *"my tunnel is 8 m wide and 6 m high, the base station
#   hangs under the ceiling, 28 GHz, 400 MHz: how many antennas, and what accuracy along the
#   tunnel?"* — and get an answer in one call (and one command, `tunnelkit design`);
# - the **position error bound** (PEB): the Fisher information of every path in the tensor of
#   eq. 1, mapped to the vehicle's position through the image method, with the clock bias, gains
#   and Dopplers as nuisances; with and without curvature, with and without road markings;
# - the exact **SR-NF validity** of notebook 02, now for every surface a path reflects on — and
#   why under a ceiling the *ceiling* decides how large the array may be;
# - PEB and SR-NF share against array size in the paper's tunnel, with its 10 × 10 marked, and a
#   Monte-Carlo JAVELIN RMSE beside the bound;
# - an explorer (carrier, bandwidth, array size, tilt, mount height) that redraws all of it on
#   every move.

# %%
from dataclasses import replace

import numpy as np

import tunnelkit as tk
from tunnelkit import design
from tunnelkit.plots.design import route_figure, size_figure
from tunnelkit.widgets.design import design_explorer, design_figure

tk.setup_notebook()

# %% [markdown]
# ## 1. Your tunnel as data
#
# A user tunnel is a TOML file without a `paper` key (the schema is documented in
# `data/scenarios/README.md`). `tunnelkit scenarios new mytunnel --from example-rectangular-28ghz`
# writes a commented copy to edit; here we load the example itself: a rectangular tunnel 8 m wide
# and 6 m high, the base station 20 cm under the ceiling with two URAs looking both ways (tilted
# 20° down), 5G NR FR2 uplink SRS at 28 GHz over 400 MHz, a car in the right lane driving towards
# the base station from 60 m to 5 m.
#
# `design.DesignSetup` keeps what a design needs: the tunnel, the mounts (the **centre** of each
# array), the route and the radio. Carrier, bandwidth, tilt and mount height can be overridden.

# %%
setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
cfg = setup.config
print(
    f"tunnel {setup.tunnel.width:g} m x {setup.tunnel.height:g} m, surfaces:",
    sorted({s.kind for s in setup.tunnel.surfaces}),
)
print("mounts:", [(m.name, m.centre.tolist()) for m in setup.mounts])
print(
    f"fc {cfg.fc / 1e9:g} GHz, {cfg.n_tones} SRS tones x {cfg.n_symbols} symbols, "
    f"N0 = {cfg.noise_power:.3g} W, route: {len(setup.trajectory)} epochs"
)

# %% [markdown]
# ## 2. What one path says about the vehicle
#
# The tensor of eq. 1 is a sum of rank-1 terms, one per path $\ell$:
#
# $$H[m,s,k] = \sum_\ell \alpha_\ell\, a_m(\mathbf s_\ell)\, e^{j s \mu_{f,\ell}}\,
#   e^{j k \mu_{t,\ell}}, \qquad a_m(\mathbf s) = e^{j \frac{2\pi}{\lambda}
#   (\|\mathbf s - \mathbf p_m\| - \|\mathbf s - \mathbf p_0\|)},$$
#
# with the wave origin $\mathbf s_\ell$ (the UE for the LoS, the virtual UE for a reflection),
# $\mu_{f,\ell} = -2\pi\Delta f\,(d_\ell / c + b)$ (delay distance plus the UE clock bias $b$,
# common to every path) and $\mu_{t,\ell} = 2\pi T_0 f_{D,\ell}$. Per path the unknowns are
# $\boldsymbol\eta_\ell = [\Re\alpha_\ell, \Im\alpha_\ell, \mu_{f,\ell}, \mu_{t,\ell},
# \mathbf s_\ell]$ (the wave origin holds direction and curvature). With noise
# $\mathcal{CN}(0, N_0)$ their joint Fisher information is
#
# $$\mathbf J_\eta = \tfrac{2}{N_0}\,\Re\!\left(\mathbf D^H \mathbf D\right),
#   \qquad \mathbf D = \partial\,\mathrm{vec}\,\mathbf H / \partial \boldsymbol\eta ,$$
#
# evaluated from the rank-1 structure (inner products factorise over array, tones and symbols),
# cross terms between paths included. `tk.extraction.crlb_paths` inverts it per path: the
# per-path CRLBs of notebook 03.

# %%
pb = design.path_bounds(setup, "8x8")
for kind in ("los", "wall", "ceiling", "road", "rrm"):
    sel = pb["kind"] == kind
    print(
        f"{kind:8s} paths {sel.sum():3d}: CRLB d {1e3 * np.median(pb['d'][sel]):.3g} mm, "
        f"direction {np.degrees(np.median(pb['direction'][sel])):.2g} deg, "
        f"curvature {np.median(pb['kappa'][sel]):.3g} m"
    )

# %% [markdown]
# ## 3. From paths to the vehicle: the position error bound
#
# The geometry is known, so every path parameter is a function of the UE position $\mathbf p$:
# a specular path's wave origin is the UE mirrored in its plane,
# $\mathbf s_\ell = \mathbf S_\ell \mathbf p + \mathbf c_\ell$ with
# $\mathbf S_\ell = \mathbf I - 2\mathbf n_\ell\mathbf n_\ell^T$ (the LoS: $\mathbf S = \mathbf I$),
# and its delay distance is $\|\mathbf s_\ell - \mathbf p_0\| + c\,b$. With
# $\boldsymbol\theta = [\mathbf p,\; c b,\; (\Re\alpha_\ell, \Im\alpha_\ell, \mu_{t,\ell})_\ell]$
# and $\mathbf T = \partial\boldsymbol\eta / \partial\boldsymbol\theta$,
#
# $$\mathbf J_\theta = \mathbf T^T \mathbf J_\eta \mathbf T, \qquad
#   \mathrm{PEB} = \sqrt{\mathrm{tr}\,[\mathbf J_\theta^{-1}]_{\mathbf p}} .$$
#
# The gains and Dopplers are nuisances (a Doppler says nothing about *where* the car is without
# its velocity), and so is the clock bias: delays only count as differences, as in JAVELIN's
# $\Delta d$. We bound the horizontal position with the antenna height known (JAVELIN's setting).
# *Without curvature* every wavefront radius becomes one more nuisance: the array then measures
# directions only. `tests/test_design.py` checks this closed form against a brute-force Fisher
# information (perturb the UE, re-trace, re-synthesise the tensor with `tk.channel`,
# $\frac{2}{N_0}\Re(\mathbf J^H\mathbf J)$) to a relative $10^{-4}$.

# %%
b8 = design.route_bounds(setup, "8x8")
variants = {
    "no curvature": design.route_bounds(setup, "8x8", curvature=False),
    "no road markings": design.route_bounds(setup, "8x8", markings=False),
}
print(
    f"8x8: median PEB {100 * np.median(b8.peb):.3g} cm; "
    + ", ".join(f"{k} {100 * np.median(v.peb):.3g} cm" for k, v in variants.items())
)

# %% [markdown]
# ## 4. SR-NF validity, every surface
#
# Notebook 02 asked whether one wall-reflected path still looks like a spherical wave from the
# reflection point (the SR-NF model behind eq. 51). The exact test is the same for any plane:
# the largest phase mismatch across the array between the true wavefront (centred on the VUE)
# and the SR-NF one,
#
# $$\Delta\Phi = \max_m \tfrac{2\pi}{\lambda}\left|(\|\mathbf s - \mathbf p_m\| - \|\mathbf s -
#   \mathbf p_0\|) - (\|\mathbf r - \mathbf p_m\| - \|\mathbf r - \mathbf p_0\|)\right|
#   \le \varepsilon_\Phi ,$$
#
# with $\mathbf r$ the reflection point. An epoch is valid when every path it uses passes. Below,
# the PEB along the tunnel (red crosses: SR-NF fails) and the mismatch per surface: the ceiling,
# 20 cm above the array, is so close that its reflection point is deep in the array's near field.

# %%
# headline: peb-along-the-tunnel
route_figure(b8, variants=variants, target=0.15, title="8x8 URA at 28 GHz under the ceiling").show()
print("SR-NF valid share per surface:", b8.surface_validity())

# %% [markdown]
# ## 5. The answer: sweep the candidates
#
# `design.design_sweep` evaluates each candidate along the route. With `criterion="srnf"` (an
# estimator built on the SR-NF model, eq. 51) an epoch counts only where SR-NF holds, and the
# smallest candidate whose bound meets the target on a chosen share of the settled route (the
# first second, the tracker's start-up, left out) passes; without a Monte-Carlo that is a
# necessary condition, not an answer. The default criterion, `"achievable"`, is the design's
# VUE-curvature tracker's, for which SR-NF is information only. The same from a shell:
#
#     tunnelkit design example-rectangular-28ghz --arrays 2x2 3x3 4x4 8x8 16x16 --target 0.15 \
#         --criterion srnf
#
# (add `--format json` for a machine-readable answer, `--runs N` for a Monte-Carlo RMSE).

# %%
candidates = ["2x2", "3x3", "4x4", "8x8", "16x16", "2x16"]
answer = design.design_sweep(setup, candidates, target=0.15, share=0.9, criterion="srnf")
print(answer.to_table())

# %% [markdown]
# Read the table left to right. The median PEB is a few centimetres or less for every candidate —
# with 400 MHz and the SNR of an SRS slot the delay differences alone pin the car down — and only
# the 2 × 2 misses 15 cm, far from the base station in the first second of the drive, which the
# decision leaves out. From 3 × 3 on the **binding constraint is
# SR-NF validity**, set by the ceiling: a 3 × 3 array keeps the SR-NF model valid almost
# everywhere; from 4 × 4 on the ceiling path breaks it on part of the route, from 8 × 8 on
# everywhere. A larger array remains useful, but only with an estimator that models the ceiling
# path's wavefront as centred on its VUE (JAVELIN with
# `kappa_model="vue"`), not with the SR-NF model.

# %%
# headline: peb-srnf-vs-size-28ghz
size_figure(answer.rows, mark=None, title="28 GHz, 8 m x 6 m tunnel: PEB and SR-NF share").show()

# %% [markdown]
# ## 6. The paper's tunnel, 4 × 4 to 32 × 32
#
# The JAVELIN tunnel (semicircular, 10 m × 5 m, 5.9 GHz, 100 MHz). A 32 × 32 URA at 5.9 GHz is
# 0.8 m on a side and does not fit with its centre at 4.8 m under a 5 m roof
# (`setup.arrays` refuses it); we lower the mount to 4.5 m for the whole sweep.

# %%
paper = design.DesignSetup.from_scenario("italiano2026-straight", mount_height=4.5)
sizes = ["4x4", "8x8", "10x10", "16x16", "24x24", "32x32"]
sweep = design.design_sweep(paper, sizes, target=0.2)
# headline: peb-srnf-vs-size-paper
size_figure(sweep.rows, mark="10x10", title="Paper's tunnel, 5.9 GHz: PEB and SR-NF share").show()
print(sweep.to_table())

# %% [markdown]
# ## 7. Does a tracker reach the bound? Monte-Carlo JAVELIN
#
# A bound is only useful beside an estimator. `design.javelin_rmse` drives the route through the
# whole signal chain (tensor, noise, clock bias, the maximum-likelihood extraction of notebook 03,
# Algorithm 1) and tracks with JAVELIN (our design, curvature centred on the VUE). No 5.9 GHz
# constant enters: each path arrives with the covariance the extraction reports for itself,
# the CRLB evaluated at its estimate (`extraction.estimate_crlb`), which the ML stage attains
# (notebook 03). The tracker uses these per path (`measurement_noise="reported"`), so a sweep is
# fair at any carrier and size. Two safeguards make such tight measurements usable:
#
# - an epoch whose fit fails its own residual test (a wrong basin, where the bound at the
#   estimate says nothing about the error) is predict-only;
# - association ranks pairs by the negative log-likelihood $\eta^2 + \ln\det S$ instead of
#   eq. 58's $\eta^2$ alone, so a new track born with $\sigma_P = 10$ m cannot take a path that
#   an established track predicts to a millimetre.
#
# The first second of each drive is the tracker's start-up from a 1 m fix; the **settled** RMSE
# leaves it out and is set beside the RMS of the PEB over the same epochs. The interval is a
# 95 % t-interval over the drives (quick mode: 2 drives of 14 epochs).

# %%
runs = tk.mc_count(6, 2)
n_epochs = 14 if tk.quick_mode() else None
mc = design.javelin_rmse(paper, "10x10", runs, seed=2026, n_epochs=n_epochs)
settled_ratio = mc["rmse_settled_m"] / mc["peb_rms_settled_m"]
print(
    f"10x10 over {runs} drives: whole-drive RMSE {100 * mc['rmse_m']:.3g} cm "
    f"[{100 * mc['ci95_m'][0]:.3g}, {100 * mc['ci95_m'][1]:.3g}]; settled RMSE "
    f"{1000 * mc['rmse_settled_m']:.3g} mm [{1000 * mc['settled_ci95_m'][0]:.3g}, "
    f"{1000 * mc['settled_ci95_m'][1]:.3g}] against an RMS PEB of "
    f"{1000 * mc['peb_rms_settled_m']:.3g} mm ({settled_ratio:.1f} x the bound); median settled "
    f"error {1000 * mc['median_settled_m']:.3g} mm"
)

# %% [markdown]
# Once settled, the typical epoch (the median) sits within a small factor of the snapshot bound
# (printed above); the settled RMSE is larger because it also counts the epochs the tracker
# coasts through, those whose fit failed its residual test. Coasting for 0.1 s on speed and
# heading messages of 0.2 m/s and 1° costs centimetres.
#
# One correction to the paper sits in this chain. Algorithm 1 drops every path with $d < 0$, but
# $d$ carries the clock bias, up to ±100 ns (±30 m) in section 4.2: closer than 30 m a negative
# bias pushes good paths below zero, and on this drive 6 % of the epochs would lose every path.
# The design's route drops only $d < -c\,b_{max}$ (`extraction.algorithm1(est, min_d=...)`); the
# cell below shows the printed rule losing a whole epoch that the corrected one keeps.

# %%
route10 = paper.signal_route("10x10")
for aware in (False, True):
    ep26 = replace(route10, bias_aware_delay_check=aware).epoch(
        26, np.random.default_rng(3), clock_bias=-60e-9
    )
    print(
        f"bias-aware check {aware!s:5}: {len(ep26.paths)} true paths 9 m from the array, "
        f"bias -60 ns, delay distances {np.round(ep26.estimates.d, 2)} m -> "
        f"{len(ep26.measurements)} kept"
    )
# The bound is that small because, with the noise model of section 4.2 and 410 tones x 12
# symbols x 100 antennas integrated, the SNR per path is near 90 dB. The remaining factor is the
# tracker's: its motion model (speed and heading messages with 0.2 m/s and 1° of noise) and the
# VUEs it must carry. The whole-drive RMSE is set by the start-up, as in the paper's tables.
#
# Why per path? Along one drive the paths' bounds differ by two orders of magnitude (an RRM
# path near the array against the LoS and road paths 45 m away, a few degrees apart). One fixed
# sigma per quantity is then either loose, and throws the good paths' information away (the
# paper's 2° and 1.5 m), or, set to the median bound, too tight for the worst paths: the gate
# rejects the LoS, the VUE tracks die and are reborn, and the drive diverges.

# %% [markdown]
# ## 8. Explorer
#
# Carrier, bandwidth, array size $n \times n$, down-tilt and mount height. Every move recomputes
# the PEB along the route, the SR-NF overlay and the smallest square array meeting 15 cm on 90 %
# of the route (bounds only, vectorised; `make bench` times one redraw). The button runs a JAVELIN
# Monte-Carlo on the current design with a progress bar.

# %%
# headline: explorer
explorer = design_explorer(target=0.15, runs=tk.mc_count(6, 2))
explorer

# %% [markdown]
# ## Exercises
#
# 1. Lower the mount from 5.8 m to 5.0 m in the explorer (or with `setup.variant(mount_height=5.0)`).
#    What happens to the largest array with SR-NF valid on 90 % of the route, and why?
# 2. Same tunnel at 5.9 GHz and 100 MHz: which square array does the sweep recommend for a 15 cm
#    target?
# 3. How much does curvature add to the PEB of a 16 × 16 array in the 28 GHz tunnel (median ratio
#    of the PEB without curvature to the PEB with it)? And for 4 × 4?
#
# The solutions are in the collapsed cells below (click to expand, then run).

# %% jupyter={"source_hidden": true}
# Solution 1: a mount 1 m below the ceiling moves the ceiling's reflection point away from the array
low = setup.variant(mount_height=5.0)
for s in ("4x4", "8x8", "12x12"):
    print(s, "SR-NF valid share:", design.route_bounds(low, s, peb=False).srnf_valid.mean())
rec_low, _ = design.smallest_meeting(low, ["2x2", "3x3", "4x4", "6x6", "8x8"], target=0.15)
print("recommended at 5.0 m:", rec_low.label if rec_low else None)

# %% jupyter={"source_hidden": true}
# Solution 2
low_band = setup.variant(fc=5.9e9, bandwidth=100e6)
sol2 = design.design_sweep(low_band, ["2x2", "3x3", "4x4", "6x6", "8x8"], target=0.15)
print(sol2.recommendation)

# %% jupyter={"source_hidden": true}
# Solution 3
for s in ("4x4", "16x16"):
    with_c = design.route_bounds(setup, s).peb
    without = design.route_bounds(setup, s, curvature=False).peb
    print(s, "median PEB ratio without/with curvature:", np.median(without / with_c).round(2))

# %% [markdown]
# ## Checks

# %%
rows = {r.array: r for r in answer.rows}
assert answer.recommendation["array"] == "2x2"  # 15 cm on 90 % of the settled route, SR-NF gate
assert rows["3x3"].met_share >= 0.9 > rows["4x4"].met_share
assert rows["8x8"].srnf_valid_share == 0.0 and b8.surface_validity()["ceiling"] == 0.0
assert all(r.peb_median_m < 0.15 for r in answer.rows)  # the bound is not what binds
assert np.all(variants["no curvature"].peb >= b8.peb * (1 - 1e-9))  # curvature only helps
peb_paper = [r.peb_median_m for r in sweep.rows]
assert np.all(np.diff(peb_paper) < 0)  # PEB falls with size
assert sweep.rows[0].srnf_valid_share >= sweep.rows[-1].srnf_valid_share
assert 0 <= mc["ci95_m"][0] <= mc["rmse_m"] <= mc["ci95_m"][1]
assert mc["median_settled_m"] < 10 * mc["peb_rms_settled_m"]  # typical epoch near the PEB (s. 7)
assert mc["rmse_settled_m"] < 0.05  # centimetres at most once settled, on the paper's 10 x 10
assert explorer.figure.layout.title.text.startswith("Recommended: ")
assert design_figure(n=4, target=0.15).layout.meta["recommended"] == "3x3"
print("all checks passed")
