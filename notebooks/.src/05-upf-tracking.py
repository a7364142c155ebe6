# %% [markdown]
# # 05 · Tracking with EKF, UKF and the unscented particle filter, against the posterior CRLB
#
# *Jiang, Wang & Peng (2023), "A Single-Site Vehicle Positioning Method in the Rectangular Tunnel
# Environment", Remote Sensing 15, 527, [doi:10.3390/rs15020527](https://doi.org/10.3390/rs15020527),
# sections 4.2 and 5; Tichavský, Muravchik & Nehorai (1998) for the bound.
# All references: `REFERENCES.md` at the top of the repository; terms and abbreviations: the
# [glossary](GLOSSARY.md).*
#
# **What you will learn**
#
# - the constant-velocity state model (eq. 40–41) and the virtual-station range/bearing model
#   (eq. 42–45), in NLOS (two wall reflections) and LOS (plus the direct path);
# - how filterpy's EKF and UKF are wired to it, with bearing residuals wrapped to $(-\pi, \pi]$;
# - the unscented particle filter (UPF, eq. 46–63), vectorised over particles, and why the
#   algorithm *as printed* collapses its weights when the process noise is small;
# - the posterior Cramér–Rao bound (PCRLB), which the paper never shows: a lower bound on the
#   mean-square error of *any* filter **averaged over random truths** (the prior's initial state
#   and the process noise), not an error any filter is promised to reach, and not a floor under
#   the error on one fixed trajectory (see [bounds](GLOSSARY.md#bounds)) — and the same recursion
#   without process noise, which for one fixed path is the classical CRLB of unbiased filters and
#   does bound the runs of the paper's drive; how close each filter gets;
# - Tables 2 and 3 of the paper beside ours, and which assumptions reproduce UPF errors of the
#   size the paper reports (about 1 cm at its lowest noise level, 7 cm at 2° / 2 m).

# %%
import numpy as np
from scipy.stats import chi2
from tqdm.auto import tqdm

import tunnelkit as tk
from tunnelkit.plots import (
    bound_ratio_figure,
    cdf_figure,
    particle_cloud_figure,
    rmse_bound_figure,
    table_figure,
    tracks_figure,
)
from tunnelkit.reproduce.jiang_tables import PREDICTION_ONLY, table_rows
from tunnelkit.tracking import pcrlb, registry, upf
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.widgets import upf_explorer

tk.setup_notebook()
RUNS = tk.mc_count(100, 8)  # Monte-Carlo runs per experiment (paper: 100)
PARTICLES = tk.mc_count(500, 200)  # UPF particles (quick mode: fewer, see "How many particles?")
print(f"{RUNS} runs, {PARTICLES} particles")

# %% [markdown]
# ## 1. The state and measurement models
#
# The state is $X_k = [x_k, y_k, \dot x_k, \dot y_k]^T$ and moves with constant velocity
# (eq. 40–41):
#
# $$X_k = \Phi X_{k-1} + U_{k-1},\qquad
# \Phi = \begin{bmatrix} 1&0&T_1&0\\0&1&0&T_1\\0&0&1&0\\0&0&0&1\end{bmatrix},\qquad
# U_k \sim N(0, Q).$$
#
# The paper states neither the observation period $T_1$ nor $Q$. We take $T_1 = 0.1$ s (the
# trajectory's sampling period) and the white-noise-acceleration model
# $Q = q \begin{bmatrix} T_1^3/3 & T_1^2/2 \\ T_1^2/2 & T_1\end{bmatrix} \otimes I_2$ with
# $q = 0.1\ \mathrm{m^2/s^3}$, the same for the straight and the curved preset (the choice and its
# reason are written in the `[tracking]` section of both scenario files).
#
# The measurement (eq. 42–45) stacks the ranges and then the bearings from each station $i$:
#
# $$Z_k = \big[d_{1k}, \dots, d_{Nk}, \beta_{1k}, \dots, \beta_{Nk}\big]^T + V_k,\quad
# d_{ik} = \sqrt{(x_k - x_{vi})^2 + (y_k - y_{vi})^2},\quad
# \beta_{ik} = \operatorname{atan2}(y_k - y_{vi},\, x_k - x_{vi}),$$
#
# with $V_k \sim N(0, R)$, $R = \mathrm{diag}(\sigma_d^2 \dots, \sigma_\theta^2 \dots)$. In NLOS the
# stations are the two virtual stations; in LOS the base station comes first (the direct path).
# The paper writes the bearing as $\arctan$ of the ratio, which cannot tell opposite quadrants
# apart; we use the four-quadrant $\operatorname{atan2}$ (the same where the paper's geometry
# puts the vehicle, and defined everywhere).

# %%
exp = vs.experiment("jiang2023-straight", level=2)  # (2 deg, 2 m), NLOS
m = exp.model
print("stations (virtual):\n", m.stations.round(4))
print("Phi =\n", m.F, "\nQ =\n", m.Q.round(6))
print("R diagonal:", np.diag(m.R).round(6))
print("LOS stations:\n", vs.model_from_scenario("jiang2023-straight", los=True).stations.round(4))

# %% [markdown]
# Each Monte-Carlo run draws the filters' prior mean from $N(X_0, P_0)$ around the true initial
# state with $P_0 = \mathrm{diag}(1\,\mathrm{m}^2, 1\,\mathrm{m}^2, 1\,(\mathrm{m/s})^2,
# 1\,(\mathrm{m/s})^2)$: an honest prior, which is also what the bound of section 5 starts from.

# %% [markdown]
# ## 2. Four interchangeable estimators
#
# The registry family `"jiang2023"` holds the four algorithms the paper compares. All share the
# filterpy surface (`x`, `P`, `predict()`, `update(z)`, `update(None)` for a missed epoch):
#
# | name | what it is |
# | --- | --- |
# | TSWLS | snapshot two-stage weighted least squares (eq. 29–39), one epoch at a time |
# | EKF | filterpy `ExtendedKalmanFilter`, analytic Jacobian of eq. 45 (sign-corrected eq. A2) |
# | UKF | filterpy `UnscentedKalmanFilter`, `MerweScaledSigmaPoints` ($\alpha=1, \beta=2, \kappa=0$; the paper, after eq. 50, asks for a small $\alpha$ without a value: ours spreads the sigma points to $\pm\sqrt{n}$ standard deviations) |
# | UPF | unscented particle filter (eq. 46–63), vectorised over particles |
#
# Not in the paper: EKF, UKF and UPF **gate** every measurement vector by default. With the
# innovation $y = Z - \hat Z$ (bearings wrapped) and its covariance $S$ from the filter, a vector
# with $y^T S^{-1} y > \chi^2_{2N}(0.999)$ (18.5 for two stations) is a gross outlier — a range
# 100 m off, a bearing 90° off — and the epoch is treated as missed; `n_rejected` counts them.
# A consistent filter rejects a good vector once in a thousand epochs (that is what the 0.999
# quantile means): on clean runs the gate changes the EKF's RMSE by less than a per cent (printed
# below). After five rejections in a row the gate takes the next measurement with an inflated
# covariance, so a real change is never locked out (`tunnelkit.tracking.reopening`). `gate=None`
# gives the paper's filters.
#
# One run, all four on the same measurements; drag the slider (or press play) to follow them.

# %%
print(list(registry.family("jiang2023")))
one = vs.monte_carlo(exp, 1, seed=3, options={"UPF": {"n_particles": PARTICLES}})
Zg, x0g = exp.simulate(1, np.random.default_rng(8))
Zg[0, 50, 0] += 100.0  # one range 100 m off at epoch 50
jump = {}
for opts in ({"gate": None}, {}):
    est = vs.run_estimator("EKF", m, Zg, x0g, exp.P0, **opts)[0, :, :2]
    jump[opts.get("gate", 0.999)] = float(np.linalg.norm(est[50] - exp.truth[50, :2]))
print(f"EKF error at the outlier epoch: no gate {jump[None]:.2f} m, gated {jump[0.999]:.2f} m")
Zc, x0c = exp.simulate(RUNS, np.random.default_rng(9))  # clean runs: what the gate costs
gate_rmse = {}
for g in (None, 0.999):
    ec = vs.run_estimator("EKF", m, Zc, x0c, exp.P0, gate=g)[..., :2] - exp.truth[:, :2]
    gate_rmse[g] = float(np.sqrt(np.mean(np.sum(ec**2, axis=-1))))
print(
    f"EKF RMSE on {RUNS} clean runs: no gate {gate_rmse[None]:.4f} m, gated {gate_rmse[0.999]:.4f} m"
)
print(f"gate threshold chi2_{2 * m.n_stations}(0.999) = {chi2.ppf(0.999, 2 * m.n_stations):.1f}")
sc = tk.load_scenario("jiang2023-straight")
tracks_figure(sc.tunnel(), sc.base_station(), exp.truth, {n: e[0] for n, e in one.items()})

# %% [markdown]
# ## 3. EKF and UKF: bearings need care
#
# Both filters see bearings, which live on a circle. A residual $\beta - \hat\beta$ must be
# wrapped to $(-\pi, \pi]$, and the UKF's weighted mean of sigma-point bearings (eq. 53) must not
# average $+179°$ and $-179°$ to $0°$. `VsModel.residual_z` wraps, `VsModel.z_mean` averages
# wrapped offsets from the first sigma point; both are passed to filterpy as `residual_z` /
# `z_mean_fn` (and `residual=` for the EKF). In this tunnel the bearings stay far from $\pm\pi$, so
# the check below builds a case that crosses it.

# %%
m1 = vs.VsModel(np.zeros((1, 2)), 0.01, 0.1, 0.1, 0.1)
sig = np.array([[1.0, np.pi - 0.01], [1.0, -np.pi + 0.01], [1.0, np.pi - 0.03]])
w = np.array([0.5, 0.25, 0.25])
print("naive mean bearing  :", round(float(w @ sig[:, 1]), 4), "rad")
print("wrapped mean bearing:", round(float(m1.z_mean(sig, w)[1]), 4), "rad")

# %% [markdown]
# ## 4. The unscented particle filter
#
# Each particle $i$ carries a state sample $X^i_{k-1}$ and a covariance $P^i_{k-1}$. Per epoch:
#
# 1. sigma points and UKF time update (eq. 46–52): for the linear $f_1$ the unscented transform
#    is exact, $\bar X^i_{k|k-1} = \Phi X^i_{k-1}$;
# 2. UKF measurement update (eq. 53–58) gives the proposal $N(\bar X^i_k, P^i_k)$;
# 3. sample $X^i_k \sim N(\bar X^i_k, P^i_k)$ (eq. 59);
# 4. weight (eq. 60–61) $\ w^i_k \propto w^i_{k-1}\,
#    \dfrac{p(Z_k \mid X^i_k)\, p(X^i_k \mid X^i_{k-1})}{q(X^i_k \mid X^i_{k-1}, Z_k)}$;
# 5. resample (the paper: every epoch, its step 6; ours: only when the effective sample size
#    $1/\sum_i (w^i)^2$ falls below $N/2$, which keeps more distinct particles);
# 6. output the weighted mean and spread (eq. 62–63).
#
# `tunnelkit.tracking.upf` does every step for all particles at once (batched sigma points,
# batched Cholesky factors, one `np.linalg.solve`), and also over a batch of Monte-Carlo runs.
#
# **Small $Q$: where the weights degenerate.** In eq. 52 the predicted covariance of particle
# $i$ is $\Phi P^i_{k-1}\Phi^T + Q$: each particle carries its own covariance, as in the standard
# UPF (van der Merwe et al., the paper's ref. 51). Its successor given the sample $X^i_{k-1}$,
# however, is spread by $Q$ alone. When $Q \ll P^i$ the proposal is far wider than
# $p(X_k \mid X^i_{k-1})$, the weight ratio of eq. 60 has a huge variance and one particle takes
# all the weight. We keep both: `proposal="carried"` (eq. 52) and `proposal="conditional"` (our
# default, the UKF approximation of the locally optimal proposal $p(X_k \mid X^i_{k-1}, Z_k)$,
# built from $Q$ alone).

# %%
Z1, x01 = exp.simulate(1, np.random.default_rng(4))
N_ESS, ess_med = 200, {}
for prop in ("carried", "conditional"):
    ess = upf.one_epoch_ess(
        m,
        Z1[0],
        x01[0],
        exp.P0,
        rng=np.random.default_rng(1),
        n_particles=N_ESS,
        proposal=prop,
        epochs=30,
    )
    ess_med[prop] = float(np.median(ess[5:]))
    print(f"{prop:11s}: median ESS of one epoch's weights = {ess_med[prop]:6.1f} of {N_ESS}")

# %% [markdown]
# ### The particle cloud
#
# Marker area follows the weight; the cloud starts as wide as the prior and contracts as
# measurements arrive (panels are 6 m wide, centred on the truth).

# %%
f = upf.UnscentedParticleFilter(
    m, x01[0], exp.P0, rng=np.random.default_rng(2), n_particles=PARTICLES
)
snaps = []
for k in range(100):
    f.step(Z1[0, k], first=(k == 0))
    if k in (0, 3, 20, 99):
        snaps.append(
            {
                "t": k * m.period,
                "particles": f.particles[0],
                "weights": f.weights,
                "truth": exp.truth[k, :2],
                "estimate": f.position,
            }
        )
particle_cloud_figure(snaps)

# %% [markdown]
# ## 5. The posterior Cramér–Rao bound
#
# For $X_k = \Phi X_{k-1} + U$ and $Z_k = h(X_k) + V$ the information matrix $J_k$ of the state
# follows Tichavský et al. (1998):
#
# $$J_0 = P_0^{-1} + E[H_0^T R^{-1} H_0],\qquad
# J_k = D^{22}_k - D^{21}\,(J_{k-1} + D^{11})^{-1} D^{12},$$
#
# $$D^{11} = \Phi^T Q^{-1}\Phi,\quad D^{12} = (D^{21})^T = -\Phi^T Q^{-1},\quad
# D^{22}_k = Q^{-1} + E[H_k^T R^{-1} H_k],$$
#
# where $H_k$ is the Jacobian of eq. 45 at the true state and $E[\cdot]$ averages over the random
# truth. It is a [Bayesian bound](GLOSSARY.md#bounds): **averaged over random truths** — the
# initial state drawn from the prior, the process noise $U$ of every epoch — and over the
# measurement noise, every filter's position MSE is at least $\mathrm{tr}$ of the position block
# of $J_k^{-1}$. It says nothing about one fixed trajectory: there a filter can do better (the
# next subsection shows it). With a huge $Q$ no epoch remembers another and the recursion gives
# the snapshot CRLB of notebook 01.
#
# Below: 2 deg / 2 m, straight, NLOS, the same simulated runs for all four. Every run drives the
# **same** path, the straight preset, which has no process noise, and the filters' RMSE is over
# the runs' measurement noise and prior means only. `pcrlb.vs_pcrlb` evaluates $H_k$ along that
# one path in place of $E[\cdot]$ over random truths: an approximation of the bound over random
# drives about it ([PCRLB](GLOSSARY.md#pcrlb)), and no bound on these runs of one drive. The
# dashed line's name says so.


# %%
Q01 = "sqrt(PCRLB) of wandering truths (q = 0.1): not a bound on this path"  # the dashed curve
bound = pcrlb.vs_pcrlb(m, exp.truth, exp.P0)
# the same simulated runs for every estimator; a progress bar over the estimators
mc = vs.monte_carlo(exp, RUNS, seed=0, options={"UPF": {"n_particles": PARTICLES}}, progress=True)
err = {n: np.linalg.norm(e[..., :2] - exp.truth[:, :2], axis=-1) for n, e in mc.items()}
rmse_t = {n: np.sqrt(np.mean(e**2, axis=0)) for n, e in err.items()}
ratio = {n: float(np.sqrt(np.mean(e**2) / np.mean(bound**2))) for n, e in err.items()}
print("RMSE / sqrt(PCRLB) over the run:", {n: round(r, 3) for n, r in ratio.items()})
rmse_bound_figure(
    exp.times, rmse_t, bound, title=f"Straight NLOS, 2 deg / 2 m, {RUNS} runs", bound_name=Q01
)

# %% [markdown]
# On this one fixed path the EKF, UKF and UPF end up *below* the bound: their ratios, printed
# above, are all under 1. That does not break it — the next subsection shows why. TSWLS uses one
# epoch at a time and stays 3–4× above it. The CDFs of the per-epoch error (the paper's Figs. 5,
# 7, 9 in spirit):

# %%
cdf_figure(err, title="CDF of the position error, straight NLOS, 2 deg / 2 m")

# %% [markdown]
# ### Below the bound? What the PCRLB assumes about the truth
#
# A ratio RMSE / $\sqrt{\mathrm{PCRLB}}$ below 1 does not break the bound, because the bound is
# not about *this* trajectory. The recursion above is the bound for the state of eq. 40–41
# **including its process noise**: the truth itself is random, $X_k = \Phi X_{k-1} + U_{k-1}$
# with $U \sim N(0, Q)$, so at every epoch the velocity may have changed by an amount of
# covariance $Q$ and no filter can know by how much until the measurements tell it. That term,
# $Q^{-1}$ in $D^{22}$ and $D^{11}$, keeps $J_k$ from growing without limit: the bound levels off.
#
# The straight preset has **no** process noise: it drives an exactly constant velocity. The
# filters still assume $Q$ (they do not know the truth is straight), but here every epoch's
# measurements are about the *same* velocity, the accumulated information is larger than the
# bound allows for a random truth, and the RMSE can end up below it. Draw the truths from the
# motion model instead — the start of the straight preset, then $X_k = \Phi X_{k-1} + U_{k-1}$
# with the same $Q$ — and the bound is the yardstick it was derived for: the ratio comes back to
# about 1, within 10 % (15 % in quick mode's few runs), and never below 1 by more than two of its
# Monte-Carlo standard errors (printed with it: a ratio a little under 1 on a finite sample is
# sampling, not a broken bound). The bound is then the average over the sampled truths of
# $E[H_k^\mathsf{T}R^{-1}H_k]$, as `vs_pcrlb` does for a stack of trajectories.
#
# The bound that matches the preset itself is the same recursion **without** process noise, its
# limit $q \to 0$: $J_k = \Phi^{-T} J_{k-1} \Phi^{-1} + E[H_k^T R^{-1} H_k]$, the information
# about the start carried forward (`vs_pcrlb(..., process_noise=False)`; $q = 10^{-6}$ gives the
# same to 0.1 %). Why it bounds *these* runs, where the start is fixed and only the data vary:
# the path is known up to its start $X_0$, and a run's data are the prior mean, drawn from
# $N(X_0, P_0)$ — a measurement of $X_0$ with covariance $P_0$ — and the $Z_k$. For that
# deterministic unknown the recursion is the **classical CRLB**: it bounds the covariance of
# any unbiased estimator of $X_k$ (the filters are close to unbiased here), whatever $q$ the
# filter is told. (Averaged over random starts it is also the Bayesian bound of straight drives
# around this one.) An estimator that knew the path could beat it, as it could beat any bound of
# a fixed truth; a filter that does not know it cannot. It lies below the $q = 0.1$ curve, and
# the same runs sit above it (the middle panel, ratios printed).

# %%
RUNS_MM = tk.mc_count(100, 12)  # truths drawn from the motion model
rng_mm = np.random.default_rng(21)
n_t = exp.truth.shape[0]
chol_q = np.linalg.cholesky(m.Q)
truth_mm = np.empty((RUNS_MM, n_t, 4))
truth_mm[:, 0] = exp.truth[0]
for k in range(1, n_t):
    truth_mm[:, k] = truth_mm[:, k - 1] @ m.F.T + rng_mm.standard_normal((RUNS_MM, 4)) @ chol_q.T
Z_mm = m.simulate(truth_mm[..., :2], rng_mm)
x0_mm = vs.initial_states(exp.truth[0], exp.P0, rng_mm, size=RUNS_MM)
bound_mm = pcrlb.vs_pcrlb(m, truth_mm, exp.P0)
rmse_mm, ratio_mm, se_mm = {}, {}, {}
for name in tqdm(("EKF", "UKF", "UPF"), desc=f"filters on {RUNS_MM} random truths", leave=False):
    opts = {"n_particles": PARTICLES} if name == "UPF" else {}
    est = vs.run_estimator(name, m, Z_mm, x0_mm, exp.P0, rng=np.random.default_rng(22), **opts)
    mse = np.sum((est[..., :2] - truth_mm[..., :2]) ** 2, axis=-1)  # (runs, T)
    rmse_mm[name] = np.sqrt(mse.mean(axis=0))
    ratio_mm[name] = float(np.sqrt(mse.mean() / np.mean(bound_mm**2)))
    # its Monte-Carlo standard error, from the spread of the runs' mean squared errors
    per_run = mse.mean(axis=1)
    se_mm[name] = ratio_mm[name] * float(per_run.std(ddof=1) / per_run.mean()) / (2 * RUNS_MM**0.5)
bound0 = pcrlb.vs_pcrlb(m, exp.truth, exp.P0, process_noise=False)  # q -> 0, the limit
DRIVE_BOUND = "sqrt(PCRLB) of this drive (q -> 0): a bound on the RMSE over runs"
bound0_6 = pcrlb.vs_pcrlb(  # the recursion with a tiny q approaches it
    vs.experiment("jiang2023-straight", level=2, q=1e-6).model, exp.truth, exp.P0
)
ratio0 = {n: float(np.sqrt(np.mean(err[n] ** 2) / np.mean(bound0**2))) for n in rmse_mm}
print("RMSE / sqrt(PCRLB), noise-free truth, q = 0.1 :", {n: round(ratio[n], 3) for n in rmse_mm})
print(
    "RMSE / sqrt(PCRLB), noise-free truth, q -> 0  :", {n: round(r, 3) for n, r in ratio0.items()}
)
print(
    "RMSE / sqrt(PCRLB), truths from the model    :",
    {n: f"{r:.3f} +- {se_mm[n]:.3f}" for n, r in ratio_mm.items()},
)
bound_ratio_figure(
    exp.times,
    {
        "preset: q = 0.1, no bound": ({n: rmse_t[n] for n in rmse_mm}, bound),
        "preset: its bound, q -> 0": ({n: rmse_t[n] for n in rmse_mm}, bound0),
        f"truths from the model ({RUNS_MM}), q = 0.1": (rmse_mm, bound_mm),
    },
    title="RMSE / sqrt(PCRLB) per epoch: the q = 0.1 figure assumes a truth that wanders",
)

# %% [markdown]
# ### The curved trajectory and LOS
#
# The curved preset (a lane change with $\pm 0.24\ \mathrm{m/s^2}$ lateral acceleration) is not a
# constant-velocity path: the filters absorb the manoeuvre through $Q$. In LOS the direct path
# adds a third station. The dashed curve is each drive's own bound, $q \to 0$ along its true
# path, as for the straight preset above; on the curved path the manoeuvre enters it as a known
# input, which the filters do not have, so it stays a bound for them.

# %%
cur = vs.experiment("jiang2023-curved", level=2).truth
acc = np.diff(cur[:, 2:], axis=0) / m.period
v_c = cur[1:, 2:]
a_lat = (v_c[:, 0] * acc[:, 1] - v_c[:, 1] * acc[:, 0]) / np.linalg.norm(v_c, axis=1)
print(f"curved preset: lateral acceleration from {a_lat.min():+.3f} to {a_lat.max():+.3f} m/s^2")
curves, rmse_c = {}, {}
for name, los in tqdm((("curved NLOS", False), ("straight LOS", True)), leave=False):
    scen = "jiang2023-curved" if name.startswith("curved") else "jiang2023-straight"
    e2 = vs.experiment(scen, level=2, los=los)
    r2 = vs.monte_carlo(e2, RUNS, seed=1, options={"UPF": {"n_particles": PARTICLES}})
    b2 = pcrlb.vs_pcrlb(e2.model, e2.truth, e2.P0, process_noise=False)
    mse = {
        n: np.mean(np.sum((e[..., :2] - e2.truth[:, :2]) ** 2, -1), axis=0) for n, e in r2.items()
    }
    curves[name] = {n: float(np.sqrt(np.mean(v) / np.mean(b2**2))) for n, v in mse.items()}
    rmse_c[name] = ({n: np.sqrt(v) for n, v in mse.items()}, b2)
    print(f"{name:13s} RMSE / sqrt(PCRLB):", {n: round(v, 3) for n, v in curves[name].items()})
rmse_bound_figure(
    exp.times,
    *rmse_c["curved NLOS"],
    title=f"Curved NLOS, 2 deg / 2 m, {RUNS} runs",
    bound_name=DRIVE_BOUND,
)

# %% [markdown]
# Against each drive's own bound the three filters lie above it on both drives, at 1.1 to 1.5
# times it (ratios printed above), and TSWLS at 4 to 5 times: the lane change costs the filters
# little, since their $q = 0.1$ lets the velocity follow it, and the third station of LOS lowers
# the bound and the errors alike.

# %% [markdown]
# ## 6. Tables 2 and 3: the paper beside ours
#
# Mean and variance of the Euclidean position error over all runs and epochs of the straight
# trajectory, per noise level (`tunnelkit reproduce jiang-table2` / `jiang-table3` runs the same
# code with 100 runs and a progress bar).

# %%
cols = [
    "algorithm",
    "sigma_theta_deg",
    "sigma_d_m",
    "paper_mean_m",
    "ours_mean_m",
    "paper_var_m2",
    "ours_var_m2",
    "rmse_over_pcrlb",
]
t2 = table_rows(
    "jiang2023_table2", los=False, runs=RUNS, seed=0, n_particles=PARTICLES, progress=True
)
table_figure(t2, cols, title=f"Table 2 (NLOS), {RUNS} runs")

# %%
t3 = table_rows(
    "jiang2023_table3", los=True, runs=RUNS, seed=0, n_particles=PARTICLES, progress=True
)
# the comparisons the reading below makes, over both tables and every noise level
ours = {
    (t, r["sigma_d_m"], r["algorithm"]): r for t, tab in (("NLOS", t2), ("LOS", t3)) for r in tab
}
levels_d = sorted({k[1] for k in ours})
cases = [(t, lv) for t in ("NLOS", "LOS") for lv in levels_d]
mean_of = {k: r["ours_mean_m"] for k, r in ours.items()}
filt = ("EKF", "UKF", "UPF")
tswls_factor = {
    (t, lv, a): mean_of[t, lv, "TSWLS"] / mean_of[t, lv, a] for t, lv in cases for a in filt
}
ekf_ukf = [mean_of[t, lv, "EKF"] / mean_of[t, lv, "UKF"] - 1 for t, lv in cases]
upf_ukf = [mean_of[t, lv, "UPF"] / mean_of[t, lv, "UKF"] - 1 for t, lv in cases]
kf_bound = [ours[t, lv, a]["rmse_over_pcrlb"] for t, lv in cases for a in ("EKF", "UKF")]
radio_gain = [
    ours[t, lv, PREDICTION_ONLY]["ours_rmse_m"] / ours[t, lv, a]["ours_rmse_m"]
    for t, lv in cases
    for a in filt
]
print(
    f"TSWLS mean / filter mean: {min(tswls_factor.values()):.2f} to {max(tswls_factor.values()):.2f}"
)
print(f"EKF mean / UKF mean - 1: {min(ekf_ukf):+.1%} to {max(ekf_ukf):+.1%}")
print(
    f"UPF mean / UKF mean - 1 ({PARTICLES} particles): {min(upf_ukf):+.1%} to {max(upf_ukf):+.1%}"
)
print(
    "EKF and UKF, RMSE / sqrt(PCRLB of the drive as simulated, q -> 0): "
    f"{min(kf_bound):.2f} to {max(kf_bound):.2f}"
)
print(f"prediction only RMSE / filter RMSE: {min(radio_gain):.0f} to {max(radio_gain):.0f}")
table_figure(t3, cols, title=f"Table 3 (LOS), {RUNS} runs")

# %% [markdown]
# **What agrees** (the ranges printed above Table 3). Filtering beats snapshot TSWLS by a factor
# of 2 to 4 in mean error, the more the noisier the measurements; errors grow with the noise; LOS
# (three stations) is better than NLOS. Every filter is far ahead of its baseline, the `prediction
# only` rows: the same constant-velocity model from the same prior with every measurement dropped,
# metres off after ten seconds of a prior velocity known to 1 m/s (the ratio of their RMSEs, the
# radio's gain, is printed above Table 3, more than 5 everywhere).
#
# **What does not.** EKF and UKF are within a few per cent of each other, and the UPF does not
# beat them: with 500 particles its mean lies between 3 % below and 6 % above the UKF's (the
# range printed above Table 3), with fewer (quick mode's 200) it can lose track on a run and end
# further above. The tables' `rmse_over_pcrlb`
# is the RMSE over the bound of the drive as simulated, the $q \to 0$ bound of section 5 (not
# the filters' $q = 0.1$ one, which they beat on this path): the EKF's and UKF's RMSE lies
# between about 1.2 and 2.2 times it (printed above Table 3), above it at every level as a bound
# requires, and furthest above at the lowest noise, where the velocity the filters let wander
# ($q = 0.1$) costs most against a truth that never turns. For this nearly linear,
# Gaussian problem the UKF posterior is already almost exact, so a particle filter has nothing
# left to gain; its Monte-Carlo sampling costs it a little. No ordering UPF < UKF < EKF beyond
# noise is to be had here.
#
# **How many particles?** Under a small $Q$ the velocity is almost a constant parameter, and
# each resampling leaves fewer distinct velocities (sample impoverishment): with too few
# particles a run can lock onto a wrong velocity and drift. How often, against the particle
# count, takes a hundred runs per count: too few particles lose a run now and then, full mode's
# count none of a hundred ([measured](../docs/results/upf-particles.md)).
#
# **The paper's UPF means (0.011 m at $\sigma_d = 0.1$ m, 0.074 m at 2 m)** look far below what
# the measurements allow. Two cautions before setting them against a bound. A mean error is not
# an RMSE: $E\|e\| \le \sqrt{E\|e\|^2}$, so a mean below a bound on the RMSE contradicts
# nothing by itself. The paper gives the variance of the same error too, so its RMSE is
# $\sqrt{\text{mean}^2 + \text{variance}}$ (reading the variance as that of the Euclidean error,
# as our tables do): that is what we compare. And the bound must be the one for the paper's
# truth, a straight drive without process noise: the $q \to 0$ bound of section 5, whose RMS over
# the run bounds the RMSE over runs and epochs. It rests on our reading of what the paper leaves
# open ($T_1 = 0.1$ s, the preset's 100 epochs, the prior $P_0$ of section 1).
#
# Printed below, per noise level: at 0.5° / 0.1 m the paper's EKF and UKF RMSEs lie above the
# bound (about 2 and 1.75 times), its UPF's about 3 % *below* it; at 1° / 1 m and 2° / 2 m every
# filter's, EKF and UKF as well as the UPF, lies at 0.3 to 0.6 times it — below what any unbiased
# filter with this prior can reach on this drive (section 5), under the assumptions just
# named — while ours lie above it. Two assumptions
# reproduce numbers of that size: (a) the filter starts at the *true* state with a tiny prior
# covariance and (almost) no process noise, on a path that is exactly constant-velocity: it then
# reports its prior and hardly listens to the measurements (it starts from what no filter knows, the
# true state, so no bound built on our prior $P_0$ holds it); (b) "mean error" is the mean of
# *signed* errors, which cancel. The paper's TSWLS fails the same test against the snapshot CRLB
# (the same recursion with a huge $Q$, so that no epoch remembers another), the bound of an unbiased
# per-epoch fix: its RMSE at 2° / 2 m (0.35 m, from its mean 0.333 m and its variance) is several
# times below that bound's RMS, where our TSWLS's RMSE lies (within 10 %; it is unbiased to first
# order). Both effects, and both bounds, measured:

# %%
oracle = vs.experiment("jiang2023-straight", level=2, q=1e-6, p0_sigma=[0.01, 0.01])
Zo, _ = exp.simulate(RUNS, np.random.default_rng(5))
x0_true = np.tile(exp.truth[0], (RUNS, 1))
est_o = vs.run_estimator(
    "UPF", oracle.model, Zo, x0_true, oracle.P0, rng=np.random.default_rng(6), n_particles=PARTICLES
)
oracle_mean = float(np.linalg.norm(est_o[..., :2] - exp.truth[:, :2], axis=-1).mean())
signed = mc["UPF"][..., :2] - exp.truth[:, :2]
print(f"(a) UPF started at the truth, P0 = (1 cm)^2, q = 1e-6: mean error {oracle_mean:.4f} m")
print(
    f"(b) honest UPF, mean of signed errors: {np.abs(signed.mean(axis=(0, 1))).round(4)} m (x, y)"
)
print(f"    honest UPF, mean Euclidean error : {np.linalg.norm(signed, axis=-1).mean():.4f} m")
# the paper's RMSE from its own mean and variance, beside the bound for its noise-free drive
paper_t2 = {(r["algorithm"], r["sigma_d_m"]): r for r in tk.reference.load("jiang2023_table2")}
paper_rmse = {k: float(np.sqrt(r["mean_m"] ** 2 + r["variance_m2"])) for k, r in paper_t2.items()}
bound0_rms, paper_over0, ours_over0 = {}, {}, {}
for lv, sd in enumerate(levels_d):
    e0 = vs.experiment("jiang2023-straight", level=lv)
    b0 = pcrlb.vs_pcrlb(e0.model, e0.truth, e0.P0, process_noise=False)
    bound0_rms[sd] = float(np.sqrt(np.mean(b0**2)))
    for a in filt:
        paper_over0[sd, a] = paper_rmse[a, sd] / bound0_rms[sd]
        ours_over0[sd, a] = ours["NLOS", sd, a]["ours_rmse_m"] / bound0_rms[sd]
    print(
        f"sigma_d = {sd:g} m (sigma_d of the bound {np.sqrt(e0.model.R[0, 0]):g} m): sqrt(PCRLB), "
        f"q -> 0, RMS over the run {bound0_rms[sd]:.3f} m; RMSE / it, paper: "
        + ", ".join(f"{a} {paper_over0[sd, a]:.2f}" for a in filt)
        + "; ours: "
        + ", ".join(f"{a} {ours_over0[sd, a]:.2f}" for a in filt)
    )
snap = vs.experiment("jiang2023-straight", level=2, q=1e6)  # no memory from epoch to epoch
snap_bound = pcrlb.vs_pcrlb(snap.model, exp.truth, snap.P0)[1:]  # epoch 0 still has the prior
snap_rms = float(np.sqrt(np.mean(snap_bound**2)))
tswls_over_snap = ours["NLOS", 2.0, "TSWLS"]["ours_rmse_m"] / snap_rms
print(
    f"snapshot sqrt(CRLB) at 2 deg / 2 m, RMS over the run {snap_rms:.2f} m; TSWLS RMSE: the "
    f"paper's {paper_rmse['TSWLS', 2.0]:.2f} m, ours {tswls_over_snap:.2f} times the bound"
)

# %% [markdown] tags=["explorer"]
# ## 7. Explore
#
# One run of all four estimators: each curve is one drive's error, epoch by epoch, and the dashed
# sqrt(PCRLB) is the bound of the drive as simulated (no process noise, the start from the
# prior): it bounds the RMSE over many such runs, not one run's error, which can dip under it
# (section 5). Move the noise
# sliders and the particle count (try 1 particle: the UPF becomes a UKF that samples its own
# posterior, and pays for it).

# %% tags=["explorer"]
explorer = upf_explorer(n_particles=min(PARTICLES, 200))
explorer

# %% [markdown]
# ## Exercises
#
# 1. Set `q` ten times larger and ten times smaller (`vs.experiment(..., q=...)`) on the straight
#    and the curved preset. Which filter suffers on which trajectory, and does the ratio to the
#    PCRLB tell you?
# 2. Run the UPF with `proposal="carried"` (eq. 52 as printed) in a small Monte-Carlo at
#    2 deg / 2 m. Compare its RMSE and the number of resampling events (`f.resampled`: under the
#    paper's rule every epoch resamples, ours only below $N/2$, section 4) with the default.
# 3. Drop every third epoch after the first two (`Z[:, 2::3] = np.nan`) and rerun. How much does
#    each filter lose? What does TSWLS do on a missed epoch?
#
# The solutions are the collapsed cells below, and Run All does not run them. Once you have
# tried an exercise, click the "Run solution" button under its solution (or run
# `tk.solution("05.2")` in a cell, for exercise 2): the solution runs on a copy of the
# notebook's variables, so it changes none of yours, and shows what it prints. A cell's blue
# bar shows its code. On the static site the solutions have already run: open one, then its
# "Show the solution's output". What to read in them follows.

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 05.1
# Solution 1: q ten times larger and smaller, straight and curved, EKF and UKF
q0, n_x = exp.model.q, tk.mc_count(20, 6)
sol1, sol1_ekf = {}, {}
for scen in ("jiang2023-straight", "jiang2023-curved"):
    for fq in (10.0, 1.0, 0.1):
        e_q = vs.experiment(scen, level=2, q=q0 * fq)
        r_q = vs.monte_carlo(e_q, n_x, seed=2, names=["EKF", "UKF"])
        b_q = pcrlb.vs_pcrlb(e_q.model, e_q.truth, e_q.P0)
        for name_q, out_q in (("UKF", sol1), ("EKF", sol1_ekf)):
            e2_q = np.sum((r_q[name_q][..., :2] - e_q.truth[:, :2]) ** 2, axis=-1)
            out_q[scen, fq] = (np.sqrt(e2_q.mean()), np.sqrt(e2_q.mean() / np.mean(b_q**2)))
        print(
            f"{scen:20s} q x {fq:4}: RMSE EKF {sol1_ekf[scen, fq][0]:.2f} m, UKF "
            f"{sol1[scen, fq][0]:.2f} m; UKF RMSE/sqrt(PCRLB of the model) {sol1[scen, fq][1]:.2f}"
        )
st, cu = "jiang2023-straight", "jiang2023-curved"
assert sol1[st, 0.1][0] < sol1[st, 10.0][0] and sol1[cu, 0.1][1] > 1.0, sol1
assert max(sol1[st, fq][1] for fq in (10.0, 1.0, 0.1)) < 1.0, sol1  # straight: below the bound
# EKF and UKF alike (within 5 %) in every case: neither suffers more than the other
assert all(abs(sol1_ekf[k][0] / sol1[k][0] - 1) < 0.05 for k in sol1), (sol1, sol1_ekf)

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 05.2
# Solution 2: the proposal as printed (eq. 52) against the default
Zp, x0p = exp.simulate(tk.mc_count(20, 4), np.random.default_rng(0))
sol2 = {}
for prop in ("carried", "conditional"):
    f_p = upf.UnscentedParticleFilter(
        m,
        x0p,
        exp.P0,
        rng=np.random.default_rng(1),
        n_particles=min(PARTICLES, 200),
        proposal=prop,
    )
    est_p = np.stack([f_p.step(Zp[:, k], first=(k == 0)) for k in range(Zp.shape[1])], 1)
    rmse_p = np.sqrt(np.mean(np.sum((est_p[..., :2] - exp.truth[:, :2]) ** 2, -1)))
    sol2[prop] = (float(np.mean(f_p.resampled)), float(rmse_p))
    print(
        f"{prop:12s} resampling events per run {sol2[prop][0]:5.1f} of {Zp.shape[1]}, "
        f"RMSE {rmse_p:.2f} m"
    )
assert (
    sol2["carried"][0] > 2 * sol2["conditional"][0]
    and sol2["carried"][1] > 2 * sol2["conditional"][1]
), sol2

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 05.3
# Solution 3: every third epoch missed (on solution 2's drives)
Zp, x0p = exp.simulate(tk.mc_count(20, 4), np.random.default_rng(0))
Zm = Zp.copy()
Zm[:, 2::3] = np.nan
sol3 = {}
for name in ("EKF", "UKF", "TSWLS"):
    full, gaps = (vs.run_estimator(name, m, Z_, x0p, exp.P0) for Z_ in (Zp, Zm))
    if name == "TSWLS":  # on a missed epoch it repeats the previous epoch's fix
        assert np.allclose(gaps[:, 2::3, :2], gaps[:, 1::3, :2][:, : gaps[:, 2::3].shape[1]])
    sol3[name] = [
        float(np.sqrt(np.mean(np.sum((e_[..., :2] - exp.truth[:, :2]) ** 2, -1))))
        for e_ in (full, gaps)
    ]
    print(
        f"{name:6s} RMSE all epochs {sol3[name][0]:.2f} m, every third missed {sol3[name][1]:.2f} m"
    )
assert all(sol3[n][1] > sol3[n][0] for n in sol3) and sol3["TSWLS"][1] > sol3["UKF"][1], sol3

# %% [markdown]
# <details><summary>What to read in the solutions</summary>
#
# 1. EKF and UKF behave alike (within 5 %) in every case. On the straight path a smaller `q`
#    lowers the RMSE (the filter averages longer) and the model's bound with it, and the ratio
#    stays below 1 (section 5: the fixed, noise-free path lets the filters beat the bound of
#    random drives; the drive's own bound, $q \to 0$, stays under them). On the curve a too small `q` makes the filters lag
#    the lane change: the RMSE no longer falls with `q`, and the ratio to the PCRLB (computed for
#    the model, which does not know about the manoeuvre) rises above 1. A ratio above 1 is also
#    what any inefficient estimator shows (TSWLS, section 5); here, where EKF and UKF are
#    otherwise near-efficient, a rise above 1 points to a model mismatch.
# 2. The printed form resamples far more often and its RMSE is several times the default's: one
#    particle carries most of the weight, so the estimate is close to a single random draw that
#    drifts.
# 3. The filters predict through the gaps (with a warning) and lose only a little, since velocity
#    is well known; TSWLS repeats its last fix (the solution checks it), so on every missed epoch
#    it is off by the distance driven meanwhile, 1.4 m at 14 m/s.
#
# </details>

# %% [markdown]
# ## Checks

# %%
assert list(registry.family("jiang2023")) == ["TSWLS", "EKF", "UKF", "UPF"]
# section 1: T1 = 0.1 s and q = 0.1 m^2/s^3, as the prose says
assert m.period == 0.1 and m.q == 0.1
assert np.allclose(exp.P0, np.eye(4))  # the prior of section 1: 1 m^2 and 1 (m/s)^2 per axis
# section 2: the gate's threshold (18.5 for two stations), a 100 m range outlier skipped, and on
# clean runs the gate changes the EKF's RMSE by less than a per cent
assert m.n_stations == 2 and abs(chi2.ppf(0.999, 4) - 18.5) < 0.05
assert jump[None] > 3.0 and jump[0.999] < 1.5
assert abs(gate_rmse[0.999] / gate_rmse[None] - 1) < 0.01, gate_rmse
# section 6's baseline: every filter beats prediction alone by more than 5x in RMSE
assert min(radio_gain) > 5, radio_gain
assert all(ours[t, lv, PREDICTION_ONLY]["ours_rmse_m"] > 1 for t, lv in cases)  # metres off
# section 4: eq. 52 as printed gives one particle all the weight; the conditional proposal does not
assert ess_med["carried"] < 2.0 and ess_med["conditional"] > 0.1 * N_ESS, ess_med
# section 5, one fixed path: EKF, UKF and UPF below the bound (by less than 20 %), TSWLS 3-4x above
assert all(0.8 < ratio[n] < 1.0 for n in ("EKF", "UKF", "UPF")), ratio
assert 3.0 < ratio["TSWLS"] < 4.0, ratio
# the curved preset's lane change: +-0.24 m/s^2 lateral acceleration
assert abs(a_lat.max() - 0.24) < 0.01 and abs(a_lat.min() + 0.24) < 0.01, (a_lat.min(), a_lat.max())
# section 6, both tables, every level: filtering beats TSWLS by 2 to 4 times in mean error, the
# more the noisier the measurements; errors grow with the noise; LOS beats NLOS
assert 2.0 < min(tswls_factor.values()) and max(tswls_factor.values()) < 4.0, tswls_factor
for t in ("NLOS", "LOS"):
    for a in filt:
        assert tswls_factor[t, levels_d[-1], a] > tswls_factor[t, levels_d[0], a], (t, a)
for a in ("TSWLS", *filt):
    for t in ("NLOS", "LOS"):
        assert all(np.diff([mean_of[t, lv, a] for lv in levels_d]) > 0), (t, a)
    assert all(mean_of["LOS", lv, a] < mean_of["NLOS", lv, a] for lv in levels_d), a
# EKF and UKF within a few (5) per cent of each other; the UPF no better than the UKF beyond noise,
# between 3 % below and 6 % above it with 500 particles or more, further with fewer (a lost run)
assert max(abs(d) for d in ekf_ukf) < 0.05, ekf_ukf
assert min(upf_ukf) > -0.03 and max(upf_ukf) < (0.06 if PARTICLES >= 500 else 0.5), upf_ukf
# EKF and UKF: about 1.2 to 2.2 times sqrt(PCRLB) of the drive as simulated, above it at every
# level, furthest at the lowest noise
assert 1.15 < min(kf_bound) and max(kf_bound) < 2.3, kf_bound
kf_low = [
    ours[t, levels_d[0], a]["rmse_over_pcrlb"] for t in ("NLOS", "LOS") for a in ("EKF", "UKF")
]
kf_high = [
    ours[t, levels_d[-1], a]["rmse_over_pcrlb"] for t in ("NLOS", "LOS") for a in ("EKF", "UKF")
]
assert min(kf_low) > max(kf_high), (kf_low, kf_high)
# the curved and the LOS drive: the filters at 1.1 to 1.5 times their drive's bound, TSWLS 4-5x
for name in curves:
    assert all(1.1 < curves[name][n] < 1.5 for n in ("EKF", "UKF", "UPF")), curves
    assert 4.0 < curves[name]["TSWLS"] < 5.0, curves
# the paper's UPF means and TSWLS mean, as quoted, and the paper's RMSEs from its means and
# variances against the q -> 0 bound (at 0.1 m EKF and UKF above it, the UPF's a few per cent
# below; at 1 m and 2 m every filter's at 0.3 to 0.6 times it) while ours lie above it
assert (
    paper_t2["UPF", 0.1]["mean_m"] == 0.011
    and paper_t2["UPF", 2.0]["mean_m"] == 0.0742
    and paper_t2["TSWLS", 2.0]["mean_m"] == 0.333
)
assert set(bound0_rms) == {0.1, 1.0, 2.0} and len(exp.truth) == 100, bound0_rms
assert paper_over0[0.1, "EKF"] > 1.5 and paper_over0[0.1, "UKF"] > 1.5, paper_over0
assert 0.95 < paper_over0[0.1, "UPF"] < 1.0, paper_over0  # about 3 % below the bound
assert all(0.3 < paper_over0[sd, a] < 0.6 for sd in (1.0, 2.0) for a in filt), paper_over0
assert all(ours_over0[sd, a] > 1.0 for sd in levels_d for a in ("EKF", "UKF")), ours_over0
assert oracle_mean < 0.05  # (a) the oracle assumption yields centimetre "errors" like the paper's
assert np.abs(signed.mean(axis=(0, 1))).max() < 0.1  # (b) signed errors cancel to centimetres
# the paper's TSWLS RMSE (0.35 m) several (> 3) times below the snapshot bound's RMS; ours at
# that bound (within 10 %)
assert abs(paper_rmse["TSWLS", 2.0] - 0.35) < 0.005 and snap_rms > 3 * paper_rmse["TSWLS", 2.0]
assert abs(tswls_over_snap - 1) < 0.1, tswls_over_snap
# section 5: the bound for the noise-free preset (q -> 0) lies below the q = 0.1 one, and the
# same runs sit above it
assert np.allclose(bound0_6, bound0, rtol=1e-3)  # q = 1e-6 is q -> 0 to 0.1 %
assert np.all(bound0[1:] < bound[1:]) and all(ratio0[n] > 1.0 for n in ratio0), ratio0
# the bound is the yardstick for truths drawn from its own motion model: ratio 1 within 10 %
# (EKF, UKF; 15 % with quick mode's 12 runs), the UPF within 15 % (20 %) for its sampling; on the
# noise-free straight truth the same filters end below that ratio
tol = 0.15 if tk.quick_mode() else 0.10
assert all(abs(ratio_mm[n] - 1) < tol for n in ("EKF", "UKF")), ratio_mm
assert ratio_mm["UPF"] < 1 + tol + 0.05, ratio_mm
# a bound: no ratio below 1 by more than two Monte-Carlo standard errors
assert all(ratio_mm[n] > 1 - 2 * se_mm[n] for n in ratio_mm), (ratio_mm, se_mm)
assert all(ratio[n] < ratio_mm[n] for n in ("EKF", "UKF", "UPF")), (ratio, ratio_mm)
# the exercises' readings are asserted in their solutions (run in CI with TUNNELKIT_SOLUTIONS=1)

# %% [markdown]
# The check on the curve is left out on purpose: the manoeuvre is outside the constant-velocity
# model, so the ratio there measures model mismatch, not filter quality.
