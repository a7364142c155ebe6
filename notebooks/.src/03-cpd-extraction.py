# %% [markdown]
# # 03 · From the tunnel to the channel tensor and back: CPD channel-parameter extraction
#
# *Italiano, Brambilla & Nicoli (2026), "In-Tunnel Single-Anchor Localization Exploiting Near-Field
# and Radio-Reflective Road Markings", [arXiv:2604.04217](https://arxiv.org/abs/2604.04217v1),
# sections 2 (eq. 1–24), 3.2 (Algorithm 1) and 4.1–4.2.
# All references: `REFERENCES.md` at the top of the repository.*
#
# **What you will learn**
#
# - how the image method turns a tunnel (semicircular facets, road, metallic road markings)
#   into a handful of paths, each with a virtual UE (VUE), a reflection point, a delay, an
#   angle, a Doppler shift and an exact length to *every* antenna;
# - how those paths build the uplink SRS channel tensor $\mathcal{H}$ (eq. 1, 3) and why its
#   canonical polyadic decomposition (CPD) hands the paths back one rank-1 term each;
# - the paper's extraction chain: scaling fix and Vandermonde roots (eq. 12–15), 2-D phase
#   unwrapping (eq. 16), TLS near-field / LS far-field solutions (eq. 17–24), Algorithm 1;
# - where it is fragile: paths that share delay *and* Doppler (the ceiling bounce right above
#   the base station), eq. 13's inefficiency, and what the curvature $\kappa$ really measures;
# - how far the estimates are from the Cramér–Rao bound.

# %%
import numpy as np
from tqdm.auto import tqdm

import tunnelkit as tk
from tunnelkit import channel, evaluation, extraction, signal_route
from tunnelkit.constants import C
from tunnelkit.plots import factors_figure, paths_table_figure, tunnel3d_figure, wave_origins_figure
from tunnelkit.widgets import cpd_explorer, curvature_study

tk.setup_notebook()

# %% [markdown]
# ## 1. The JAVELIN tunnel and its paths
#
# Section 4.1: a straight tunnel, 100 m long, with a semicircular cross-section 10 m wide and
# 5 m high; one base station (BS) at the centre, 4.8 m high, with two $10\times10$ URAs looking
# along the tunnel and tilted 30° down; four metallic radio-reflective road markings (RRMs), two
# at the sidewalk–wall junction (55°) and two on the walls at 3.3 m (90°). The preset
# `italiano2026-straight` holds all of it (`tunnelkit.propagation` registers its tunnel and
# trajectory kinds). The semicircle is built from 12 planar facets plus the road.
#
# **Image method.** A surface with unit normal $n$ and offset $c$ mirrors the UE into the VUE
# $p_v = p_u - 2(n\cdot p_u + c)\,n$. The reflected path exists when the straight line from the
# array's reference antenna to the VUE crosses the surface *inside* the finite facet (the
# specular point) and no box (a truck) blocks either leg. Its exact length to antenna $m$ is
# $d_{\ell,m} = \lVert p_v - p_m\rVert$ (eq. 2, 38): a spherical wavefront centred on the VUE.

# %%
route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
k_demo = 12
array, paths = route.paths(k_demo)
ue = route.trajectory.position[k_demo]
print(f"epoch {k_demo}: UE at {ue.round(2)}, array '{array.name}', {len(paths)} paths")
tunnel3d_figure(
    route.tunnel,
    [array],
    paths,
    ue,
    x_range=(-5, 40),
    title=f"Paths at epoch {k_demo} (LoS green, ceiling red, road grey, RRM purple)",
)

# %%
paths_table_figure(evaluation.path_rows(paths), title="True paths (world-frame angles, eq. 46-50)")

# %% [markdown]
# Two things to notice. The ceiling bounce is only a few centimetres longer than the LoS and has
# the same Doppler: the BS hangs 0.2 m under the crown, so the ceiling's VUE sits almost on the
# LoS ray, mirrored upwards. And the curvature the SR-NF model assigns to a reflected path (the
# distance to the reflection point, eq. 51) is much shorter than the distance to the VUE.

# %% [markdown]
# ## 2. The channel tensor (eq. 1, 3)
#
# $$h_{m,s}[k]=\sum_{\ell=0}^{L-1}\alpha_{\ell}\,e^{j2\pi\frac{f_c}{c}\delta_{\ell,m}}
#   \,e^{-j2\pi s\Delta f\tau_{\ell}}\,e^{j2\pi k f^{d}_{\ell}T_{0}} \qquad (1)$$
#
# with section 4.2's SRS: $f_c = 5.9$ GHz, 100 MHz (273 resource blocks of 12 subcarriers at
# 30 kHz), comb 8, hence $N_f = 410$ tones spaced $\Delta f = 240$ kHz; $N_t = 12$ symbols of
# $T_0 = 35.7\,\mu$s; 23 dBm; noise $\mathcal{CN}(0, N_0)$ per element with
# $N_0 = k_B\,BW\,T_e$, $T_e = T_\text{ant} + 290(N_F - 1)$, $T_\text{ant} = 298$ K,
# $N_F = 5$ dB. The delay $\tau_\ell = d_\ell/c + b$ carries the UE clock bias $b$, a Gaussian of
# 50 ns standard deviation truncated to ±100 ns. (The paper writes $d = \tau/c$; it means
# $d = c\,\tau$.) Eq. 3 is a CPD: $\mathcal{H}=\sum_\ell \alpha_\ell\, b^s_\ell\circ b^f_\ell
# \circ b^t_\ell$.

# %%
cfg = route.config
snap = channel.synthesize(paths, cfg, np.random.default_rng(1))
print("H shape (M, Nf, Nt):", snap.H.shape)
print(
    f"N0 = {cfg.noise_power:.3e} W, T_e = {cfg.noise_temperature:.0f} K, "
    f"clock bias = {snap.clock_bias * 1e9:.1f} ns = {snap.clock_bias * 3e8:.2f} m"
)
print("per-element SNR of each path [dB]:", snap.snr_db.round(1))
doppler_res = 1 / (cfg.n_symbols * cfg.symbol_period)  # 1/(N_t T_0) [Hz]
print(
    f"Doppler resolution 1/(N_t T_0) = {doppler_res / 1e3:.2f} kHz "
    f"= {doppler_res * C / cfg.fc:.0f} m/s in radial speed"
)

# %% [markdown]
# ## 3. CPD and the three factor matrices (eq. 11–16)
#
# `extraction.extract_paths` runs the chain. The CPD (tensorly `parafac`) returns
# $\hat B^s, \hat B^f, \hat B^t$ up to scale; dividing each column by its first entry fixes the
# scale, and the gain is the product of the first rows (eq. 12). The frequency and time factors
# are Vandermonde, so their roots follow from shift invariance (eq. 13):
# $\hat\mu = \angle\,\mathrm{diag}(\hat B_-^H \hat B_+)$, giving
# $\hat d = -\frac{c}{2\pi\Delta f}\hat\mu^f$ (eq. 14) and $\hat v = \frac{c}{2\pi f_c T_0}\hat\mu^t$
# (eq. 15). The spatial factor's phase, unwrapped in 2-D over the URA grid (eq. 16, scikit-image's
# Herráez et al. algorithm, the paper's ref. 25), gives the path-length offsets $\hat\delta_m$.

# %%
est = extraction.extract_paths(
    snap.H, len(paths), array.local, cfg.fc, cfg.tone_spacing, cfg.symbol_period
)
print(f"CPD relative error {est.rel_error:.4f} (the noise floor), core iterations {est.n_iter}")
factors_figure(est.factors, unwrapped=est.delta.T * 2 * np.pi * cfg.fc / C)

# %% [markdown]
# **How the CPD is computed here.** A plain `parafac(H, L, init="svd")` on the full
# $100\times410\times12$ tensor is about ten times slower (see `benchmarks/bench_extraction.py`)
# and, even on a noiseless tensor, stops in a wrong decomposition: the time factor hardly varies
# between paths over 12 symbols (Doppler resolution $1/(N_tT_0) \approx 2.3$ kHz, i.e. 119 m/s,
# printed in section 2),
# and the frequency factor barely separates paths closer than $c/BW = 3$ m. So
# `extract_paths` (1) compresses $\mathcal{H}$ to an $L\times L\times L$ core (truncated HOSVD),
# (2) initialises the core's CPD algebraically from a *shift invariance* — of the URA rows
# (angles differ by degrees) and of the Vandermonde frequency factor — (3) refines with
# tensorly's `parafac(init=..., linesearch=True)` on the core, (4) lifts back and polishes with
# two ALS sweeps on the full tensor. Below, the plain call on a smaller tensor for comparison.

# %%
small = channel.channel_tensor(paths, cfg, n_tones=64, clock_bias=snap.clock_bias)
plain = extraction.extract_paths(
    small,
    len(paths),
    array.local,
    cfg.fc,
    cfg.tone_spacing,
    cfg.symbol_period,
    method="plain",
    n_iter_max=60,
)  # may warn
fast = extraction.extract_paths(
    small, len(paths), array.local, cfg.fc, cfg.tone_spacing, cfg.symbol_period
)
d_true = np.sort([p.length for p in paths]) + C * snap.clock_bias
print("true d      ", d_true.round(3))
print("plain parafac", plain.d.round(3), "| converged:", plain.converged)
print("fast          ", fast.d.round(3))

# %% [markdown]
# ## 4. Directions and curvature (eq. 17–24)
#
# With the reference antenna at the origin of the array's local frame and the array in its
# $xy$-plane, $\hat\delta_{\ell,m}+\kappa_\ell = \lVert p_m - p_\ell\rVert$ (eq. 17) becomes the
# linear system $2[x_m\; y_m\; \hat\delta_{\ell,m}]\,x_\ell = r_m^2-\hat\delta_{\ell,m}^2$
# (eq. 18), solved by total least squares; in the far field $[x_m\; y_m]\,u = -\hat\delta_m$
# by LS. **Convention**: eq. 19 writes
# $x_\ell = \kappa(\cos\phi\sin\psi,\ \sin\phi\sin\psi)$, so $\psi$ is the polar angle from the
# array normal, while eq. 22/24's $\cos^{-1}(\rho/\kappa)$ returns its complement (the angle
# above the array plane). We follow eq. 19 and also return the unit direction, checked against
# exact geometry in `tests/test_extraction.py`. Algorithm 1 then drops $\hat d<0$ and falls back
# on the far-field angles when $\hat\kappa<0$.

# %%
rows = evaluation.comparison_rows(est, paths, array, snap.clock_bias)
paths_table_figure(rows, title="Extracted vs true (kappa: NaN = far-field fallback of Algorithm 1)")

# %% [markdown]
# The ceiling path and the LoS share delay and Doppler within a fraction of the resolution, so
# only the spatial factor tells them apart, and a CPD with a free spatial factor struggles:
# Kruskal's condition $\mathrm{kr}(B^s)+\mathrm{kr}(B^f)+\mathrm{kr}(B^t)\ge 2L+2$ holds in exact
# arithmetic but, numerically, the time factor has Kruskal rank 1.

# %%
Bt = np.exp(2j * np.pi * cfg.symbol_period * np.outer(np.arange(12), [p.doppler for p in paths]))
Bf = np.exp(
    -2j * np.pi * cfg.tone_spacing * np.outer(np.arange(cfg.n_tones), [p.length / C for p in paths])
)
kr = {
    tol: (extraction.kruskal_rank(Bf, tol), extraction.kruskal_rank(Bt, tol))
    for tol in (1e-6, 1e-2)
}
print("Kruskal rank (frequency, time) at tolerance 1e-6 and 1e-2:", kr)

# %% [markdown]
# ## 5. Eq. 13 is unbiased but not efficient
#
# Eq. 13 sums $\bar b_n b_{n+1}$: its phase error telescopes to the two end samples, so its
# variance falls as $1/N^2$ instead of the $1/N^3$ of the maximum-likelihood (periodogram) root.
# `extract_paths(refine=...)` offers the paper's `"none"`, a per-column periodogram `"column"`
# and the default `"joint"`: all roots refined together with free spatial factors (variable
# projection), the ML estimate of exactly the model a CPD fits plus the Vandermonde structure.
# We compare them on LoS + road (no ceiling, so the comparison is not dominated by it).

# %%
two = signal_route.SignalRoute(
    route.tunnel, route.arrays, route.trajectory, cfg, kinds=("los", "road")
)
n_cmp = tk.mc_count(40, 8)
cmp = {
    m: evaluation.rmse_study(two, k_demo, n_cmp, seed=7, refine=m, progress=True)[0]
    for m in ("none", "column", "joint")
}
paths_table_figure(
    [
        {
            "refine": m,
            "RMSE d [mm]": 1e3 * r["RMSE d [m]"],
            "CRLB d [mm]": 1e3 * r["CRLB d [m]"],
            "RMSE v [m/s]": r["RMSE v [m/s]"],
            "CRLB v [m/s]": r["CRLB v [m/s]"],
        }
        for m, r in cmp.items()
    ],
    title=f"LoS errors over {n_cmp} snapshots",
)

# %% [markdown]
# ## 6. RMSE against the Cramér–Rao bound
#
# `extraction.crlb_paths` assembles the Fisher information of eq. 1 for all paths jointly from
# the rank-1 structure (inner products factorise over the three modes; checked against a
# finite-difference FIM in the tests). For $d$ and $v$ the bound uses a *free* spatial factor
# (what the CPD fits); for direction and $\kappa$ it uses the exact spherical model. Seeded
# snapshots at the paper's SNR, $L$ known, clock bias drawn per snapshot (and part of the truth
# for $d$), LoS and reflected paths separately. Full mode: 200 snapshots.

# %%
n_mc = tk.mc_count(200, 12)
study_all = evaluation.rmse_study(route, k_demo, n_mc, seed=11, progress=True)
study_noceil = evaluation.rmse_study(two, k_demo, n_mc, seed=11, progress=True)
paths_table_figure(study_all, title=f"All paths at epoch {k_demo}, {n_mc} snapshots")

# %%
paths_table_figure(study_noceil, title=f"LoS + road only, {n_mc} snapshots")

# %% [markdown]
# Read the two tables side by side. With two well-separated paths (LoS + road) the joint
# estimate sits on the bound for $d$ and $v$; direction and $\kappa$, which come from the TLS of
# eq. 18 (all antennas weighted equally, noise in both $A$ and $y$), stay several times above
# theirs. With the whole cluster at 30 m — LoS, ceiling, road and a road marking within a metre
# of each other and with the same Doppler — the errors are set by how well the free spatial
# factor can keep the paths apart, not by the noise: decimetres in $d$, degrees in direction,
# and a curvature that is rarely usable (the far-field share counts Algorithm 1's fallbacks).

# %% [markdown]
# ## 7. Estimated wave origins along the trajectory (cf. Fig. 5)
#
# For every epoch we place each near-field estimate at $p = \text{origin} + \hat\kappa\,\hat u$
# and colour it by altitude. With the SR-NF channel the origins are the reflection points (road
# markings low, the ceiling high); with the exact physics they are the VUEs, mirrored *outside*
# the tunnel.

# %%
step = 4 if tk.quick_mode() else 1
origins = {}
for model in ("srnf", "exact"):
    r_m = signal_route.SignalRoute(route.tunnel, route.arrays, route.trajectory, cfg, model=model)
    ks = range(0, len(route.trajectory), step)
    eps = [r_m.epoch(k, np.random.default_rng(100 + k)) for k in tqdm(ks, desc=model, leave=False)]
    origins[f"{model} channel"] = np.concatenate([e.measurements.wave_origins for e in eps])
wave_origins_figure(origins, route.trajectory.position, route.arrays[0].origin)

# %% [markdown] tags=["explorer"]
# ## 8. What does the curvature measure? (M and SNR sliders)
#
# Theorem 3.1/3.4 (notebook 02): up to $M_{\max}$ antennas the exact channel of a reflected path
# is indistinguishable, within a phase error $\varepsilon_\Phi$, from the SR-NF model whose
# wavefront is centred on the reflection point. Past $M_{\max}$ only the VUE explains it. The
# explorer resizes the URA ($n\times n$), synthesises the *exact* channel and shows the TLS
# $\hat\kappa$ of the strongest road-marking path between the two candidates; on the right, the
# largest SR-NF phase mismatch over the aperture against $\varepsilon_\Phi = 0.15$ rad.

# %% tags=["explorer"]
explorer = cpd_explorer()
explorer

# %%
big = curvature_study(16, 30.0, k_demo)
small_arr = curvature_study(3, 30.0, k_demo)
print(
    f"M = 256: kappa = {np.round(big['kappa'], 2)} (VUE {big['kappa_vue']:.2f} m, reflection "
    f"point {big['kappa_reflection']:.2f} m), mismatch {big['mismatch']:.3f} rad"
)
print(
    f"M = 9:   kappa = {np.round(small_arr['kappa'], 2)}, mismatch {small_arr['mismatch']:.4f} rad"
)

# %% [markdown]
# With a small array the curvature is not measurable at all (the TLS falls back on the far
# field, $\hat\kappa<0$): the SR-NF and the exact model are the same channel there. With a
# large array and enough SNR the estimate sits on the VUE distance, never on eq. 51's
# reflection-point distance — the tracker of notebook 04 has to know which one it is fed.

# %% [markdown]
# ## Exercises
#
# 1. Put a truck between the vehicle and the BS
#    (`route.tunnel.with_blockers(propagation.truck_box(20, -2.5))`) and rerun section 1–3 at
#    epoch 12: which paths survive, and which one does Algorithm 1 now call "path 0"?
# 2. Remove the ceiling from the path families (`kinds=("los", "wall", "road", "rrm")`) and
#    compare the LoS RMSE of section 6 with and without it. Why does one path that is 3 cm
#    longer than the LoS spoil the LoS estimate?
# 3. Lower the SNR with `signal_route.SignalRoute(..., snr_offset_db=-20)`: at what offset does the
#    CPD stop finding the RRM paths (count `missed`)?
#
# <details><summary>Hints and solutions</summary>
#
# 1. `tun = route.tunnel.with_blockers(propagation.truck_box(20, -2.5))`,
#    `arr, ps = route.paths(12, tunnel=tun)`: the LoS and the road bounce are gone, the RRM and
#    ceiling paths remain; the earliest arrival (path 0, the reference of $\Delta d$) is then a
#    reflection, which is why JAVELIN tracks VUEs rather than assuming a LoS.
# 2. At epoch 12 (200 snapshots) the LoS $d$ RMSE is about 0.47 m with the ceiling, 0.12 m
#    without it, and 0.2 mm with LoS + road only: the ceiling path has the same delay and
#    Doppler as the LoS within the noise, so the CPD must split their sum with the spatial factor
#    alone, and a free spatial factor can rotate between them (Kruskal rank 1 in time, section 4).
#    The free-model CRLB grows accordingly (compare `extraction.path_crlb` with and without it).
# 3. Loop `snr_offset_db` over `range(0, -40, -5)` and call `evaluation.rmse_study(r, 12, 10, 0)`
#    with `r = signal_route.SignalRoute(..., snr_offset_db=off)`; watch `missed` grow, weakest path
#    first (compare `snap.snr_db`).
#
# </details>

# %% [markdown]
# ## Checks

# %%
los = paths[0]
assert los.kind == "los" and abs(los.length - np.linalg.norm(ue - array.origin)) < 1e-12
assert {p.surface_kind for p in paths} >= {"los", "ceiling", "road", "rrm"}
assert cfg.n_tones == 410 and snap.H.shape == (100, 410, 12)
assert abs(snap.clock_bias) <= 100e-9
assert est.rel_error < 0.05 and np.all(np.isfinite(est.d))
assert np.max(np.abs(fast.d - d_true)) < 0.05  # noiseless small tensor: fast CPD exact-ish
assert kr[1e-2][1] == 1  # the time factor is numerically rank one
assert cmp["joint"]["RMSE d [m]"] < cmp["none"]["RMSE d [m]"]  # eq. 13 is not efficient
assert study_noceil[0]["RMSE d [m]"] < 2 * study_noceil[0]["CRLB d [m]"]  # LoS within 2x CRLB
assert study_noceil[0]["RMSE v [m/s]"] < 2 * study_noceil[0]["CRLB v [m/s]"]
assert study_noceil[0]["RMSE dir [deg]"] < 2.0
z_srnf = origins["srnf channel"][:, 2]
assert np.nanmax(z_srnf) > 4.0 and np.nanmin(z_srnf) < 1.0  # ceiling high, road/RRMs low
assert explorer.figure.layout.title.text.startswith(f"epoch {k_demo}")
assert abs(np.median(big["kappa"]) - big["kappa_vue"]) < 0.1 * big["kappa_vue"]  # VUE, not eq. 51
assert big["mismatch"] > 0.15 > small_arr["mismatch"]
print("all checks passed")
