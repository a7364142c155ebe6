# %% [markdown]
# # 04 · JAVELIN: tracking a vehicle and its virtual UEs with one base station
#
# *Italiano, Brambilla & Nicoli (2026), "In-Tunnel Single-Anchor Localization Exploiting Near-Field
# and Radio-Reflective Road Markings", [arXiv:2604.04217](https://arxiv.org/abs/2604.04217v1),
# sections 3.2–3.5 (eq. 43–69, Algorithms 1–4) and 4.
# All references: `REFERENCES.md` at the top of the repository.*
#
# **What you will learn**
#
# - the variable-dimension state of eq. 43 (the UE plus one $(y, z)$ pair per virtual UE) and the
#   measurement model of eq. 44–52, with its Jacobian checked against finite differences;
# - the prediction of eq. 62–63 (V2X speed/heading for the UE, a random walk for VUEs) and why a
#   wall-fixed VUE should rather *mirror* the UE's motion;
# - the chi-square gate (eq. 56–59), nearest-neighbour association (Algorithm 2), births, deaths,
#   the LoS test (eq. 60–61) and the Doppler test (Algorithm 3), epoch by epoch with a slider;
# - the Joseph-form EKF update (eq. 64–68) and the whole loop of Algorithm 4 on measurements that
#   come out of the channel tensor and the CPD extraction of notebook 03, not out of a noise
#   generator;
# - why the CPD merges paths that arrive together, and how the array separates them again (ours,
#   beyond the paper);
# - Tables 1–2 and Figs. 6–7 of the paper beside ours, the road-marking ablation, and a measured
#   ablation of our changes to the paper's design.

# %%
import numpy as np
from IPython.display import display

import tunnelkit as tk
from tunnelkit.crlb import numeric_jacobian
from tunnelkit.metrics import position_errors
from tunnelkit.plots import (
    cdf_figure,
    javelin_table_figure,
    tracks_count_figure,
    trajectories_figure,
)
from tunnelkit.reproduce.javelin_tables import collect_routes, table_rows
from tunnelkit.tracking.javelin import experiment as ex
from tunnelkit.tracking.javelin import measurement_model
from tunnelkit.widgets import epoch_explorer

tk.setup_notebook()

# %% [markdown]
# ## 1. Drives through the signal route
#
# Section 4 of the paper: a straight semicircular tunnel (100 m × 10 m × 5 m), one base station
# 4.8 m high in the middle with two 10 × 10 URAs looking both ways, four metallic road markings
# (RRMs), a vehicle driving towards the BS at 50 km/h, one SRS slot every 0.1 s. Every epoch goes
# through the signal route of notebook 03: image-method paths → the tensor of eq. 1 with noise and
# a clock bias → CPD → Algorithm 1. Four conditions: **L** (LoS), **N@0.5** (LoS blocked with
# probability 0.5 per epoch), **N** (always blocked) and **NoRRMs** (no road markings, LoS
# blocked — our reading of the paper). Every drive is measured twice from the *same* tensors: with
# the paper's extraction, and with ours, which separates paths the CPD merged (section 3). This
# is the expensive cell (quick mode: one shortened drive each).

# %%
runs = tk.mc_count(20, 1)
n_epochs = 12 if tk.quick_mode() else None  # quick mode: the first 12 epochs (1.2 s) of each drive
straight_conditions = ("L", "N@0.5", "N", "NoRRMs")
slalom_conditions = ("L",) if tk.quick_mode() else ("L", "N@0.5", "N")
routes = {
    scenario: collect_routes(scenario, conds, runs, seed, progress=True, n_epochs=n_epochs)
    for scenario, conds, seed in (
        ("italiano2026-straight", straight_conditions, 0),
        ("italiano2026-slalom", slalom_conditions, 1),
    )
}
straight, straight_sep = (routes["italiano2026-straight"][e] for e in ("paper", "separated"))
slalom, slalom_sep = (routes["italiano2026-slalom"][e] for e in ("paper", "separated"))
drive, drive_sep = straight["L"][0], straight_sep["L"][0]
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

# %%
k = 8
src = drive.sources[k]  # true UE (LoS first) and VUEs of epoch k
s_true = np.concatenate([src[0], src[1:, 1:].ravel()])
h, H = measurement_model(s_true, drive.base_station)
H_num = numeric_jacobian(lambda s: measurement_model(s, drive.base_station)[0], s_true)
jac_err = float(np.abs(H - H_num).max())
print("state dimension D =", s_true.size, " measurements K =", h.size, " max |H - H_fd| =", jac_err)

# %% [markdown]
# What does the extraction deliver against this model? Each extracted path was matched to its
# true path (Hungarian on delay and direction). The table lists the error in azimuth and elevation
# and the extracted curvature beside eq. 51's value and the VUE distance.


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
# Two things stand out and drive everything below. (i) The LoS path and the ceiling reflection
# arrive almost together (the BS hangs 0.2 m under the ceiling): the CPD mixes them, so their
# angles are off by degrees and their curvature is meaningless. (ii) With a 23 cm aperture the
# wavefront curvature at 10–45 m is barely measurable: $\hat\kappa$ is far from both eq. 51 and
# the VUE distance. The paper assumes $\sigma_\kappa = 1.5$ m. The Doppler, on the other hand, is
# excellent (cm/s), and a spurious CPD component shows itself by a radial speed no static
# reflector can produce.
#
# ## 3. Paths the CPD merges, and how the array separates them (ours)
#
# In this tunnel every path of an epoch arrives within about a metre of the LoS (the 100 MHz SRS
# resolves 3 m) and within a fraction of a metre per second in Doppler (12 symbols resolve about
# 119 m/s, $c/(f_c N_t T_0)$, computed in notebook 03). Take two paths with the same delay and Doppler: their frequency and time factors are
# the same vectors $\mathbf b_f$, $\mathbf b_t$, and in the CPD of eq. 3/11
#
# $$\alpha_1\,\mathbf s(\mathbf q_1)\circ\mathbf b_f\circ\mathbf b_t + \alpha_2\,\mathbf s(\mathbf q_2)\circ\mathbf b_f\circ\mathbf b_t
# = \big(\alpha_1\mathbf s(\mathbf q_1) + \alpha_2\mathbf s(\mathbf q_2)\big)\circ\mathbf b_f\circ\mathbf b_t$$
#
# is **one** rank-one term. The CPD returns one component whose spatial factor is a mixture, and
# eq. 16–24 read one biased direction from it; the spare component of the rank-$L$ fit goes to
# noise. The ceiling bounce (0.2 m above the BS, centimetres longer than the LoS) is the worst
# case, and the road bounce is not far behind.
#
# The array still tells them apart: the steering vector of a point source $\mathbf q$ (eq. 1–2,
# local frame) is known, $[\mathbf s(\mathbf q)]_m = e^{jk_0(\|\mathbf q - \mathbf p_m\| - \|\mathbf q\|)}$,
# so each component's spatial factor is fitted with one, two or three sources by nonlinear least
# squares (a source is added at the beam-scan peak of the residual while the residual stays above
# $10^{-3}$ of the factor's energy; a split must halve it). The sources of all components are
# pooled, duplicates dropped, the $L$ strongest kept, and every path gets its own delay and
# Doppler from the tensor beamformed onto the separated steering matrix, $\mathbf S^+\mathbf H_{(1)}$
# (eq. 13–15 on each row). `tunnelkit.extraction.coherent.resolve_coherent` does this; the paper does not.
# The same epoch, same tensor:

# %%
javelin_table_figure(cols, model_rows(drive_sep, k), title=f"epoch {k}: separated vs model")

# %% [markdown]
# Over all straight LoS drives, per kind of path: how many were found, and how far off their
# direction is.

# %%
los_rms = {}
for name, d in (("paper", straight["L"]), ("separated", straight_sep["L"])):
    pcols, prows = ex.path_errors(d)
    los_rms[name] = {r[0]: r[3] for r in prows}["los"]
    display(javelin_table_figure(pcols, prows, title=f"straight, L: {name} extraction"))

# %% [markdown]
# The curvature does not improve much: separating the sources fixes their directions, but a 23 cm
# aperture still measures $\kappa$ poorly beyond ~10 m.
#
# ## 4. Prediction (eq. 62–63)
#
# The UE moves by the V2X speed $\nu$ and heading $\theta$:
# $\mathbf p_{u,k} = \mathbf p_{u,k-1} + T\nu[\cos\theta, \sin\theta, 0]^\mathsf T$, with
# $\mathbf Q_u = T^2\mathbf G\,\mathrm{diag}(\sigma_\nu^2, \sigma_\theta^2)\mathbf G^\mathsf T$ and
# $\mathbf G = \partial\Delta\mathbf p/\partial(\nu, \theta)$. The paper lets every VUE follow a
# random walk. But a VUE of a surface along the tunnel *is* the UE mirrored in it, so it moves by
# the mirrored displacement $\Delta_v = \Delta_u - 2(\mathbf n\cdot\Delta_u)\mathbf n$. How far off is each
# prediction from the true VUEs one epoch later, on the slalom?

# %%
sl = slalom["L"][0]
vue_err = {mode: ex.vue_prediction_errors(sl, mode) for mode in ("random_walk", "mirror")}
for mode, e in vue_err.items():
    print(
        f"{mode:12s} median {np.median(e) * 100:5.1f} cm   90 % {np.percentile(e, 90) * 100:5.1f} cm"
    )

# %% [markdown]
# The mirror model is exact for planar surfaces along the tunnel; what is left is the ceiling's
# facets (a curved surface moves its VUE differently) and paths that switch surface.
#
# ## 5. Gate and association (eq. 55–59, Algorithm 2)
#
# For every pair (track $i$, path $j$) the three rows $(\phi_j, \psi_j, \kappa_j)$ of the Jacobian
# give $\mathbf S_{ij} = \hat{\mathbf H}_\hbar\hat{\mathbf P}\hat{\mathbf H}_\hbar^\mathsf T + \mathbf R_\hbar$
# (eq. 56), the innovation $\mathbf y_{ij}$ (eq. 57) and $\eta^2_{ij} = \mathbf y_{ij}^\mathsf T\mathbf S_{ij}^{-1}\mathbf y_{ij}$
# (eq. 58). A pair is feasible if $\eta^2_{ij} < \chi^2_3(p)$ (eq. 59); the nearest feasible pair
# is taken first, then the next (greedy nearest neighbour). A far-field path (no curvature) is
# gated on its two angles with $\chi^2_2(p)$. We run the tracker as the paper does (its design, its
# extraction) and as we do (our design of section 12, on the separated measurements of section 3)
# on the same drive, keeping every step's report.

# %%
gate = tk.tracking.javelin.ChiSquareGate(0.99)
print(f"chi2_3(0.99) = {gate.threshold(3):.3f}, chi2_2(0.99) = {gate.threshold(2):.3f}")
ev_paper = ex.evaluate(drive, ex.PAPER, keep_reports=True)
ev_ours = ex.evaluate(drive_sep, ex.OURS_SEPARATED, keep_reports=True)
rep = ev_ours.run.reports[k]
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
for name, ev in (("paper", ev_paper), ("ours", ev_ours)):
    reps = ev.run.reports
    births = sum(len(r.manage.born) for r in reps if r.manage)
    deaths = sum(len(r.manage.dead) for r in reps if r.manage)
    los = sum(bool(r.manage and r.manage.los) for r in reps)
    print(
        f"{name:13s} births {births:3d}  deaths {deaths:3d}  epochs declared LoS {los}/{len(reps)}"
        f"  2-D RMSE {ev.metrics['rmse_2d_m']:.2f} m"
    )
tracks_count_figure(
    drive.t, ev_ours.run.n_tracks, drive.los, title="tracked states per epoch (ours)"
)

# %% [markdown]
# The paper's design churns: with junk curvatures and $\sigma_\kappa = 1.5$ m the true pairs fail
# the gate, so tracks die and are reborn nearly every epoch and the UE is pulled by whatever
# passes. Ours keeps its tracks: every path is found in (nearly) every epoch. The LoS test of eq. 61 rarely fires because $\hat d$ carries a clock bias of tens of
# nanoseconds (metres) and $\hat\kappa$ is unreliable.
#
# ## 7. Epoch by epoch
#
# Slide through the drive. The cross-section at the UE's $x$ shows every track (they share $x$):
# prior positions with 2-σ ellipses (grey; dotted and crossed red when the track dies this epoch),
# where each measured arrival ray crosses the plane (orange diamonds), the associations (orange
# lines), births (green stars), posteriors (dots) and the true UE/VUEs (green asterisks).

# %%
explorer = epoch_explorer(drive_sep, ev_ours, k=k)
explorer

# %% [markdown]
# ## 8. Trajectories: JAVELIN vs TeNFiLoc (Fig. 6)
#
# TeNFiLoc is a snapshot method: in LoS it takes the tuple $(\hat\phi, \hat\psi, \hat\kappa)$ of the
# LoS path (or $\hat d$, biased by the clock, when there is no curvature); without LoS it minimises
# eq. 69. The paper prints eq. 69 as a plain sum of residuals, which has no minimum; we minimise
# the sum of *squares*, optionally with the clock bias as a fourth unknown.

# %%
tf_est, tf_ok = ex.tenfiloc_track(drive)
fig6a = trajectories_figure(
    drive.truth,
    {
        "JAVELIN (ours)": ev_ours.estimates,
        "JAVELIN (paper)": ev_paper.estimates,
        "TeNFiLoc": tf_est,
    },
    base_station=drive.base_station,
    title="straight, L",
)
fig6a.update_xaxes(range=[0, 50])

# %%
sl_ours, sl_tf = ex.evaluate(slalom_sep["L"][0], ex.OURS_SEPARATED), ex.tenfiloc_track(sl)[0]
fig6b = trajectories_figure(
    sl.truth,
    {"JAVELIN (ours)": sl_ours.estimates, "TeNFiLoc": sl_tf},
    base_station=sl.base_station,
    title="slalom, L",
)
fig6b.update_xaxes(range=[0, 50])

# %% [markdown]
# ## 9. Error CDFs (Fig. 7)
#
# The 2-D error $\|\hat{\mathbf p}_{xy} - \mathbf p_{xy}\|$ of every epoch of every run, per
# configuration: JAVELIN ours (design and separated extraction), TeNFiLoc as in the paper.


# %%
def errors(drives, cfg=ex.OURS_SEPARATED):
    return np.concatenate(
        [position_errors(ex.evaluate(d, cfg).estimates[:, :2], d.truth[:, :2]) for d in drives]
    )


cdfs = {f"JAVELIN-{c}": errors(straight_sep[c]) for c in straight_sep}
cdfs["TeNFiLoc-L"] = np.concatenate(
    [position_errors(ex.tenfiloc_track(d)[0][:, :2], d.truth[:, :2]) for d in straight["L"]]
)
fig7 = cdf_figure(cdfs, title="2-D error CDF, straight")
fig7.update_xaxes(type="log", range=[-2, 2])

# %% [markdown]
# ## 10. Tables 1–2 beside the paper
#
# Mean over runs of 2-D RMSE, 2-D MAE and Y-MAE, for JAVELIN with the paper's design (section 4.2
# parameters) and with ours, and for TeNFiLoc-L; the `extraction` column says which measurement
# route fed them (`paper`: the CPD as published; `separated`: section 3, same tensors). The
# paper's numbers are in the `paper_` columns. The same computation runs from the command line:
# `tunnelkit reproduce javelin-table1` / `javelin-table2` (20 runs by default).

# %%
cols1, rows1 = table_rows(straight, "italiano2026_table1", straight_sep)
javelin_table_figure(cols1, rows1, title=f"Table 1 (straight), {runs} run(s) per condition")

# %%
cols2, rows2 = table_rows(slalom, "italiano2026_table2", slalom_sep)
javelin_table_figure(cols2, rows2, title=f"Table 2 (slalom), {runs} run(s) per condition")

# %% [markdown]
# ## 11. The road-marking ablation
#
# Removing the four RRMs removes up to four paths in the stretch $10 \le x \le 30$ m. Compare
# JAVELIN-N (LoS blocked, RRMs present) with JAVELIN-NoRRMs (LoS blocked, no RRMs), and count the
# paths each condition delivers.

# %%
rmse = {tuple(r[:3]): r[3] for r in rows1}
for cond in ("N", "NoRRMs"):
    paths = np.mean(
        [np.mean([0 if e is None else len(e) for e in d.epochs]) for d in straight_sep[cond]]
    )
    print(
        f"JAVELIN-{cond:7s} paths/epoch {paths:4.2f}   2-D RMSE paper "
        f"{rmse[(f'JAVELIN-{cond}', 'paper', 'paper')]:6.2f} m, "
        f"ours {rmse[(f'JAVELIN-{cond}', 'ours', 'separated')]:5.2f} m"
    )

# %% [markdown]
# ## 12. Beyond the paper, measured
#
# Our design changes the paper's one step at a time: (1) Doppler clutter rejection — a static
# reflector's path cannot have a radial speed above the vehicle's speed, so faster CPD components
# are dropped before association; (2) measurement noise calibrated on what the extraction really
# delivers (angles ~5°, curvature nearly uninformative, $\sigma_\kappa = 50$ m); (3) global nearest
# neighbour (scipy's `linear_sum_assignment`) instead of greedy; (4) VUEs moved with the mirrored UE
# displacement (section 4); (5) a newborn track is not used to update in its birth epoch (its
# position came from the very angles it would update with); (6) the measurement route of section
# 3, coherent paths separated by the array; (7) on that route, each path's curvature modelled as
# the distance to its VUE (`kappa_model="vue"`): the channel's wavefront is centred on the image
# source, and the separated extraction fits each path as a point source, so that is what
# $\hat\kappa$ measures. Eq. 51's reflection-point distance (SR-NF) is kept for the CPD route,
# whose merged components carry no usable curvature (there the VUE model is worse; exercise 3).
# Settings (1)–(5) were tuned on the paper's extraction and (7) chosen, for the physical reason
# above, on other seeds (seed 7) than these. Mean 2-D RMSE [m]:

# %%
abl_cols, abl_rows = ex.ablation(straight, separated=straight_sep)
javelin_table_figure(abl_cols, abl_rows, title="ablation on the straight drives: 2-D RMSE [m]")

# %% [markdown]
# ## 13. Where our tunnel differs from the paper's
#
# - **Propagation.** The paper used a ray tracer on a Blender model with a single bounce; we use
#   the image method on 12 planar facets plus the road and four finite RRM plates. Both are
#   single-bounce, but our facets give fewer, cleaner wall paths, and the RRMs only exist for
#   $10 \le x \le 30$ m.
# - **The LoS/ceiling pair.** With the BS 0.2 m under the ceiling, the ceiling reflection is
#   centimetres behind the LoS in delay and shares its Doppler; the road bounce is a few tenths of
#   a metre behind. The CPD of eq. 11 cannot separate such paths (section 3); on the paper's route
#   our design stops at about 0.8 m (straight, L). The paper does not mention the problem, and its
#   ray tracer may have produced weaker or better separated ceiling paths. With the paths
#   separated by the array (ours), JAVELIN-L reaches 0.17 m on the straight drive and 0.31 m on
#   the slalom in our 20-run tables (paper: 0.20 and 0.41 m).
# - **Curvature.** The paper assumes $\sigma_\kappa = 1.5$ m; our extraction of a 23 cm aperture
#   delivers far worse beyond ~10 m (tens of metres RMS, merged or separated). Eq. 51 ties
#   $\kappa$ to the reflection point (SR-NF), while our channel is exact: the wavefront is centred
#   on the VUE (notebooks 02/03 show when the two agree). On the separated route our design uses
#   the VUE distance (`kappa_model="vue"`, section 12).
# - **Clock bias.** We read "variance 50 ns" as a 50 ns standard deviation (15 m); TDoAs cancel
#   it, but the LoS test of eq. 61 and TeNFiLoc's $\hat d$ fallback suffer.
# - **Start.** The paper assumes the open-sky position is known; we start at the truth with 1 m
#   uncertainty rather than its $\sigma_P = 10$ m.
# - **Drive length.** 29 epochs per drive (40 m at 50 km/h), so start-up transients weigh in the
#   averages.
# - **Road markings do not help here (NoRRMs vs N).** Without LoS, our tracker updates the UE
#   with the road bounce in most epochs (on our tuning drives, seed 7, straight: 155 of 174
#   epochs in N, 165 of 174 in NoRRMs): the road image sits at $(x_u, y_u, -z_u)$, a few degrees
#   below the blocked LoS, inside the 5° angle gate. It has the UE's $x$ and $y$, so the lateral
#   error stays at about 0.1 m, but the estimated height drifts down towards the image (2.4 m too
#   low at the end of the drive) and $x$ is biased towards the BS, by 0.6–0.7 m over the last
#   10 m: the 2-D error grows as the vehicle approaches. With the paths separated the RRM paths are
#   found in every epoch and measured to about 1° RMS, yet removing their estimates by oracle
#   lowers JAVELIN-N from 0.47 to 0.33 m (NoRRMs: 0.39 m). They update the UE in only 1 of 174
#   epochs, appear and vanish about three times per drive and add about 2.8 births per drive
#   (5.3 against 2.5); which of these costs the most is not settled. With LoS and RRMs gone, two well-separated paths remain
#   (ceiling and road) and both are extracted almost exactly. (A semicircular tunnel with the BS
#   at the crown has no side-wall specular path in the cross-section: the only wall-like bounce
#   is the ceiling facet next to the crown.)
#
# ## Exercises
#
# 1. Rerun section 5 with `ex.PAPER.with_(sigma_kappa=50.0)`. Does honest curvature noise alone
#    rescue the paper's design? What else is needed?
# 2. Set `max_misses=3` in our design. Do tracks live longer? Does the RMSE change?
# 3. Use `ex.OURS.with_(kappa_model="vue")` on `drive` (the paper's extraction) and on
#    `drive_sep`. Why does the VUE curvature fit an exact (non-SR-NF) channel better, and why does
#    it help on one route only?
# 4. Take one epoch, `ep = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight").epoch(5,
#    np.random.default_rng(1))`, and run `tk.extraction.coherent.resolve_coherent` on it with
#    `max_sources=1`, 2 and 3 (the other arguments: `ep.snapshot.H, ep.estimates,
#    ep.array.local` and the route's `config.fc, config.tone_spacing, config.symbol_period`).
#    Match the results to the true paths with `tk.evaluation.match_paths`. What does each extra
#    source buy?
#
# <details><summary>Solutions</summary>
#
# 1. `ex.evaluate(drive, ex.PAPER.with_(sigma_kappa=50.0))`: better, but still metres off (about
#    7 m on our tuning drives): the spurious CPD components still get associated. Adding
#    `doppler_clutter_margin=1.0` brings it below a metre: both changes are needed (the ablation
#    table shows each step).
# 2. `ex.evaluate(drive, ex.OURS.with_(max_misses=3), keep_reports=True)`: tracks survive missed
#    epochs, births drop by about a third, and the RMSE moves by centimetres (0.56 -> 0.48 m on
#    our tuning drives), within run-to-run spread.
# 3. The exact channel's wavefront is centred on the VUE, so its curvature radius is the VUE
#    distance, not eq. 51's reflector distance (for the ceiling bounce, tens of metres against
#    half a metre). On the separated route each path is fitted as a point source and
#    $\hat\kappa$ estimates exactly that distance: the VUE model nearly halves the error on
#    our tuning drives (0.26 m to 0.15 m, straight, L). On the paper's route the merged
#    components' curvature belongs to no single path, and the VUE model is worse (0.67 m to
#    1.1 m): a better model only pays on measurements that follow it.
# 4. With `max_sources=1` nothing is split: the LoS stays 3.3° off (it still carries the ceiling
#    bounce), the ceiling and one RRM path are missing and two estimates match no true path. With 2, all
#    five paths are found, the LoS within 0.44°, the ceiling within 1.1°. A third source adds
#    nothing in this epoch: no component holds three paths here (it can at x = 28 m, where LoS,
#    ceiling and road share one).
#
# </details>

# %% [markdown]
# ## Checks

# %%
assert jac_err < 1e-5, jac_err
assert abs(gate.threshold(3) - 11.345) < 1e-3
assert np.median(vue_err["mirror"]) < np.median(vue_err["random_walk"])
for ev in (ev_paper, ev_ours):
    assert np.all(np.isfinite(ev.estimates))
    assert all(np.all(np.linalg.eigvalsh(c) > -1e-9) for c in ev.run.covariances)
ours, paper = rmse[("JAVELIN-L", "ours", "separated")], rmse[("JAVELIN-L", "paper", "paper")]
assert ours < 1.0, rmse
assert ours < paper and ours < rmse[("TeNFiLoc-L", "paper", "paper")]
assert ours < rmse[("JAVELIN-L", "ours", "paper")]  # our route beats our design on the paper's
assert los_rms["separated"] < los_rms["paper"]  # and sharpens the LoS direction
assert abl_rows[-1][1] < abl_rows[0][1]  # our route beats the paper's on L
print("all checks passed")
