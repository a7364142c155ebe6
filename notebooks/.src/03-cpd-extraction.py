# %% [markdown]
# # 03 · From the tunnel to the channel tensor and back: CPD channel-parameter extraction
#
# *Italiano, Brambilla & Nicoli (2026), "In-Tunnel Single-Anchor Localization Exploiting Near-Field
# and Radio-Reflective Road Markings", [arXiv:2604.04217](https://arxiv.org/abs/2604.04217v1),
# sections 2 (eq. 1–24), 3.2 (Algorithm 1) and 4.1–4.2. References: `REFERENCES.md`; terms and
# the words for bounds: the [glossary](GLOSSARY.md) and its [Bounds](GLOSSARY.md#bounds) section.
# How the extraction is computed and reports its own failures is told in
# [docs/extraction-notes.md](../docs/extraction-notes.md).*
#
# **What you will learn**
#
# - how the image method turns a tunnel into paths, each from a virtual UE (VUE), and how they
#   build the uplink [SRS](GLOSSARY.md#srs) channel tensor (eq. 1, 3), whose canonical polyadic
#   decomposition (CPD) hands them back one rank-1 term each (eq. 12–24, Algorithm 1);
# - how far that is from the Cramér–Rao bound (CRLB), and how a maximum-likelihood (ML) fit of
#   eq. 1 comes close to it: on a calibrated array (section 10), above a threshold (section 11).

# %%
import warnings
from dataclasses import replace

import numpy as np
from scipy.stats import chi2
from tqdm.auto import tqdm

import tunnelkit as tk
from tunnelkit import channel, efficiency, evaluation, extraction, plots, signal_route
from tunnelkit.constants import C
from tunnelkit.extraction import ml
from tunnelkit.widgets import cpd_explorer, curvature_study
from tunnelkit.widgets.cpd import mismatch

tk.setup_notebook()

# %% [markdown]
# ## 1. The JAVELIN tunnel and its paths
#
# Section 4.1: a straight tunnel, 100 m long, semicircular, 10 m wide and 5 m high; a base
# station (BS) 4.8 m high with two $10\times10$ URAs along the tunnel; four metallic road
# markings (RRMs): the preset `italiano2026-straight`. **Image method**: a surface with unit normal
# $n$ and offset $c$ mirrors the UE into the VUE $p_v = p_u - 2(n\cdot p_u + c)\,n$; the path
# exists when the line from the array to the VUE crosses the finite facet, unblocked. Its length
# to antenna $m$ is $d_{\ell,m} = \lVert p_v - p_m\rVert$ (eq. 2, 38): a spherical wavefront.
#
# The ceiling bounce is only centimetres longer than the LoS, with the same Doppler: the array
# hangs just under the crown, so the ceiling's VUE sits almost on the LoS ray. And the SR-NF
# model's curvature of a reflected path (the distance to the reflection point, eq. 51, "kappa
# SR-NF") is much shorter than the distance to the VUE ("length").

# %%
route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
k_demo = 12
array, paths = route.paths(k_demo)
ue = route.trajectory.position[k_demo]
plots.tunnel3d_figure(route.tunnel, [array], paths, ue, x_range=(-5, 40), title=f"epoch {k_demo}")

# %%
ceil = next(p for p in paths if p.surface_kind == "ceiling")
ceil_gap = float(ceil.point[2] - array.origin[2])
print(f"ceiling: reflection point {ceil_gap:.2f} m above the array,", end=" ")
print(f"{100 * (ceil.length - paths[0].length):.1f} cm longer than the LoS")
plots.paths_table_figure(evaluation.path_rows(paths), title="True paths (world frame, eq. 46-50)")

# %% [markdown]
# ## 2. The channel tensor (eq. 1, 3)
#
# $$h_{m,s}[k]=\sum_{\ell=0}^{L-1}\alpha_{\ell}\,e^{j2\pi\frac{f_c}{c}\delta_{\ell,m}}
#   \,e^{-j2\pi s\Delta f\tau_{\ell}}\,e^{j2\pi k f^{d}_{\ell}T_{0}} \qquad (1)$$
#
# Section 4.2's SRS: $f_c = 5.9$ GHz, 100 MHz, comb 8; at our assumed 30 kHz spacing (273 RB;
# the paper gives neither) $N_f = 410$ tones spaced $\Delta f = 240$ kHz; $N_t = 12$ symbols of
# $T_0 = 35.7\,\mu$s; noise $\mathcal{CN}(0, N_0)$ per element. The delay $\tau_\ell = d_\ell/c
# + b$ carries the UE clock bias $b$ (the paper writes $d = \tau/c$ for $d = c\,\tau$). Eq. 3 is
# a CPD: $\mathcal{H}=\sum_\ell \alpha_\ell\, b^s_\ell\circ b^f_\ell \circ b^t_\ell$.
#
# **The clock bias, read.** The paper draws $b$ from a Gaussian "with variance 50 ns" truncated to
# $[-100, 100]$ ns. We read a 50 ns **standard deviation**: a variance would be in ns², and 50 ns
# puts the truncation at two standard deviations, where it acts; as 50 ns², the deviation would be
# about 7 ns and the support fourteen of them each side, a truncation that never acts (printed).

# %%
cfg = route.config
snap = channel.synthesize(paths, cfg, np.random.default_rng(1))
sd_ns2 = np.sqrt(50.0) * 1e-9  # the literal reading: a variance of 50 ns^2
print(f"support ±{cfg.clock_bias_limit / cfg.clock_bias_sigma:.0f} sd of 50 ns", end="; ")
print(f"as 50 ns²: sd {1e9 * sd_ns2:.1f} ns, support ±{cfg.clock_bias_limit / sd_ns2:.0f} sd")
doppler_res = 1 / (cfg.n_symbols * cfg.symbol_period)  # 1/(N_t T_0) [Hz]
print(f"Doppler resolution {doppler_res / 1e3:.2f} kHz = {doppler_res * C / cfg.fc:.0f} m/s")
snr_eff = snap.snr_db + 10 * np.log10(snap.H.size)  # integrated over N_f N_t M
print(f"SNR per element {snap.snr_db.round(1)} dB, integrated {snr_eff.round(0)} dB")

# %% [markdown]
# ## 3. CPD and the three factor matrices (eq. 11–16)
#
# `extraction.extract_paths(..., refine="joint")` runs the paper's chain. The CPD (fitted to a
# [HOSVD](GLOSSARY.md#hosvd)-compressed core: extraction notes, part 1) returns the factors up to
# scale; dividing each column by its first entry fixes it (eq. 12). The frequency and time
# factors are Vandermonde: by shift invariance $\hat\mu = \angle\,\mathrm{diag}(\hat B_-^H \hat
# B_+)$ (eq. 13), so $\hat d = -\frac{c}{2\pi\Delta f}\hat\mu^f$ (eq. 14), $\hat v = \frac{c}{2\pi
# f_c T_0}\hat\mu^t$ (eq. 15). The spatial factor's phase, unwrapped in 2-D (eq. 16, [Herráez
# 2002]), gives the path-length offsets $\hat\delta_m$.

# %%
est = extraction.extract_paths(snap.H, len(paths), array, cfg, refine="joint")
print(f"CPD relative error {est.rel_error:.4f} (the noise floor)")
plots.factors_figure(est.factors, unwrapped=est.delta.T * 2 * np.pi * cfg.fc / C)

# %% [markdown]
# ## 4. Directions and curvature (eq. 17–24)
#
# In the array's frame, $\hat\delta_{\ell,m}+\kappa_\ell = \lVert p_m - p_\ell\rVert$ (eq. 17)
# becomes $2[x_m\; y_m\; \hat\delta_{\ell,m}]\,x_\ell = r_m^2-\hat\delta_{\ell,m}^2$ (eq. 18),
# solved by total least squares (TLS); far field: $[x_m\; y_m]\,u = -\hat\delta_m$ by LS. (Eq.
# 19's $\psi$ is the polar angle from the array normal; eq. 22/24 return its complement.)
# Algorithm 1 drops $\hat d<0$ and falls back on the far field when $\hat\kappa<0$. The LoS and the
# ceiling share delay and Doppler: [Kruskal's](GLOSSARY.md#kruskal-rank) condition
# $\mathrm{kr}(B^s)+\mathrm{kr}(B^f)+\mathrm{kr}(B^t)\ge 2L+2$ holds exactly, but numerically
# the time factor has Kruskal rank 1 (printed), and only the spatial factor tells them apart.

# %%
rows = evaluation.comparison_rows(est, paths, array, snap.clock_bias)
Bt = np.exp(2j * np.pi * cfg.symbol_period * np.outer(np.arange(12), [p.doppler for p in paths]))
kr_t = {tol: extraction.kruskal_rank(Bt, tol) for tol in (1e-6, 1e-2)}
print("Kruskal rank of the time factor at tolerance 1e-6 and 1e-2:", kr_t)
plots.paths_table_figure(rows, title="Extracted vs true (kappa NaN: far-field fallback)")

# %% [markdown]
# ## 5. Eq. 13 is unbiased but not efficient
#
# Eq. 13 sums $\bar b_n b_{n+1}$: its phase error telescopes to the two end samples, so its
# variance falls as $1/N^2$, not the $1/N^3$ of the ML (periodogram) root. `refine=`: the paper's
# `"none"`, a per-column periodogram `"column"`, `"joint"` (all roots with free spatial factors,
# [variable projection](GLOSSARY.md#variable-projection)), `"ml"` (section 7). LoS, on LoS + road:

# %%
two = replace(route, kinds=("los", "road"))  # the same route, two path families
n_cmp = tk.mc_count(40, 4)
refines = ("none", "column", "joint", "ml")
cmp = {m: evaluation.rmse_study(two, k_demo, n_cmp, seed=7, refine=m)[0] for m in refines}
plots.paths_table_figure([{"refine": m, **r} for m, r in cmp.items()])

# %% [markdown]
# ## 6. RMSE against the Cramér–Rao bound
#
# `extraction.path_crlb` assembles the Fisher information $J$ of eq. 1, all paths jointly (per
# path: gain, $d$, $v$, wave origin). The CRLB, $J^{-1}$, bounds the *variance* of an *unbiased*
# estimator. Each column names its model: $d$ and $v$ bounds of the model the paper's route fits
# (free spatial factor, section 7), direction and $\kappa$ of eq. 1. An RMSE counts the draws that
# found the path (`matched share`; $\kappa$'s, those with a near-field estimate), while a bound
# holds for every draw. Full mode: 200 snapshots.

# %%
n_mc = tk.mc_count(200, 6)
study_all = evaluation.rmse_study(route, k_demo, n_mc, seed=11, refine="joint", progress=True)
study_noceil = evaluation.rmse_study(two, k_demo, n_mc, seed=11, refine="joint")
b_eq1 = extraction.path_crlb(paths, array, cfg)
b_free = extraction.path_crlb(paths, array, cfg, spatial="free")
pair = [r for r in study_all if r["path"] in ("los", "ceiling")]  # the merged pair
print("LoS, ceiling: d RMSE [m]", [round(r["RMSE d [m]"], 2) for r in pair], end=" ")
print("under their free-factor CRLB [m]", [round(r["CRLB d [m]"], 2) for r in pair])
d_mm = {"free factor": (1e3 * b_free["d"]).round(1), "eq. 1": (1e3 * b_eq1["d"]).round(3)}
print("CRLB d [mm]:", d_mm, "\neq. 1, kappa [m]:", b_eq1["kappa"].round(3), end="; ")
print(f"LoS direction {study_all[0]['CRLB dir [deg]']:.4f} deg")
# one quantity per column: an RMSE over the matched draws, a bound named for its model
over = dict(d=("matched", "free factor"), v=("matched", "free factor"), dir=("matched", "eq. 1"))
over["kappa"] = ("matched, near field", "eq. 1")
units = dict(zip(over, ("m", "m/s", "deg", "m")))
named = {f"{s} {q} [{units[q]}]": f"{s} {q}, {w[i]} [{units[q]}]" for q, w in over.items()
         for i, s in enumerate(("RMSE", "CRLB"))}  # fmt: skip
both = [{"paths": n_, "path": r["path"], "matched share": r["matched"] / n_mc}
        | {named[k]: r[k] for k in named} | {"far field, of matched": r["far-field share"]}
        for n_, st in (("all", study_all), ("2", study_noceil)) for r in st]  # fmt: skip
plots.paths_table_figure(both, title=f"Paper's route, all paths and LoS + road (2), {n_mc} draws")

# %% [markdown]
# **LoS + road**: $d$ and $v$ close to their bound, direction and $\kappa$ above theirs. **All
# paths** (lengths within 1.5 m): direction and $\kappa$ orders of magnitude above the bound of
# eq. 1; in $d$, though, the LoS and the ceiling bounce sit *below* their free-factor bound, which
# is huge (metres, printed above).
#
# No bound is broken. With a free spatial factor those two paths are almost unidentifiable, so an
# *unbiased* estimate of each delay would scatter by metres. The paper's route returns instead one
# merged component (section 7), whose mean follows neither delay one for one, and misses one of
# the pair in a share of the draws (`matched share` below 1). A biased estimator obeys the
# *biased* CRB, $\mathrm{var} \ge (1+\partial b/\partial\theta)^2/J$ for a bias $b(\theta)$
# ($g^\mathsf{T}J^{-1}g$ for several parameters, $g$ the gradient of the estimate's mean), small
# when the mean hardly moves with $\theta$; and an RMSE holds the bias, $\text{RMSE}^2 = b^2 +
# \mathrm{var}$, so it is compared with $\sqrt{b^2 + (1+\partial b/\partial\theta)^2/J}$. An RMSE
# under the unbiased bound marks a biased estimator, not a bound beaten. The bound of eq. 1
# (printed: a fraction of a millimetre in $d$, about a thousandth of a degree, centimetres in
# $\kappa$, for a calibrated array) lies far below the same errors: the gap is the estimator's.
#
# ## 7. Why a CPD is not efficient, and what is
#
# A CPD fits, per path, a **free** spatial factor, $2(M-1)$ real unknowns where the physics has
# **three** (the wave origin). (1) *Noise enters every free entry*: the curvature's small quadratic
# phase, $k_0\lVert p_m\rVert^2/(2\kappa)$, is buried in $2(M-1)$ noisy directions and read back by
# a TLS weighting every antenna alike. (2) *Paths sharing delay and Doppler are one rank-one
# term*, $(\alpha_1 s_1 + \alpha_2 s_2)\circ b_f\circ b_t$: the LoS and the ceiling come out as one
# biased path. (The free-factor bound on $d$ is looser too: printed above.)
#
# A **structured** fit of eq. 1 to the whole tensor — maximum likelihood — comes within 1.5× the
# CRLB at this SNR, far above section 11's threshold (quick mode: 4×, over 2 snapshots).
# `extraction.ml`: variable projection and [Levenberg–Marquardt](GLOSSARY.md#levenberg-marquardt)
# from the CPD, re-seeding a path like [SAGE](GLOSSARY.md#sage) while the residual stands above the
# noise floor (*basin test*: $\rho = \lVert r\rVert^2/(\text{dof}\,\sigma^2) \approx 1$).

# %%
study_ml = evaluation.rmse_study(route, k_demo, tk.mc_count(40, 2), seed=11, refine="ml")
plots.paths_table_figure(study_ml, title=f"ML route, all paths at epoch {k_demo}")

# %% [markdown]
# **Along the drive**, the LoS: the paper's route, the coherent split (`refine="coherent"`, point
# sources fitted to a free factor) and ML (quick: two epochs, one snapshot; full: every third, 10).
# An RMSE over $n$ draws is random: for an efficient estimator $n\,\text{RMSE}^2/\text{CRLB}^2 \sim
# \chi^2_n$, so RMSE/CRLB lies in $[\sqrt{\chi^2_{n;0.05}/n}, \sqrt{\chi^2_{n;0.95}/n}]$ nine times
# in ten: from one snapshot, anything from a few hundredths to about two (printed).

# %%
drive_epochs = [4, 24] if tk.quick_mode() else list(range(0, len(route.trajectory), 3))
n_eff = tk.mc_count(10, 1)
eff = efficiency.drive_efficiency(route, drive_epochs, n_eff, seed=5)
chi_band = {n: [float(np.sqrt(chi2.ppf(q, n) / n)) for q in (0.05, 0.95)] for n in (1, n_eff)}
eff_ml = [r for r in eff if r["route"] == "ml" and r["path"] == "los"]
ratio_ml = [r["RMSE kappa [m]"] / r["CRLB kappa [m]"] for r in eff_ml]
crlb_k = [r["CRLB kappa [m]"] for r in eff_ml]
print("90 % band of RMSE/CRLB, by number of snapshots:", chi_band)
print("ML kappa, RMSE/CRLB:", np.round(ratio_ml, 2), "CRLB [m]:", np.round(crlb_k, 3))
plots.efficiency_figure(eff, "los", title=f"LoS along the drive, {n_eff} snapshot(s) per epoch")

# %% [markdown]
# The paper's route sits far above the bound, ML on it (mostly inside the band); $\kappa$'s bound
# grows from millimetres near the BS to decimetres at the far end. The paper's URA **does**
# measure the wavefront's curvature, if calibrated and if the estimator uses the model.
#
# ## 8. Estimated wave origins along the trajectory (cf. Fig. 5)
#
# The paper's near-field estimates at $\text{origin} + \hat\kappa\,\hat u$: with the SR-NF channel,
# the reflection points (markings low, ceiling high); with the exact physics, the VUEs, outside.

# %%
origins, ks = {}, range(0, len(route.trajectory), 7 if tk.quick_mode() else 1)
for model in ("srnf", "exact"):
    r_m = route.with_options(model=model)
    eps = [r_m.epoch(k, np.random.default_rng(100 + k), refine="joint") for k in tqdm(ks)]
    origins[f"{model} channel"] = np.concatenate([e.measurements.wave_origins for e in eps])
plots.wave_origins_figure(origins, route.trajectory.position, route.arrays[0].origin)

# %% [markdown] tags=["explorer"]
# ## 9. What does the curvature measure? (M and SNR sliders)
#
# Theorem 3.1/3.4 (notebook 02): up to $M_{\max}$ antennas a reflected path's exact channel is,
# within a phase error $\varepsilon_\Phi$, the SR-NF one centred on the reflection point; past it
# only the VUE explains it. The explorer resizes the URA, synthesises the *exact* channel, and
# shows the strongest road marking's TLS $\hat\kappa$ between the two candidates and its largest
# SR-NF phase mismatch against $\varepsilon_\Phi = 0.15$ rad. At the paper's 10 × 10 *this
# path's* channel is SR-NF within tolerance (geometry), yet the TLS estimates match neither
# candidate (the estimator). SR-NF belongs to one path: at the same epoch the other marking and
# the ceiling bounce break it, the ceiling at every epoch (notebook 02; printed).

# %% tags=["explorer"]
explorer = cpd_explorer()
explorer

# %%
big, small_arr = curvature_study(16, 30.0, k_demo), curvature_study(3, 30.0, k_demo)
for s in (big, small_arr):
    print(f"M = {s['M']}: kappa {s['kappa'].round(2)}, mismatch {s['mismatch']:.4f} rad")
print(f"candidates: VUE {big['kappa_vue']:.2f} m, reflection {big['kappa_reflection']:.2f} m")
mis = {p.surface: round(mismatch(p, cfg.fc), 3) for p in paths[1:]}  # 10 x 10, epoch 12
drive_paths = [route.paths(k)[1] for k in range(len(route.trajectory))]
ceil_mis = [mismatch(p, cfg.fc) for ps in drive_paths for p in ps if p.surface_kind == "ceiling"]
print(f"10 x 10 mismatch [rad] {mis}; the ceiling's, whole drive: >= {min(ceil_mis):.2f}")

# %% [markdown]
# With a 3 × 3 array SR-NF and exact differ by a few thousandths of a radian, and the TLS mostly
# returns no curvature ($\hat\kappa < 0$: the fallback). With a large array it sits on the VUE's
# distance, never on eq. 51's; at 10 × 10 the ML route already does, to its bound.
#
# ## 10. When the model is wrong: impairments eq. 1 leaves out
#
# A real array adds (`channel.Impairments`) a **calibration error**, element $m$ multiplying what
# it receives by $10^{e_m/20}e^{j\varphi_m}$, $e_m\sim\mathcal N(0,\sigma_\text{dB}^2)$,
# $\varphi_m\sim\mathcal N(0,\sigma_\varphi^2)$, drawn once (a small one below), and **spatial
# wideband**: the wave reaches element $m$ $\delta_{\ell m}/c$ later, so tone $s$ carries
# $e^{-j2\pi (s - s_c)\Delta f\,\delta_{\ell m}/c}$ (over a tenth of a radian at the band edges,
# printed). ML still fits eq. 1; LoS + road at epoch 12:

# %%
impairments = {
    "none": channel.Impairments(),
    "calibration 0.5 deg, 0.05 dB": channel.Impairments(phase_sigma_deg=0.5, gain_sigma_db=0.05),
    "spatial wideband": channel.Impairments(spatial_wideband=True),
}
imp_los = {}
for name, imp in impairments.items():
    r_imp = two.with_impairments(imp, np.random.default_rng(3))
    rows_ = efficiency.drive_efficiency(r_imp, [k_demo], tk.mc_count(10, 1), 21, refines=("ml",))
    r = imp_los[name] = next(x for x in rows_ if x["path"] == "los")
    print(f"{name}: LoS kappa RMSE {r['RMSE kappa [m]']:.3f} m, CRLB {r['CRLB kappa [m]']:.3f} m")
delta_max = max(np.abs(p.delta("exact")).max() for p in paths)  # largest offset [m]
sw_edge = 2 * np.pi * (cfg.n_tones / 2) * cfg.tone_spacing * delta_max / C
print(f"spatial wideband phase at the band edges: up to {sw_edge:.2f} rad")

# %% [markdown]
# The printed CRLB is eq. 1's, no bound for data of another model: ML converges to a pseudo-true
# value (eq. 1's closest fit to the data), its spread about it approximated by the misspecified
# CRB (MCRB, notebooks 07-08). A fraction of a degree of phase error is a bias far above the
# noise, turned by the wrong model's fit into a wrong direction and curvature. Spatial wideband
# can be modelled (ML here does not); the calibration error puts $\kappa$ off by metres.
#
# ## 11. The threshold region: where maximum likelihood leaves the bound
#
# The CRLB is *local* (the likelihood's curvature at the truth) and bounds every unbiased estimator
# at every SNR; at low SNR it still holds, but ML stops attaining it. ML scans about $K = M N_f N_t$
# orthogonal cells (beams × delay × Doppler bins, curvature ignored); on the normalised periodogram
# a noise cell is $|n_1|^2$ (exponential, mean 1), the path's $|\sqrt{\eta} + n_0|^2$ ($\eta =
# P_t|\alpha|^2 M N_f N_t / N_0$: integrated SNR). An *outlier*, a noise cell beating the path, has
# probability $P_\text{out}(\eta) = \Pr(\max_{K-1} |n_k|^2 > |\sqrt{\eta} + n_0|^2)$.
#
# - The **method of interval errors (MIE)** is an *approximation*, not a bound: ML's mean-square
#   error $\approx (1 - P_\text{out})\,\text{CRLB} + P_\text{out}\,\sigma^2_\text{prior}$ (near
#   the truth, or with probability $P_\text{out}$ a guess anywhere in the search space).
# - The **Ziv–Zakai bound** is a *bound* on the mean-square error of any estimator of a parameter
#   drawn from a prior (an average over it), valid at every SNR: near the CRLB far above the
#   threshold, rising towards the prior's variance below. It is not computed here.
#
# The threshold is the $\eta$ where $P_\text{out} = 1\,\%$ (`ml.snr_threshold`); a path below it,
# or closer to another than `ml.RESOLVE_Z` standard deviations, is flagged. The fit is also tested
# by a **generalised likelihood-ratio test (GLRT)**: the likelihood with one path more against the
# fitted model, each maximised over its unknowns, against a threshold set for 1 % false alarms
# (failed: `fit_ok = False`). The LoS alone, a thinner SRS, the SNR lowered step by step:

# %%
thin = replace(cfg, n_rb=20, comb=4)
los_only = replace(route, config=thin, kinds=("los",))
n_cells = array.M * thin.n_tones * thin.n_symbols
eta_th = 10 * np.log10(ml.snr_threshold(n_cells))  # P_out = 1 %
power = abs(los_only.paths(k_demo)[1][0].gain) ** 2 * thin.tx_power  # the LoS's power
eta0 = 10 * np.log10(power * n_cells / thin.noise_power)  # its integrated SNR
offsets = eta_th + np.array([15.0, 8.0, 0.0, -5.0]) - eta0  # to eta_th +15, +8, 0, -5 dB
snr_rows = efficiency.threshold_study(los_only, [k_demo], offsets, tk.mc_count(20, 2), seed=23)
print(f"K = {n_cells} cells: threshold (P_out = 1 %) at an integrated SNR of {eta_th:.1f} dB")
p_out = {}
for r in snr_rows:
    dx = round(r["integrated SNR [dB]"] - eta_th)
    p_out[dx] = float(ml.outlier_probability(10 ** (r["integrated SNR [dB]"] / 10), n_cells))
    print(f"{dx:+3d} dB: MIE P_out {p_out[dx]:.2g}, lost {r['beyond 6 sigma']:.2f}", end=", ")
    print(f"flagged {r['flagged']:.2f}, RMSE/CRLB direction {r['RMS/CRLB direction']:.2f}")
eta_120 = snr_eff[0] - 20 * np.log10(120.0 / paths[0].length)  # the LoS at 120 m, full SRS
margin_120 = eta_120 - 10 * np.log10(ml.snr_threshold(snap.H.size))
print(f"presets' SNR, full SRS: the LoS at 120 m stands {margin_120:.0f} dB above the threshold")

# %% [markdown]
# From 8 dB above the threshold on, ML stays within 3 times the bound (an RMS of few snapshots),
# none lost, $P_\text{out}$ negligible; 5 dB below, the path is lost (beyond 6 standard
# deviations, or missed) in most snapshots, and flagged. The CRLB still holds there: ML has
# stopped attaining it. At the threshold the share lost is well above the MIE's 1 %: an
# approximation, of the search's outliers only. At the presets' SNR the LoS stays far above the
# threshold (margin at 120 m printed; failures past it: extraction notes, part 3).

# %% [markdown]
# ## Exercises
#
# 1. Put a truck (12 m long, 4 m high, in the vehicle's lane) between the vehicle and the BS,
#    `route.tunnel.with_blockers(propagation.truck_box(15, -2.5))`, and rerun sections 1–3 at
#    epoch 12: which paths survive, and which one does Algorithm 1 now call "path 0"?
# 2. Remove the ceiling from the path families (`kinds=("los", "wall", "road", "rrm")`) and
#    compare the LoS RMSE of section 6 with and without it. Why does one path that is a few
#    centimetres longer than the LoS (section 1 prints how many) spoil the LoS estimate?
# 3. Lower the SNR with `signal_route.SignalRoute(..., snr_offset_db=-20)`: at what offset does the
#    CPD stop finding the RRM paths (count `missed`)?
# 4. **Break the ML stage.** (a) On the tensor of sections 2–4 (`snap`), start `ml.fit_ml` at
#    the truth, then at the paper's route estimates `est` (`ml.start_from_estimates(est)`), with
#    the re-seeding switched off (`n_reseed=0`) and on. (b) On a LoS + road tensor, ask
#    `ml.ml_paths` for one path too few and one too many. Each time read `fit.rho` against
#    `fit.rho_max` (the basin test) and `fit.significance`. What went wrong, and how does the
#    fit tell you?
#
# Run All does not run the solutions below: once you have tried, click "Run solution" under
# one (or run `tk.solution("03.2")`); it runs on a copy of your variables. On the static site
# they have run: open one, then "Show the solution's output". What to read in them follows.

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 03.1
# Solution 1: a truck between the vehicle and the BS, epoch 12
from tunnelkit import propagation

tun_truck = route.tunnel.with_blockers(propagation.truck_box(15, -2.5))
arr_t1, ps_t1 = route.paths(k_demo, tunnel=tun_truck)
print("without the truck:", ", ".join(p.surface_kind for p in paths))
print("with the truck:   ", ", ".join(p.surface_kind for p in ps_t1))
snap_t1 = channel.synthesize(ps_t1, cfg, np.random.default_rng(1))
est_t1 = extraction.extract_paths(snap_t1.H, len(ps_t1), arr_t1, cfg, refine="joint")
first_t1 = min(ps_t1, key=lambda p: p.length)
print(f"earliest arrival: {first_t1.surface_kind} ({first_t1.surface}), {first_t1.length:.3f} m;"
      f" path 0 of the extraction: d = {est_t1.d[0]:.3f} m (= length + clock bias "
      f"{C * snap_t1.clock_bias:.3f} m)")  # fmt: skip
assert "los" not in {p.kind for p in ps_t1} and first_t1.surface_kind == "rrm"
assert abs(est_t1.d[0] - first_t1.length - C * snap_t1.clock_bias) < 0.1

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 03.2
# Solution 2: the LoS estimate with and without the ceiling bounce (the paper's route, section 6)
no_ceil = signal_route.SignalRoute(
    route.tunnel, route.arrays, route.trajectory, cfg, kinds=("los", "wall", "road", "rrm")
)
study_nc = evaluation.rmse_study(no_ceil, k_demo, n_mc, seed=11, refine="joint")
sol2 = {"all paths": study_all[0], "no ceiling": study_nc[0], "LoS + road": study_noceil[0]}
for name, r in sol2.items():
    print(f"{name:11s} LoS d RMSE {r['RMSE d [m]']:.4f} m, free-factor CRLB {r['CRLB d [m]']:.4f}"
          f" m, direction RMSE {r['RMSE dir [deg]']:.3f} deg")  # fmt: skip
d_rmse = [sol2[n]["RMSE d [m]"] for n in ("all paths", "no ceiling", "LoS + road")]
assert d_rmse[0] > 5 * d_rmse[1] > 5 * d_rmse[2], d_rmse

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 03.3
# Solution 3: the SNR lowered on the paper's route: how often is each path missed?
n_sol3 = tk.mc_count(10, 2)
sol3 = {}
for off in range(0, -40, -5 if not tk.quick_mode() else -10):
    r3 = signal_route.SignalRoute(
        route.tunnel, route.arrays, route.trajectory, cfg, snr_offset_db=off
    )
    rows3 = evaluation.rmse_study(r3, k_demo, n_sol3, seed=0, refine="joint")
    sol3[off] = {r["surface"] if r["path"] == "rrm" else r["path"]: r["missed"] for r in rows3}
    print(f"SNR {off:+3d} dB: missed of {n_sol3} snapshots {sol3[off]}")
snr3 = {r["surface"] if r["path"] == "rrm" else r["path"]: v
        for r, v in zip(rows3, snap.snr_db.round(1))}  # fmt: skip
print("per-element SNR at 0 dB offset [dB]:", snr3)
assert sol3[0]["los"] + sol3[0]["ceiling"] > 0, sol3  # the merged pair, missed at 0 dB
low = [o for o in sol3 if o <= -10]  # from 10 dB below on: the marking worse, the road less so
assert all(sol3[o]["RRM bottom right"] > sol3[0]["RRM bottom right"] for o in low), sol3
assert 2 * sum(sol3[o]["road"] for o in low) < sum(sol3[o]["RRM bottom right"] for o in low)
assert sum(sol3[-30].values()) >= sum(sol3[0].values()), sol3


# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 03.4a
# Exercise 4, solution (a): starts in the wrong basin, on the tensor of sections 2-4
def truth_start(paths, array, clock_bias):
    """(theta, mu_f, mu_t) of the true paths: (u_x, u_y, 1/kappa) in the array frame, roots."""
    src = np.stack([array.to_local(p.source) for p in paths])
    r = np.linalg.norm(src, axis=1)
    d = np.array([p.length for p in paths]) + C * clock_bias
    return (
        np.column_stack([src[:, :2] / r[:, None], 1.0 / r]),
        -2 * np.pi * cfg.tone_spacing * d / C,
        2 * np.pi * cfg.symbol_period * np.array([p.doppler for p in paths]),
    )


paper_start = ml.start_from_estimates(est)  # the paper's route (section 3) as the start
fits = {
    "truth": ml.fit_ml(snap.H, truth_start(paths, array, snap.clock_bias), array, cfg),
    "paper's route, no re-seeding": ml.fit_ml(snap.H, paper_start, array, cfg, n_reseed=0),
    "paper's route, re-seeding": ml.fit_ml(snap.H, paper_start, array, cfg),
}
for name, f in fits.items():
    print(f"{name:30s} rho = {f.rho:9.3f} (basin test passes below {f.rho_max:.4f})")
assert fits["truth"].rho < fits["truth"].rho_max
assert fits["paper's route, no re-seeding"].rho > 10 * fits["truth"].rho
assert fits["paper's route, re-seeding"].rho < fits["paper's route, re-seeding"].rho_max
assert 10 < fits["paper's route, no re-seeding"].rho < 100  # tens of times the noise floor

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 03.4b
# Exercise 4, solution (b): the wrong number of paths, on a LoS + road tensor
arr2, paths2 = two.paths(k_demo)
snap2 = channel.synthesize(paths2, cfg, np.random.default_rng(4))
args2 = (arr2, cfg)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    wrong_L = {L: ml.ml_paths(snap2.H, L, *args2, n_reseed=0) for L in (1, 2, 3)}
for L, e in wrong_L.items():
    print(f"L = {L}: rho = {e.fit.rho:9.3f}, significance = {np.round(e.fit.significance, 0)}, "
          f"valid = {e.valid}")  # fmt: skip
print("warnings:", sorted({type(w.message).__name__ for w in caught}))
assert wrong_L[1].fit.rho > wrong_L[1].fit.rho_max and wrong_L[2].fit.rho < wrong_L[2].fit.rho_max
assert 100 < wrong_L[1].fit.rho < 1000  # one path too few: hundreds of times
assert not wrong_L[3].valid.all()

# %% [markdown]
# <details><summary>What to read in the solutions</summary>
#
# 1. The 12 m truck in the vehicle's lane shadows the LoS, the ceiling bounce and the road
#    bounce; only a road-marking reflection gets past it. The earliest arrival, "path 0" of
#    Algorithm 1 and the reference of $\Delta d$, is then a reflection, which is why JAVELIN
#    tracks VUEs rather than assuming a LoS.
# 2. On the paper's route the LoS $d$ RMSE is decimetres with the ceiling bounce, an order of
#    magnitude smaller without it, and a fraction of a millimetre with LoS + road only (printed).
#    The ceiling path has the same delay and Doppler as the LoS within the noise, so the CPD must
#    split their sum with the spatial factor alone, and a free spatial factor can rotate between
#    them (Kruskal rank 1 in time, section 4); the free-factor CRLB grows accordingly.
# 3. The CPD loses paths long before the noise hides them, and not the weakest first: already at
#    the presets' SNR the LoS and the ceiling bounce are often merged (one of them missed); from
#    about 10 dB below on, the bottom-right road marking is missed more often than at the
#    presets' SNR, while the road bounce, the weakest per element, is missed less than half as
#    often as that marking over the same levels. What a free spatial factor cannot separate goes
#    first. (Quick mode: two snapshots per level, so the counts are coarse.) Try the same with
#    `refine="ml"` (slower): its `MLDetectionWarning` says when a path no longer stands above
#    the noise.
#
# </details>
#
# <details><summary>What happened in exercise 4</summary>
#
# (a) From the truth the fit stays there and $\rho \approx 1$: the residual is the noise. The
# paper's route merged the LoS and the ceiling bounce into one component and left a spare one
# on noise: started there, Levenberg–Marquardt improves what it has and stops in a local
# minimum whose residual is tens of times the noise floor — one wave is explained by
# two starts, another by none, and no small step fixes that. The basin test sees it
# ($\rho \gg \rho_{\max}$). With re-seeding on, the fit drops the least significant path,
# searches the residual for it (SAGE-like: power iterations, periodogram, beam scan, curvature
# scan) and refits: back to $\rho\approx 1$. (b) With one path too few the missing path stays
# in the residual: $\rho$ is hundreds of times the floor whatever the fit does (re-seeding cannot
# help; try it). With one too many the extra path fits noise: its significance (log-likelihood
# ratio against noise) is tiny, it is returned with `valid = False`, and an `MLDetectionWarning`
# says so. The residual against the noise floor is the estimator's own check of both its start
# and its model order.
#
# </details>

# %% [markdown]
# ## Checks

# %%
los = paths[0]
# sections 1-2: the paths, section 4.2's SRS, the clock bias read as a 50 ns sd
assert los.kind == "los" and abs(los.length - np.linalg.norm(ue - array.origin)) < 1e-12
assert {p.surface_kind for p in paths} >= {"los", "ceiling", "road", "rrm"} and cfg.comb == 8
assert np.ptp([p.length for p in paths]) < 1.5 and cfg.bandwidth == 100e6
assert 0 < ceil.length - los.length < 0.1 and abs(ceil.doppler - los.doppler) < 0.01 * doppler_res
assert ceil.kappa_srnf < 0.25 * ceil.length and 0 < ceil_gap < ceil.kappa_srnf
assert snap.H.shape == (100, 410, 12) and cfg.tone_spacing == 240e3 and cfg.fc == 5.9e9
assert abs(cfg.symbol_period - 35.7e-6) < 0.05e-6 and abs(snap.clock_bias) <= cfg.clock_bias_limit
assert np.isclose(cfg.clock_bias_sigma, 50e-9) and np.isclose(cfg.clock_bias_limit, 100e-9)
assert 7.0e-9 < sd_ns2 < 7.1e-9 and 14.0 < cfg.clock_bias_limit / sd_ns2 < 14.2
assert 2.3e3 < doppler_res < 2.4e3 and 118.5 < doppler_res * C / cfg.fc < 119.5
# sections 3-5: the CPD, the numerically rank-one time factor, eq. 13 not efficient
assert est.rel_error < 0.05 and np.all(np.isfinite(est.d)) and kr_t[1e-2] == 1
assert cmp["joint"]["RMSE d [m]"] < cmp["none"]["RMSE d [m]"]
assert cmp["ml"]["RMSE d [m]"] < 3 * cmp["ml"]["CRLB d [m]"]
# section 6, LoS + road: d and v within 2x the bound of the model the route fits, dir/kappa above
arr_two, paths_two = two.paths(k_demo)
free_two, nc = extraction.path_crlb(paths_two, arr_two, cfg, spatial="free"), study_noceil[0]
assert nc["RMSE d [m]"] < 2 * free_two["d"][0] and nc["RMSE v [m/s]"] < 2 * free_two["v"][0]
assert 2 * nc["CRLB dir [deg]"] < nc["RMSE dir [deg]"] < 2.0
assert nc["RMSE kappa [m]"] > 2 * nc["CRLB kappa [m]"]
# ... all paths: the merged pair under its huge (metres) free-factor bound in d, at times missed
assert [r["path"] for r in pair] == ["los", "ceiling"]
assert all(r["CRLB d [m]"] > 1.0 and r["RMSE d [m]"] < r["CRLB d [m]"] for r in pair), pair
assert min(r["matched"] for r in pair) < n_mc and {"matched share"} < set(both[0]), pair
assert np.allclose([r["CRLB kappa [m]"] for r in study_all], b_eq1["kappa"], rtol=1e-9)
for r in study_all:
    assert r["RMSE dir [deg]"] > 100 * r["CRLB dir [deg]"], r
    assert r["RMSE kappa [m]"] > 100 * r["CRLB kappa [m]"], r
assert b_eq1["d"].max() < 1e-3 and study_all[0]["RMSE d [m]"] > 100 * b_eq1["d"][0]
assert 5e-4 < study_all[0]["CRLB dir [deg]"] < 5e-3 and 0.01 < b_eq1["kappa"].min()
assert b_eq1["kappa"].max() < 0.1 and np.all(b_free["d"] > b_eq1["d"])
# section 7: the ML stage within 1.5x the bound (4x in quick mode: RMS over 2 snapshots)
ml_rows, lim = {r["path"]: r for r in study_ml}, (4.0 if tk.quick_mode() else 1.5)
assert ml_rows["los"]["matched"] >= 2 and ml_rows["los"]["missed"] == 0
for r in (ml_rows[kind] for kind in ("los", "road", "ceiling")):
    assert r["RMSE kappa [m]"] < lim * r["CRLB kappa [m]"], r
    assert r["RMSE dir [deg]"] < lim * r["CRLB dir [deg]"], r
# ... along the drive: ML mostly inside the 90 % band, kappa's bound mm to dm, the paper far above
(lo1, hi1), (lo_n, hi_n) = chi_band[1], chi_band[n_eff]
assert 0.01 < lo1 < 0.1 and 1.5 < hi1 < 2.5 and lo_n < 1 < hi_n
assert np.mean([lo_n <= x <= hi_n for x in ratio_ml]) > 0.5 and max(ratio_ml) < 5.0, ratio_ml
assert min(crlb_k) < 0.01 and max(crlb_k) > 0.1, crlb_k
paper = [r for r in eff if r["route"] == "joint" and r["path"] == "los"]
assert np.nanmin([r["RMSE kappa [m]"] / r["CRLB kappa [m]"] for r in paper]) > 10
# section 8: ceiling high, road and RRMs low; the ceiling's kappa inside the ML search's 0.5 m
z_srnf = origins["srnf channel"][:, 2]
assert np.nanmax(z_srnf) > 4.0 and np.nanmin(z_srnf) < 1.0 and 0.5 < ceil.kappa_srnf
# section 9: SR-NF holds for the marking shown, not the other one nor the ceiling (any epoch)
title = explorer.figure.layout.title.text
assert title.startswith(f"epoch {k_demo}") and "SR-NF within" in title and "neither" in title
assert big["surface"] == small_arr["surface"] == "RRM bottom right"
assert mis["RRM bottom right"] < 0.15 < min(mis["RRM top left"], mis[ceil.surface], *ceil_mis)
assert abs(np.median(big["kappa"]) - big["kappa_vue"]) < 0.1 * big["kappa_vue"]  # VUE, not eq. 51
assert big["mismatch"] > 0.15 and 1e-3 < small_arr["mismatch"] < 1e-2
assert np.sum(small_arr["kappa"] < 0) > len(small_arr["kappa"]) / 2  # mostly the fallback
# section 10: impairments lift the estimate off the bound; the small calibration error by metres
assert imp_los["none"]["RMSE kappa [m]"] < 5 * imp_los["none"]["CRLB kappa [m]"]
for r in list(imp_los.values())[1:]:  # lost: the curvature gone altogether, a plane-wave fit
    assert r["no kappa"] == r["matched"] or r["RMSE kappa [m]"] > max(10 * r["CRLB kappa [m]"], 1)
assert 0.1 < sw_edge < 0.3
# section 11: within 3x the bound from 8 dB above the threshold, lost and flagged 5 dB below
at = {round(r["integrated SNR [dB]"] - eta_th): r for r in snr_rows}
assert sorted(at) == [-5, 0, 8, 15] and 12.0 < eta_th < 16.0
assert abs(float(ml.outlier_probability(10 ** (eta_th / 10), n_cells)) - 0.01) < 1e-4
assert p_out[15] < 1e-6 and p_out[8] < 1e-3 and p_out[-5] > 0.5, p_out
assert all(at[x]["RMS/CRLB direction"] < 3.0 and at[x]["beyond 6 sigma"] == 0 for x in (8, 15))
assert at[-5]["beyond 6 sigma"] > 0.5 and at[-5]["flagged"] > 0.5, at[-5]
assert at[0]["beyond 6 sigma"] > 0.05 and margin_120 > 10.0, at[0]  # well above the MIE's 1 %
# exercises 1-4: asserted in their solutions (run in CI)
print("all checks passed")
