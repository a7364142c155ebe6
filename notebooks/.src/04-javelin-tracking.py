# %% [markdown]
# # 04 · JAVELIN: tracking a vehicle and its virtual UEs with one base station
#
# *Italiano, Brambilla & Nicoli (2026), "In-Tunnel Single-Anchor Localization Exploiting Near-Field
# and Radio-Reflective Road Markings", [arXiv:2604.04217](https://arxiv.org/abs/2604.04217v1),
# sections 3.2–3.5 (eq. 43–68, Algorithms 1–4) and 4 (Figs. 6–7; the TeNFiLoc baseline's eq. 69
# is in section 4.3).
# All references: `REFERENCES.md` at the top of the repository; terms and abbreviations: the
# [glossary](GLOSSARY.md).*
#
# **What you will learn**
#
# - the variable-dimension state of eq. 43 (the UE plus one $(y, z)$ pair per virtual UE) and the
#   measurement model of eq. 44–52, with its Jacobian checked against finite differences;
# - what the measurements the tracker is fed look like when they come out of the channel tensor
#   and the extraction of notebook 03 rather than out of a noise generator: why the paper's CPD
#   merges paths that arrive together, and what a structured maximum-likelihood fit measures;
# - the prediction of eq. 62–63 (V2X speed/heading for the UE, a random walk for VUEs), why a
#   wall-fixed VUE should rather *mirror* the UE's motion, and what eq. 62's held heading costs
#   on a turn;
# - the chi-square gate (eq. 56–59), nearest-neighbour association (Algorithm 2), births, deaths,
#   the LoS test (eq. 60–61) and the Doppler test (Algorithm 3), epoch by epoch with a slider;
# - the Joseph-form EKF update (eq. 64–68) and the whole loop of Algorithm 4;
# - the trajectories of Fig. 6 (JAVELIN against the snapshot baseline [TeNFiLoc](GLOSSARY.md#tenfiloc)) and the error
#   CDFs of Fig. 7 on a few drives, beside the baseline the paper does not draw: dead reckoning
#   on the same V2X messages.
#
# The reproduction of Tables 1–2 over 20 runs, the road-marking ablation and how our design was
# chosen and measured are in the appendix notebook `04b-javelin-reproduction`.

# %%
from dataclasses import replace

import numpy as np
from IPython.display import display

import tunnelkit as tk
from tunnelkit import simulation as ex
from tunnelkit.crlb import numeric_jacobian
from tunnelkit.evaluation import match_paths
from tunnelkit.extraction.coherent import resolve_coherent
from tunnelkit.metrics import position_errors
from tunnelkit.plots import (
    cdf_figure,
    javelin_table_figure,
    tracks_count_figure,
    trajectories_figure,
)
from tunnelkit.reckoning import dead_reckoning
from tunnelkit.signal_route import SignalRoute, measurements_from_estimates
from tunnelkit.simulation import collect_routes
from tunnelkit.tracking.javelin import TeNFiLoc, designs, measurement_model
from tunnelkit.tracking.javelin.measured import design_from_errors
from tunnelkit.tracking.javelin.motion import midpoint_messages
from tunnelkit.widgets import epoch_explorer

tk.setup_notebook()

# %% [markdown]
# ## 1. A drive through the signal route
#
# The setup has two sources. **The paper** gives the tunnel and the radio: a straight
# semicircular tunnel 100 m long, 10 m wide and 5 m high, one base station (the anchor) at its
# centre 4.8 m high with two arrays looking both ways along the tunnel, and four metallic road
# markings (RRMs) (section 4.1); 10 × 10 URAs, a 5.9 GHz carrier and a 100 MHz uplink SRS of 12
# symbols per slot (section 4.2). It does **not** give the vehicle's speed, the time between
# epochs or where the drive starts and ends (its trajectories come from MATLAB's Driving
# Scenario). Those are the package's preset `italiano2026-straight` (`tunnelkit.scenarios`,
# printed below): the vehicle drives from x = 45 m towards the BS to x = 5 m at 50 km/h, one
# epoch (one SRS slot) every 0.1 s; the preset also places the RRMs and hangs each array just
# below the anchor, so that the tilted array fits under the curved ceiling.
#
# Every epoch goes through the signal route of notebook 03: image-method paths → the tensor of eq. 1
# with noise and a clock bias → extraction → Algorithm 1. The drive is measured twice from the
# *same* tensors: with the paper's extraction (CPD, eq. 11–24) and with the joint maximum-likelihood
# fit of eq. 1 (`extract_paths(refine="ml")`, notebook 03 section 7), whose errors come close to the
# Cramér–Rao bound at this SNR (notebook 03 checks how close; the CRLB: the smallest variance an
# unbiased estimator can have; see [bounds](GLOSSARY.md#bounds)). One drive in LoS on the straight
# trajectory and one on the slalom (quick mode: their first 6 epochs).

# %%
preset = tk.load_scenario("italiano2026-straight")
tunnel_size = [preset.section("tunnel")[q] for q in ("length", "width", "height")]
anchor_z = preset.section("base_station")["position"][2]
array_shapes = [a["shape"] for a in preset.section("base_station")["arrays"]]
n_rrm_plates = len(preset.section("tunnel")["plates"])
traj = preset.section("trajectory")
speed_kmh = 3.6 * traj["speed"]
print(
    f"from the paper: tunnel {tunnel_size} m, anchor {anchor_z} m high, arrays {array_shapes}, "
    f"{n_rrm_plates} RRMs"
)
print(
    f"from the preset: x = {traj['x_start']} m to {traj['x_end']} m at {speed_kmh:.1f} km/h, "
    f"one epoch every {traj['period']} s"
)

# %% tags=["explorer-setup"]
n_epochs = 6 if tk.quick_mode() else None  # quick mode: the first 6 epochs (0.6 s) of each drive
first = {
    sc: collect_routes(sc, ("L",), 1, 0, n_epochs=n_epochs)
    for sc in ("italiano2026-straight", "italiano2026-slalom")
}
drive, drive_ml = (first["italiano2026-straight"][e]["L"][0] for e in ("paper", "ml"))
sl, sl_ml = (first["italiano2026-slalom"][e]["L"][0] for e in ("paper", "ml"))
n_paths = [0 if m is None else len(m) for m in drive.epochs]
print(f"{len(drive.epochs)} epochs, {drive.dt:.1f} s apart; paths kept per epoch: {n_paths}")
print("true paths per epoch:", drive.n_true.tolist())

# %% [markdown]
# ## 2. State and measurement model (eq. 43–52)
#
# The state stacks the UE position and, per tracked VUE, its lateral and vertical coordinates
# (the surfaces run along the tunnel, so a VUE shares the UE's $x$):
#
# $$\mathbf s = [\mathbf p_u^\mathsf T\; y_{v,1}\; z_{v,1} \cdots y_{v,\hat L-1}\; z_{v,\hat L-1}]^\mathsf T
# \in \mathbb R^{2\hat L + 1}. \tag{43}$$
#
# Seen from the reference antenna, each track gives an azimuth and an elevation (eq. 46–47,
# 49–50), a wavefront curvature — the UE range for LoS (eq. 48), the distance to the reflection
# point of eq. 45 for a VUE (eq. 51) — and a TDoA against the LoS, $\Delta d_\ell = \|\mathbf p_{v,\ell}\|
# - \|\mathbf p_u\|$ (eq. 52), free of the clock bias. We build the *true* state of one epoch from
# the traced paths and check the analytic Jacobian (eq. 55) against central differences.

# %% tags=["explorer-setup"]
k = 4 if tk.quick_mode() else 8
src = drive.sources[k]  # true UE (LoS first) and VUEs of epoch k
s_true = np.concatenate([src[0], src[1:, 1:].ravel()])
h, H = measurement_model(s_true, drive.base_station)
H_num = numeric_jacobian(lambda s: measurement_model(s, drive.base_station)[0], s_true)
jac_err = float(np.abs(H - H_num).max())
print("state dimension D =", s_true.size, " measurements K =", h.size, " max |H - H_fd| =", jac_err)

# %% [markdown]
# What does the extraction deliver against this model? Each extracted path was matched to its
# true path by the **Hungarian algorithm**, which solves the *assignment problem*: given a cost
# for every pair (extracted path, true path) — here the difference in delay distance plus the
# angle between the two directions, each scaled — it finds the one-to-one pairing of smallest
# total cost (scipy's `linear_sum_assignment`; a pair too costly stays unmatched, and an
# extracted path left over is clutter). The table lists the error in azimuth and elevation and
# the extracted curvature beside eq. 51's value and the VUE distance.


# %%
def model_rows(d, k):
    """Each extracted path of epoch k of drive d beside the model of eq. 46-51."""
    m, L = d.epochs[k], len(src)
    rows = []
    for j, t in enumerate(d.truth_index[k]):
        if t < 0:
            rows.append([f"path {j}", "clutter", None, None, m.kappa[j], None, None, m.v[j]])
            continue
        vue = np.linalg.norm(src[t] - d.base_station)
        dphi, dpsi = np.degrees(m.phi[j] - h[t]), np.degrees(m.psi[j] - h[L + t])
        rows.append([f"path {j}", d.kinds[k][t], dphi, dpsi, m.kappa[j], h[2 * L + t], vue, m.v[j]])
    return rows


cols = ["path", "surface", "Δφ [deg]", "Δψ [deg]", "κ̂ [m]", "κ eq. 51 [m]", "‖VUE‖ [m]", "v̂ [m/s]"]
javelin_table_figure(cols, model_rows(drive, k), title=f"epoch {k}: extracted vs model")

# %% [markdown]
# Two things stand out. (i) The LoS path and the ceiling reflection arrive almost together (the
# array hangs just under the ceiling): the CPD mixes them, so their angles are off by degrees and
# their curvature belongs to neither. (ii) The paper's route reads $\hat\kappa$ more than ten metres
# away from the true curvature (over the whole drive: the median printed below) — not because
# the array cannot measure it (notebook 03: along this drive its Cramér–Rao bound runs from
# millimetres near the BS to decimetres at the far end), but because a CPD with free spatial
# factors followed by a TLS is far from efficient. The paper assumes $\sigma_\kappa = 1.5$ m
# (section 4.2). The Doppler of the matched paths, on the other hand, stays close to the
# vehicle's speed, and a spurious CPD component (a "clutter" row, when there is one) shows itself
# by a radial speed no static reflector can produce.


# %%
def curvature_errors(d):
    """|kappa_hat - distance to the true wave source| [m] of every matched path of drive d that
    has a curvature (the source: the UE for the LoS, the VUE for a reflection)."""
    out = []
    for e, m in enumerate(d.epochs):
        for j, t in enumerate(d.truth_index[e] if m is not None else []):
            if t >= 0 and np.isfinite(m.kappa[j]):
                out.append(abs(m.kappa[j] - np.linalg.norm(d.sources[e][t] - d.base_station)))
    return np.asarray(out)


kappa_err_paper = curvature_errors(drive)
print(f"paper route, this drive: median curvature error {np.median(kappa_err_paper):.1f} m")

# %% [markdown]
# ## 3. Paths the CPD merges, and what a structured fit measures (ours)
#
# In this tunnel every path of an epoch arrives less than 2 m behind the LoS, where the 100 MHz
# SRS resolves $c/B$ = 3 m, and within a few metres per second of it in radial speed, where 12
# symbols resolve $c/(f_c N_t T_0)$, about 119 m/s (the traced paths of the whole drive are
# printed below). Take two paths with the same delay and Doppler: their frequency and time factors are
# the same vectors $\mathbf b_f$, $\mathbf b_t$, and in the CPD of eq. 3/11
#
# $$\alpha_1\,\mathbf s(\mathbf q_1)\circ\mathbf b_f\circ\mathbf b_t + \alpha_2\,\mathbf s(\mathbf q_2)\circ\mathbf b_f\circ\mathbf b_t
# = \big(\alpha_1\mathbf s(\mathbf q_1) + \alpha_2\mathbf s(\mathbf q_2)\big)\circ\mathbf b_f\circ\mathbf b_t$$
#
# is **one** rank-one term. The CPD returns one component whose spatial factor is a mixture, and
# eq. 16–24 read one biased direction from it; the spare component of the rank-$L$ fit goes to
# noise. The ceiling bounce (just above the array, centimetres longer than the LoS) is the worst
# case, and the road bounce (tenths of a metre longer) is not far behind.

# %%
sr_straight = SignalRoute.from_scenario("italiano2026-straight")
srs = sr_straight.config
excess, rate_gap = {}, []  # per kind: path length minus the LoS's; |range rate - the LoS's|
for e in range(len(sr_straight.trajectory)):
    traced = sr_straight.paths(e)[1]
    los_path = next(p for p in traced if p.kind == "los")
    for p in traced:
        excess.setdefault(p.surface_kind, []).append(p.length - los_path.length)
        rate_gap.append(abs(p.range_rate - los_path.range_rate))
res_range = tk.constants.C / srs.bandwidth
res_speed = tk.constants.C / (srs.fc * srs.n_symbols * srs.symbol_period)
print(f"resolution: range {res_range:.1f} m, radial speed {res_speed:.0f} m/s")
print(
    f"largest path-length gap to the LoS {max(max(v) for v in excess.values()):.2f} m, "
    f"largest radial-speed gap {max(rate_gap):.2f} m/s"
)
print(
    "median length gap to the LoS [m]:",
    {q: round(float(np.median(v)), 3) for q, v in excess.items()},
)

# %% [markdown]
# The array still tells them apart: the steering vector of a point source $\mathbf q$ (eq. 1–2,
# local frame) is known, $[\mathbf s(\mathbf q)]_m = e^{jk_0(\|\mathbf q - \mathbf p_m\| - \|\mathbf q\|)}$.
# The maximum-likelihood route of notebook 03 fits eq. 1 itself — per path a wave origin, a
# delay, a Doppler and a gain, all paths jointly — to the whole tensor, started from the CPD and
# the coherent split, with a residual test against the noise floor. The same epoch, same tensor:

# %%
javelin_table_figure(cols, model_rows(drive_ml, k), title=f"epoch {k}: ML route vs model", digits=4)

# %%
t_ceil = list(drive.kinds[k]).index("ceiling")  # the ceiling bounce of epoch k
kappa51_ceil = float(h[2 * len(src) + t_ceil])
vue_ceil = float(np.linalg.norm(src[t_ceil] - drive.base_station))
print(
    f"epoch {k}, ceiling bounce: kappa of eq. 51 (distance to the reflection point) "
    f"{kappa51_ceil:.2f} m, distance to its VUE {vue_ceil:.2f} m"
)

# %% [markdown]
# One drive is one draw of the noise. Over a few drives per condition (quick mode: one shortened
# drive), per kind of path: how many were found, and how far off their direction is; then what
# the tracker is fed on the ML route — the RMS error of each measurement of eq. 54 per kind of
# path (curvature against the distance of the true wave source, the UE or its VUE; $\Delta d$
# against the true TDoA). The drives of section 1 are the first of these.
#
# Our ML-route design (notebook 04b) set its measurement noise on these drives, so they show what
# the extraction does, not how well that design tracks: notebook 04b scores it on drives held out.

# %%
runs = tk.mc_count(3, 1)
straight_conditions = ("L", "N") if tk.quick_mode() else ("L", "N@0.5", "N", "NoRRMs")
slalom_conditions = ("L",) if tk.quick_mode() else ("L", "N@0.5", "N")
routes = {
    sc: collect_routes(sc, conds, runs, 0, progress=True, n_epochs=n_epochs)
    for sc, conds in (
        ("italiano2026-straight", straight_conditions),
        ("italiano2026-slalom", slalom_conditions),
    )
}
straight, straight_ml = (routes["italiano2026-straight"][e] for e in ("paper", "ml"))
slalom_ml = routes["italiano2026-slalom"]["ml"]

# %%
los_rms, los_median = {}, {}
for name, d in (("paper", straight["L"]), ("ML", straight_ml["L"])):
    pcols, prows = ex.path_errors(d)
    los_rms[name], los_median[name] = {r[0]: r[3:5] for r in prows}["los"]
    display(javelin_table_figure(pcols, prows, title=f"straight, L: {name} route", digits=4))
ecols, erows = ex.extraction_errors(straight_ml["L"] + slalom_ml["L"])
javelin_table_figure(ecols, erows, title="ML route: RMS measurement error per path", digits=4)

# %% [markdown]
# Read the last table against the paper's assumed noise (section 4.2),
# $\sigma_\phi = \sigma_\psi = 2°$, $\sigma_\kappa = \sigma_{\Delta d} = 1.5$ m (the ratios are
# printed below). In the angles and the TDoA the ML route's RMS errors are two to four orders of
# magnitude smaller. In the curvature they are smaller by a factor of several: decimetres
# along the drive, which is what notebook 03's Cramér–Rao bound allows a 10 × 10 array there
# (millimetres near the BS, decimetres at the far end) and what its ML fit reaches. So the
# paper's 1.5 m is a generous assumption on this route — and far too tight on the paper's own
# route, whose curvatures are more than ten metres off (section 2). Where the ML fit's own test
# flags an epoch (a path missed or merged), the epoch carries no measurement and the tracker
# only predicts: one reason why "found" can fall short of "true" in the ML route's table.
#
# The curvature the ML route measures for a reflection is the distance to its **VUE** (the exact
# wavefront's radius), not eq. 51's distance to the reflection point (the SR-NF model) — for the
# ceiling bounce the two differ most (printed under this section's first table). The paper's
# design as printed uses eq. 51; we run it both ways (`designs.paper()`, and
# `designs.paper_vue()`, which changes only that).
#
# A tracker's measurement noise $\mathbf R$ should say what the extraction delivers; the pooled
# row "all" gives four sigmas. Our design for the ML route (notebook 04b) assumes wider ones, by
# the factors printed below, chosen on the tuning drives: a Gaussian $\mathbf R$ set to the RMS
# of a heavy-tailed error makes the gate reject the next good measurement after a rare gross
# error (two nearly coincident paths swapped or merged), so how wide to make it is a choice about
# the tails (notebook 04b, exercise 2). The paper's values, what this route measures, and what
# our ML-route design assumes:

# %%
measured = design_from_errors(erows)
sig = {}
for name, d in (
    ("the paper (section 4.2)", designs.paper()),
    ("measured here", measured),
    ("our ML design assumes", designs.ours_ml()),
):
    c = d.config
    sig[name] = np.array(
        [np.degrees(c.sigma_phi), np.degrees(c.sigma_psi), c.sigma_kappa, c.sigma_delta_d]
    )
    print(
        f"{name:24s} sigma_phi {sig[name][0]:6.3f} deg  sigma_psi {sig[name][1]:6.3f} deg  "
        f"sigma_kappa {sig[name][2]:6.2f} m  sigma_dd {sig[name][3]:6.4f} m"
    )
print("paper / measured:  ", np.round(sig["the paper (section 4.2)"] / sig["measured here"], 0))
print("ours / measured:   ", np.round(sig["our ML design assumes"] / sig["measured here"], 0))

# %% [markdown]
# ## 4. Prediction (eq. 62–63)
#
# The UE moves by the V2X speed $\nu$ and heading $\theta$ of the previous epoch:
# $\mathbf p_{u,k} = \mathbf p_{u,k-1} + T\nu_{k-1}[\cos\theta_{k-1}, \sin\theta_{k-1}, 0]^\mathsf T$, with
# $\mathbf Q_u = \mathbf G\,\mathrm{diag}(\sigma_\nu^2, \sigma_\theta^2)\mathbf G^\mathsf T$ and
# $\mathbf G = \partial\Delta\mathbf p/\partial(\nu, \theta)$ (proportional to $T$, since
# $\Delta\mathbf p$ is). The paper lets every VUE follow a
# random walk. But a VUE of a surface along the tunnel *is* the UE mirrored in it, so it moves by
# the mirrored displacement $\Delta_v = \Delta_u - 2(\mathbf n\cdot\Delta_u)\mathbf n$. How far off is each
# prediction from the true VUEs one epoch later, on the slalom?

# %%
vue_err = {mode: ex.vue_prediction_errors(sl, mode) for mode in ("random_walk", "mirror")}
for mode, e in vue_err.items():
    print(
        f"{mode:12s} median {np.median(e) * 100:5.1f} cm   90 % {np.percentile(e, 90) * 100:5.1f} cm"
    )

# %% [markdown]
# The mirror model is exact for planar surfaces along the tunnel; what is left, apart from the
# UE's own step (next), is the ceiling's facets (a curved surface moves its VUE differently) and
# paths that switch surface.
#
# The UE's step itself lags on a turn. Eq. 62 moves the UE into epoch $k$ on the message of epoch
# $k-1$, held over the step. The displacement the step must reproduce is the chord, the straight
# segment from $\mathbf p_{u,k-1}$ to $\mathbf p_{u,k}$. On a turn at yaw rate $\omega$ the held
# heading $\theta_{k-1}$ lags the chord's heading by half the turn made over the step,
# $(\theta_k - \theta_{k-1})/2 = \omega T/2$, so each step lands about $\nu\omega T^2/2$ to the
# side, and that adds up over the drive. On a steady turn the chord's heading is exactly the mean
# of the two headings taken along the shorter arc, $\theta_{k-1} + \tfrac12\,
# \mathrm{wrap}(\theta_k - \theta_{k-1})$ (this drive heads along $-x$, its heading crossing
# $\pm 180°$, where the plain average of the two angles would point the step backwards). Our
# designs step on that mean (`JavelinConfig(motion_step="midpoint")`; the paper's design keeps
# eq. 62). It needs the message of epoch
# $k$ when predicting into $k$; the filter has it, since the prediction runs when epoch $k$'s
# measurements arrive (where that message is missing, the step stays held). Dead reckoning
# (integrating the messages alone, no radio) along the slalom's whole drive on its true,
# noise-free messages, both ways, and the mirrored VUE prediction above with the midpoint step:

# %%
slalom_path = SignalRoute.from_scenario("italiano2026-slalom").trajectory
v_true = slalom_path.velocity[:, :2]
true_msgs = (np.linalg.norm(v_true, axis=1), np.arctan2(v_true[:, 1], v_true[:, 0]))
step_rms = {}
for name, msgs in (("held (eq. 62)", true_msgs), ("midpoint", midpoint_messages(*true_msgs))):
    e = dead_reckoning(slalom_path.t, *msgs, slalom_path.position[0, :2])
    e = e - slalom_path.position[:, :2]
    step_rms[name] = float(np.sqrt(np.mean(np.sum(e**2, axis=1))))
    print(f"{name:14s} RMS {step_rms[name]:.3f} m over {len(slalom_path.t)} epochs")
# the VUEs' mirrored prediction with the UE stepping on the midpoint of two true velocities
sp, hd = midpoint_messages(np.linalg.norm(sl.velocity[:, :2], axis=1),
                           np.arctan2(sl.velocity[:, 1], sl.velocity[:, 0]))  # fmt: skip
v_mid = np.stack([sp * np.cos(hd), sp * np.sin(hd), sl.velocity[:, 2]], axis=-1)
vue_err["mirror, midpoint step"] = ex.vue_prediction_errors(replace(sl, velocity=v_mid), "mirror")
for mode in ("mirror", "mirror, midpoint step"):
    print(f"VUE prediction, {mode:22s} median {np.median(vue_err[mode]) * 100:5.2f} cm")

# %% [markdown]
# With no noise at all the held step leaves dead reckoning about a third of a metre off on the
# slalom, the midpoint a few centimetres: the slalom is not a steady turn (its yaw rate swings
# from one side to the other), so the mean heading is right only to second order. Most of what
# the mirrored VUE prediction left above was this same lag, copied to the VUEs. The tracker's
# prediction carries it too, and its process noise $\mathbf Q_u$ does not model it, so on a
# turning drive part of what the radio corrects is eq. 62's own lag. In the reproduced tables the
# paper's design keeps eq. 62 and ours steps on the midpoint, each column's dead reckoning as its
# design; `tunnelkit reproduce javelin-table2 --motion-step held` (or `midpoint`) makes every
# design take one step (`docs/results/baselines.md` measures both).
#
# ## 5. Gate and association (eq. 55–59, Algorithm 2)
#
# For every pair (track $i$, path $j$) the three rows $(\phi_j, \psi_j, \kappa_j)$ of the Jacobian
# give $\mathbf S_{ij} = \hat{\mathbf H}_\hbar\hat{\mathbf P}\hat{\mathbf H}_\hbar^\mathsf T + \mathbf R_\hbar$
# (eq. 56), the innovation $\mathbf y_{ij}$ (eq. 57) and $\eta^2_{ij} = \mathbf y_{ij}^\mathsf T\mathbf S_{ij}^{-1}\mathbf y_{ij}$
# (eq. 58). A pair is feasible if $\eta^2_{ij} < \chi^2_3(p)$ (eq. 59); the nearest feasible pair
# is taken first, then the next (greedy nearest neighbour). A far-field path (no curvature) is
# gated on its two angles with $\chi^2_2(p)$. We run the tracker with the paper's design on the
# paper's extraction, and the paper's design (curvature centred on the VUE) on the ML route, on
# the same drive, keeping every step's report.

# %% tags=["explorer-setup"]
gate = tk.tracking.javelin.ChiSquareGate(0.99)
print(f"chi2_3(0.99) = {gate.threshold(3):.3f}, chi2_2(0.99) = {gate.threshold(2):.3f}")
ev_paper = ex.evaluate(drive, designs.paper(), keep_reports=True)
ev_ml = ex.evaluate(drive_ml, designs.paper_vue(), keep_reports=True)
rep = ev_ml.run.reports[k]
print(f"epoch {k}: eta^2 (rows: tracks UE, VUE {rep.prior_ids}; columns: paths)")
print(np.round(rep.costs.eta2, 1))
print("gated:\n", rep.costs.gated.astype(int), "\nassociated (track, path):", rep.associated)

# %% [markdown]
# ## 6. Track management (Algorithm 3) and the EKF update (eq. 64–68)
#
# A track missed $\zeta = 1$ time is marginalised out (rows and columns of $\hat{\mathbf P}$
# dropped); every unassociated path gives birth to a VUE where its arrival ray meets the plane
# $x = \hat x_u$, with covariance $\sigma_P^2\mathbf I$. If no path was associated with the UE, the
# LoS is the path minimising $|\hat d_\ell - \hat\kappa_\ell|$ (eq. 60) provided
# $1 - \gamma \le \hat d/\hat\kappa \le 1 + \gamma$ (eq. 61). The update stacks the associated rows
# and uses the Joseph form $\mathbf P = (\mathbf I - \mathbf K\mathbf H)\mathbf P(\mathbf I - \mathbf K\mathbf H)^\mathsf T + \mathbf K\mathbf R\mathbf K^\mathsf T$
# (eq. 68), which keeps $\mathbf P$ symmetric positive semi-definite. How many tracks live, and how
# often are they born and killed?

# %%
churn = {}
for name, ev in (("paper route", ev_paper), ("ML route", ev_ml)):
    reps = ev.run.reports
    births = sum(len(r.manage.born) for r in reps if r.manage)
    deaths = sum(len(r.manage.dead) for r in reps if r.manage)
    los = sum(bool(r.manage and r.manage.los) for r in reps)
    churn[name] = {"births": births, "deaths": deaths, "epochs": len(reps)}
    print(
        f"{name:11s} births {births:3d}  deaths {deaths:3d}  epochs declared LoS {los}/{len(reps)}"
        f"  2-D RMSE {ev.metrics['rmse_2d_m']:.2f} m"
    )
tracks_count_figure(
    drive.t,
    ev_ml.run.n_tracks,
    drive.los,
    title="tracked states per epoch (paper's design + VUE curvature, ML route)",
)

# %% [markdown]
# On the paper's route the paper's design churns: with curvatures more than ten metres off and
# $\sigma_\kappa = 1.5$ m the true pairs fail the gate, so more tracks die over the drive than
# it has epochs — on average every epoch kills a track and gives birth to a new one — and the UE
# is pulled by whatever passes. On the ML route the same design (with the VUE curvature) keeps
# its tracks: after the births of the first epoch, fewer than one track dies in three epochs,
# since its measurements are well inside the noise the design assumes (section 3); an epoch the
# ML fit flags carries no measurement, and the tracker predicts through it. The LoS test of
# eq. 61 compares $\hat d$ with $\hat\kappa$; $\hat d$ carries the clock bias (a 50 ns
# standard deviation, read from section 4.2 of the paper as in notebook 03: 15 m of distance),
# so it fires only when the bias is small — but with the LoS tracked the tracker no longer needs it.

# %% [markdown] tags=["explorer"]
# ## 7. Epoch by epoch
#
# Slide through the drive. The cross-section at the UE's $x$ shows every track (they share $x$):
# prior positions with 2-σ ellipses (grey; dotted and crossed red when the track dies this epoch),
# where each measured arrival ray crosses the plane (orange diamonds), the associations (orange
# lines), births (green stars), posteriors (dots) and the true UE/VUEs (green asterisks).

# %% tags=["explorer"]
explorer = epoch_explorer(drive_ml, ev_ml, k=k)
explorer

# %% [markdown]
# ## 8. Trajectories: JAVELIN vs TeNFiLoc (Fig. 6)
#
# TeNFiLoc is a snapshot method: in LoS it takes the tuple $(\hat\phi, \hat\psi, \hat\kappa)$ of the
# LoS path (or $\hat d$, biased by the clock, when there is no curvature); without LoS, eq. 69.
# The paper prints eq. 69 as a weighted sum of residuals $\lVert\mathbf p_u -
# \hat{\mathbf p}_{s,\ell}\rVert - \hat d_\ell + \hat\kappa_\ell$. With positive weights that
# sum is convex and has a minimum — the weighted geometric median of the reflector estimates —
# but $\hat d_\ell$ and $\hat\kappa_\ell$ enter it only as constants, so its minimum ignores the
# measurements. The paper leaves eq. 69 out of its results (section 4.3: it needs $L > 3$ and
# perfect synchronisation), so its tables compare TeNFiLoc-L only. Ours, for the epochs in which
# the LoS path goes unfound, minimises the sum of *squared* residuals, optionally with the clock
# bias as a fourth unknown. The paper does not
# say what to do with an implausible curvature; ours uses a LoS curvature only when it is within
# the clock-bias support of the delay ($|\hat d - \hat\kappa| \le c\,b_{\max}$, 30 m with the
# paper's $b_{\max}$ = 100 ns) and within 200 m of the BS, else the delay distance: a wild
# curvature taken as is would put the fix far outside the tunnel. On the ML route TeNFiLoc-L is
# a fair baseline: its LoS tuple is as good as the extraction.

# %%
tf_rule = TeNFiLoc.for_drive(drive)
print(f"TeNFiLoc: c b_max = {tf_rule.bias_limit:.1f} m, largest range {tf_rule.max_range:g} m")
tf_est, tf_ok = ex.tenfiloc_track(drive)
tf_ml, _ = ex.tenfiloc_track(drive_ml)
fig6a = trajectories_figure(
    drive.truth,
    {
        # the ML-route pair first, as in the slalom figure below: a method keeps its marker
        "JAVELIN (paper design + VUE κ, ML route)": ev_ml.estimates,
        "TeNFiLoc (ML route)": tf_ml,
        "JAVELIN (paper design, eq. 51, paper route)": ev_paper.estimates,
        "TeNFiLoc (paper route)": tf_est,
    },
    base_station=drive.base_station,
    title="straight, L",
)
fig6a.update_xaxes(range=[0, 50])

# %%
fig6b = trajectories_figure(
    sl_ml.truth,
    {
        "JAVELIN (paper design + VUE κ, ML route)": ex.evaluate(
            sl_ml, designs.paper_vue()
        ).estimates,
        "TeNFiLoc (ML route)": ex.tenfiloc_track(sl_ml)[0],
    },
    base_station=sl_ml.base_station,
    title="slalom, L",
)
fig6b.update_xaxes(range=[0, 50])

# %% [markdown]
# ## 9. Error CDFs (Fig. 7), and the baseline the paper does not draw
#
# One drive shows a path; how often a method is how far off needs many epochs. The 2-D error
# $\|\hat{\mathbf p}_{xy} - \mathbf p_{xy}\|$ of every epoch of the drives of section 3, per
# condition: JAVELIN with the paper's design (VUE curvature) on the ML route, TeNFiLoc-L on the ML
# route. (Notebook 04b draws the same figure over the many more runs of its Tables 1–2, for both
# trajectories, on a held-out seed.)
#
# A tracker also has to beat what it would do **without the radio**: *dead reckoning*, the same
# JAVELIN from the same start on the same V2X speed and heading messages, every radio measurement
# dropped (`simulation.without_radio`: it only predicts, eq. 62). The paper shows no such curve.
# The radio's gain is dead reckoning's error over JAVELIN's (above 1 the radio helps).


# %%
def errors(drives, cfg=None, method="JAVELIN"):
    """2-D position errors of every epoch of ``drives``, pooled (``cfg``: the paper's design
    with the VUE curvature unless given)."""
    cfg = designs.paper_vue() if cfg is None else cfg
    return np.concatenate(
        [
            position_errors(ex.evaluate(d, cfg, method=method).estimates[:, :2], d.truth[:, :2])
            for d in drives
        ]
    )


cdfs = {f"JAVELIN-{c}": errors(straight_ml[c]) for c in straight_ml}
cdfs["TeNFiLoc-L"] = errors(straight_ml["L"], method="TeNFiLoc")
cdfs["dead reckoning"] = errors([ex.without_radio(d) for d in straight_ml["L"]])
fig7 = cdf_figure(
    cdfs,
    title=f"2-D error CDF, straight, ML route, JAVELIN = paper design + VUE κ, {runs} run(s)",
)
fig7.update_xaxes(type="log", range=[-2, 2])

# %%
within_1m = {n: float(np.mean(e <= 1.0)) for n, e in cdfs.items()}
p90 = {n: float(np.percentile(e, 90)) for n, e in cdfs.items()}
print("share of epochs within 1 m:          ", {n: round(v, 3) for n, v in within_1m.items()})
print("90th percentile of the 2-D error [m]:", {n: round(v, 3) for n, v in p90.items()})
rmse = {n: float(np.sqrt(np.mean(e**2))) for n, e in cdfs.items()}
radio_gain = rmse["dead reckoning"] / rmse["JAVELIN-L"]
print(f"2-D RMSE: JAVELIN-L {rmse['JAVELIN-L']:.3f} m, dead reckoning {rmse['dead reckoning']:.3f}"
      f" m: the radio's gain {radio_gain:.1f}x")  # fmt: skip

# %% [markdown]
# Read a CDF left to right: the higher a curve at a given error, the larger the share of epochs
# within it (the shares within 1 m and the 90th percentiles are printed under the figure).
# Blocking the LoS hardly hurts on the ML route: JAVELIN-N's 90th percentile stays within 1.5
# times JAVELIN-L's, since the ceiling and road bounces, measured as well as the LoS, locate the
# UE through their VUEs. Where the LoS comes and goes (N@0.5, full mode only) the tail is heavier
# than with the LoS always blocked: every return of the LoS is a track to be born again.
# TeNFiLoc-L fixes most epochs to within a metre — in LoS it reads the UE off the LoS path, as
# well as the extraction measures it — but has a long tail, its 90th percentile many times
# JAVELIN-L's: a snapshot fix has no memory, so every epoch whose LoS curvature is implausible
# falls back to the clock-biased delay, metres off. That tail is what a tracker buys. (Quick
# mode's six-epoch drives are few epochs to read a tail from.)
#
# **Against dead reckoning** (the last curve): over the whole 40 m drives of full mode JAVELIN-L's
# 2-D RMSE is more than 1.2 times smaller than dead reckoning's (the radio's gain, printed above) —
# a real gain, but a modest one, because the V2X errors drawn here are white (0.2 m/s, 1°): dead
# reckoning's error grows only like $\sqrt{t}$ and the drive lasts three seconds. A wheel-speed
# scale error or a drifting gyro bias would make it grow with the distance driven
# (`docs/results/baselines.md`). In quick mode's six-epoch drives, which start at the true position,
# dead reckoning has had no time to drift while JAVELIN is still settling from its 1 m start, so
# there the gain is below 1: a baseline has to be read on drives long enough to let it drift.
#
# ## Exercises
#
# 1. Rerun section 5 on the paper's route with `designs.paper().with_(sigma_kappa=50.0)`. Does honest
#    curvature noise alone rescue the paper's design there? What else is needed?
# 2. Set `max_misses=3` in our design for the paper's route (`designs.ours()`). Do tracks live longer?
#    Does the RMSE change?
# 3. Run `designs.paper()` (eq. 51) and `designs.paper_vue()` on `drive_ml` and on `drive`. Why does the VUE
#    curvature fit an exact (non-SR-NF) channel better, and why does it matter on one route only?
# 4. Take one epoch through the paper's route, `ep = SignalRoute.from_scenario(
#    "italiano2026-straight").epoch(5, np.random.default_rng(1), refine="joint")`, and run
#    `resolve_coherent` (`tunnelkit.extraction.coherent`) on it with `max_sources=1`, 2 and 3
#    (the other arguments: `ep.snapshot.H, ep.estimates, ep.array.local` and the route's
#    `config.fc, config.tone_spacing, config.symbol_period`). Match the results to the true paths
#    with `match_paths` (`tunnelkit.evaluation`). What does each extra source buy?
#
# The solutions are the collapsed cells below, and Run All does not run them. Once you have
# tried an exercise, click the "Run solution" button under its solution (or run
# `tk.solution("04.2")` in a cell, for exercise 2): the solution runs on a copy of the
# notebook's variables, so it changes none of yours, and shows what it prints. A cell's blue
# bar shows its code. On the static site the solutions have already run: open one, then its
# "Show the solution's output". What to read in them follows.

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04.1
# Solution 1: the paper's design on the paper's route, one change, then a second
steps = {
    "paper (section 4.2)": designs.paper(),
    "sigma_kappa = 50 m": designs.paper().with_(sigma_kappa=50.0),
    "sigma_kappa = 50 m + Doppler test": designs.paper(sigma_kappa=50.0).with_prefilter(
        tk.tracking.javelin.DopplerClutter(1.0)
    ),
}
sol1 = {name: ex.evaluate(drive, cfg).metrics["rmse_2d_m"] for name, cfg in steps.items()}
for name, v in sol1.items():
    print(f"{name:34s} 2-D RMSE {v:6.2f} m")
# both changes needed: the lowest error only with the Doppler test as well
last = sol1["sigma_kappa = 50 m + Doppler test"]
assert last < min(sol1["paper (section 4.2)"], sol1["sigma_kappa = 50 m"]), sol1

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04.2
# Solution 2: tracks that survive up to three missed epochs
sol2 = {}
for zeta in (designs.ours().config.max_misses, 3):
    ev_z = ex.evaluate(drive, designs.ours().with_(max_misses=zeta), keep_reports=True)
    sol2[zeta] = ev_z.metrics["rmse_2d_m"]
    reps = [r for r in ev_z.run.reports if r.manage]
    births = sum(len(r.manage.born) for r in reps)
    print(
        f"max_misses = {zeta}: births {births:3d}, mean tracked states "
        f"{np.mean(ev_z.run.n_tracks):4.1f}, 2-D RMSE {ev_z.metrics['rmse_2d_m']:.2f} m"
    )
assert abs(sol2[3] - sol2[designs.ours().config.max_misses]) < 0.25 * max(sol2.values()), sol2

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04.3
# Solution 3: the curvature model on both routes
sol3 = {}
for route_name, d in (("ML route", drive_ml), ("paper route", drive)):
    sol3[route_name] = [
        ex.evaluate(d, c).metrics["rmse_2d_m"] for c in (designs.paper(), designs.paper_vue())
    ]
    print(
        f"{route_name:11s} eq. 51: {sol3[route_name][0]:6.2f} m   VUE curvature: "
        f"{sol3[route_name][1]:6.2f} m"
    )
# the VUE curvature pays on the ML route; on the paper's route both are metres off
assert sol3["ML route"][1] < sol3["ML route"][0], sol3
assert min(sol3["paper route"]) > 1.0, sol3

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04.4
# Solution 4: split merged CPD components into 1, 2 or 3 sources
route = SignalRoute.from_scenario("italiano2026-straight")
ep = route.epoch(5, np.random.default_rng(1), refine="joint")
cfg = route.config
labels = ["LoS" if p.kind == "los" else p.surface for p in ep.paths]
sol4 = {}
for n_src in (1, 2, 3):
    est = resolve_coherent(ep.snapshot.H, ep.estimates, ep.array, cfg, max_sources=n_src)
    meas = measurements_from_estimates(est, ep.array)
    idx = match_paths(meas.d, meas.direction, ep.paths, clock_bias=ep.snapshot.clock_bias)
    off = {
        labels[t]: np.degrees(np.arccos(np.clip(meas.direction[j] @ ep.paths[t].direction, -1, 1)))
        for j, t in enumerate(idx)
        if t >= 0
    }
    missing = [lab for lab in labels if lab not in off]
    print(
        f"max_sources={n_src}: angle error [deg]", {k: round(float(v), 3) for k, v in off.items()}
    )
    print(f"    true paths missed: {missing}; estimates matching no path: {int(np.sum(idx < 0))}")
    sol4[n_src] = (off, missing)
# one source: the LoS degrees off, a path without an estimate; two: all found, the LoS within
# about half a degree; three: the same paths, the LoS no better
(off1, miss1), (off2, miss2), (off3, miss3) = sol4[1], sol4[2], sol4[3]
assert off1["LoS"] > 2.0 and miss1 and not miss2 and 0.2 < off2["LoS"] < 0.7, sol4
assert not miss3 and set(off3) == set(off2) and abs(off3["LoS"] - off2["LoS"]) < 0.1, sol4

# %% [markdown]
# <details><summary>What to read in the solutions</summary>
#
# 1. Honest curvature noise alone does not rescue the paper's design on the paper's route: the
#    true pairs pass the gate again, but so do the spurious CPD components (a radial speed no
#    static reflector can have), so the tracker stays well off the ML route (the second
#    line). The Doppler test removes those components and lowers the error further (the third
#    line): both changes are needed, and on one drive neither brings the paper's route to the ML
#    route's centimetres. Notebook 04b measures each step of that path over 20 runs.
# 2. With $\zeta = 3$ a track survives missed epochs, so it need not be born again; whether that
#    happens on this drive the births and tracked states of the output say. The RMSE hardly
#    moves.
# 3. The exact channel's wavefront is centred on the VUE, so its curvature radius is the VUE
#    distance, not eq. 51's reflector distance (for the ceiling bounce, the two numbers printed
#    in section 3). The ML route fits each path as a point source and $\hat\kappa$ estimates
#    exactly that distance: with eq. 51 and $\sigma_\kappa = 1.5$ m every reflection fails the
#    gate by metres, tracks die and are reborn and the estimate runs off; with the VUE model the
#    same parameters track far better (the first line of the output). On the paper's route the
#    merged components' curvature belongs to no single path, so neither model describes it and
#    both leave the tracker metres off; the VUE model may even do worse there (the second line).
#    A better model only pays on measurements that follow it.
# 4. With `max_sources=1` nothing is split: the LoS estimate still carries the ceiling bounce
#    (degrees off) and some true paths have no estimate of their own. With 2 the pair LoS +
#    ceiling is split and every path is found, the LoS within about half a degree. A third source
#    adds nothing in this epoch: no component holds three paths here.
#
# </details>

# %% [markdown]
# ## Checks

# %%
# section 1: the setup the prose quotes, from the paper (sections 4.1-4.2) and from the preset
assert tunnel_size == [100.0, 10.0, 5.0] and anchor_z == 4.8 and n_rrm_plates == 4
assert array_shapes == [[10, 10], [10, 10]]
assert (srs.fc, srs.bandwidth, srs.n_symbols) == (5.9e9, 100e6, 12), srs
assert abs(speed_kmh - 50.0) < 0.1 and (traj["x_start"], traj["x_end"]) == (45.0, 5.0), traj
assert traj["period"] == 0.1 and abs(drive.dt - traj["period"]) < 1e-9, drive.dt
# section 2: the paper's route reads the curvature more than ten metres off (its LoS direction
# degrees off: section 3)
assert np.median(kappa_err_paper) > 10.0, np.median(kappa_err_paper)
assert jac_err < 1e-5, jac_err
# section 3: every path less than 2 m behind the LoS (c/B = 3 m), the ceiling bounce
# centimetres, the road bounce tenths of a metre; radial speeds a few m/s apart (119 m/s)
assert max(max(v) for v in excess.values()) < 2.0 and abs(res_range - 3.0) < 0.01, excess
assert max(rate_gap) < 5.0 and abs(res_speed - 119.0) < 1.0, (max(rate_gap), res_speed)
assert np.median(excess["ceiling"]) < 0.1 < np.median(excess["road"]) < 1.0
assert abs(gate.threshold(3) - 11.345) < 1e-3
assert np.median(vue_err["mirror"]) < np.median(vue_err["random_walk"])
# section 4: the held step (eq. 62) about a third of a metre off on the noise-free slalom, the
# midpoint a few centimetres
assert 0.25 < step_rms["held (eq. 62)"] < 0.4 and step_rms["midpoint"] < 0.05, step_rms
# section 4: most of the mirrored VUEs' one-step error is the UE's held step
assert np.median(vue_err["mirror, midpoint step"]) < 0.5 * np.median(vue_err["mirror"]), vue_err
for ev in (ev_paper, ev_ml):
    assert np.all(np.isfinite(ev.estimates))
    assert all(np.all(np.linalg.eigvalsh(c) > -1e-9) for c in ev.run.covariances)
# section 1's drive is the first drive of section 3 (run 0 of seed 0, same child seed)
assert np.array_equal(straight_ml["L"][0].truth, drive_ml.truth)
assert los_rms["ML"] < 0.05 < los_rms["paper"]  # the ML route: the LoS direction to 0.001 deg
assert los_median["paper"] > 1.0, los_median  # the paper's route: degrees off
err_all = {r[0]: r for r in erows}["all"]
assert err_all[2] < 1.0 and err_all[5] < 0.1  # RMS over every path, gross errors included
# section 3: eq. 51 and the VUE distance of the ceiling bounce differ by an order of magnitude;
# against the paper's sigmas (2 deg, 2 deg, 1.5 m, 1.5 m) the ML route's RMS errors are two to
# four orders of magnitude smaller in the angles and the TDoA, a factor of several in the
# curvature (decimetres); our ML design assumes wider sigmas than measured
assert vue_ceil > 5 * kappa51_ceil, (kappa51_ceil, vue_ceil)
assert np.allclose(sig["the paper (section 4.2)"], [2.0, 2.0, 1.5, 1.5])
ratio_paper = sig["the paper (section 4.2)"] / sig["measured here"]
assert np.all((ratio_paper[[0, 1, 3]] > 1e2) & (ratio_paper[[0, 1, 3]] < 1e4)), ratio_paper
assert 2.0 < ratio_paper[2] < 20.0 and 0.05 < err_all[4] < 1.0, (ratio_paper, err_all)
assert np.all(sig["our ML design assumes"] > sig["measured here"]), sig
# section 6: the paper's route kills (and gives birth to) more tracks than the drive has
# epochs; the ML route fewer than one death in three epochs
assert churn["paper route"]["deaths"] > churn["paper route"]["epochs"], churn
assert churn["paper route"]["births"] > churn["paper route"]["epochs"], churn
assert churn["ML route"]["deaths"] < churn["ML route"]["epochs"] / 3, churn
# section 8: TeNFiLoc's plausibility rule, c b_max = 30 m and 200 m
assert abs(tf_rule.bias_limit - 30.0) < 0.1 and tf_rule.max_range == 200.0, tf_rule
# section 9 (Fig. 7): blocking the LoS hardly hurts (90th percentile within 1.5 times LoS's);
# N@0.5 has the heavier tail; TeNFiLoc-L within a metre in most epochs, its tail many times
# JAVELIN's
assert p90["JAVELIN-N"] < 1.5 * p90["JAVELIN-L"], p90
if "JAVELIN-N@0.5" in p90:
    assert p90["JAVELIN-N@0.5"] > p90["JAVELIN-N"], p90
assert within_1m["TeNFiLoc-L"] > 0.5 and p90["TeNFiLoc-L"] > 5 * p90["JAVELIN-L"], p90
# section 9: the radio's gain over dead reckoning, above 1.2 over the full drives, below 1 over
# quick mode's six epochs from the true start
assert (radio_gain < 1.0) if tk.quick_mode() else (radio_gain > 1.2), radio_gain
# the exercises' readings are asserted in their solutions (run in CI with TUNNELKIT_SOLUTIONS=1)
print("all checks passed")
