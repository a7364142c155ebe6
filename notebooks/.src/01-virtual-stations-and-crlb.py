# %% [markdown]
# # 01 · Virtual stations and the Cramér–Rao bound
#
# *Jiang, Wang & Peng (2023), "A Single-Site Vehicle Positioning Method in the Rectangular Tunnel
# Environment", Remote Sensing 15, 527, [doi:10.3390/rs15020527](https://doi.org/10.3390/rs15020527),
# sections 2, 3 and 4.1, Appendix A.
# All references: `REFERENCES.md` at the top of the repository; terms and abbreviations: the
# [glossary](GLOSSARY.md).*
#
# **What you will learn**
#
# - why one base station is enough in a tunnel: each wall reflection behaves like a direct path
#   from a *virtual station*, the base station mirrored in the wall (eq. 3–4);
# - the joint TOA/DOA measurement model and its Fisher information (eq. 18–27) — and the sign
#   error in the paper's cross term, shown numerically;
# - where in the tunnel the Cramér–Rao bound (eq. 28) is small or large, with sliders;
# - what that bound bounds: the error of an *unbiased* estimator; a biased one can go below it
#   and has its own bound — the core of the workbook's [vocabulary of bounds](GLOSSARY.md#bounds);
# - how close least squares and the two-stage weighted least squares (TSWLS, eq. 29–39) get to
#   the bound;
# - why range (TOA) alone leaves a mirror ambiguity that the angle (DOA) resolves.

# %%
import numpy as np

import tunnelkit as tk
from tunnelkit import crlb, positioning, reflection
from tunnelkit.plots import line_figure, report_table, tunnel_topview
from tunnelkit.widgets import crlb_explorer, crlb_figure

tk.setup_notebook()

# %% [markdown]
# ## 1. The tunnel and its virtual stations
#
# The paper's tunnel (section 5) is bounded by two wall lines, $3x - 3y + 40 = 0$ and
# $3x - 3y - 23.6396 = 0$: a 15 m wide tube running at 45°, with the base station (BS) at the
# origin. A line $Ax + By + C = 0$ mirrors the BS $(x_b, y_b)$ into the virtual station (eq. 3)
#
# $$x_{v} = \frac{(B^2 - A^2)x_b - 2ABy_b - 2AC}{A^2 + B^2}, \qquad
#   y_{v} = \frac{(A^2 - B^2)y_b - 2ABx_b - 2BC}{A^2 + B^2}.$$
#
# `tunnelkit.geometry` mirrors with the vector form $p - 2(n\cdot p + c)\,n$; we check it against
# eq. 3 written out literally.

# %%
sc = tk.load_scenario("jiang2023-straight")
tunnel, bs = sc.tunnel(), sc.base_station()
vs = tunnel.virtual_stations(bs)


def eq3(A, B, C, xb, yb):
    den = A**2 + B**2
    return np.array(
        [
            ((B**2 - A**2) * xb - 2 * A * B * yb - 2 * A * C) / den,
            ((A**2 - B**2) * yb - 2 * A * B * xb - 2 * B * C) / den,
        ]
    )


vs_eq3 = np.array([eq3(3, -3, 40, *bs), eq3(3, -3, -23.6396, *bs)])
print("tunnel width [m]:", round(tunnel.width, 4))
print("virtual stations (package):\n", vs.round(4))
print("max |package - eq. 3| =", np.abs(vs - vs_eq3).max())

# %% [markdown]
# The reflected path BS → wall → vehicle has exactly the length of the straight line from the
# virtual station to the vehicle, and arrives from the same direction. That is the whole trick:
# the NLOS paths become LOS paths from two extra (virtual) transmitters.

# %%
traj = sc.trajectory(tunnel)
vehicle = traj.position[0]
for k, wall in enumerate(tunnel.walls):
    r = reflection.specular_point(bs, vehicle, wall)
    folded = np.linalg.norm(r - bs) + np.linalg.norm(vehicle - r)
    print(
        f"wall {k + 1}: reflection point {r.round(3)}, BS→wall→vehicle {folded:.6f} m, "
        f"|VS{k + 1} − vehicle| {np.linalg.norm(vehicle - vs[k]):.6f} m"
    )
tunnel_topview(tunnel, bs, vehicle=vehicle, trajectory=traj.position).show()

# %% [markdown]
# ## 2. Measurements and their Fisher information
#
# From station $i$ at $(x_{vi}, y_{vi})$ the receiver measures a range and a bearing (eq. 1–2, 5, 11)
#
# $$\hat d_i = \sqrt{(x - x_{vi})^2 + (y - y_{vi})^2} + n_{d_i}, \qquad
#   \hat\theta_i = \operatorname{atan2}(y - y_{vi},\, x - x_{vi}) + n_{\theta_i},$$
#
# with independent Gaussian errors of standard deviations $\sigma_d$ and $\sigma_\theta$. For
# Gaussian noise the Fisher information of $(x, y)$ is $F = \sum_i \nabla\theta_i\nabla\theta_i^T /
# \sigma_\theta^2 + \nabla d_i \nabla d_i^T / \sigma_d^2$ (eq. 20–24). The derivatives are
#
# $$\frac{\partial d_i}{\partial x} = \frac{x - x_{vi}}{d_i},\quad
#   \frac{\partial d_i}{\partial y} = \frac{y - y_{vi}}{d_i},\quad
#   \frac{\partial \theta_i}{\partial x} = -\frac{y - y_{vi}}{d_i^2},\quad
#   \frac{\partial \theta_i}{\partial y} = \frac{x - x_{vi}}{d_i^2}.$$
#
# **The paper's eq. A2 drops the minus sign** in $\partial\theta_i/\partial x$. $F_{xx}$ and
# $F_{yy}$ (eq. 25–26) are unaffected because the derivative appears squared, but the cross term is:
#
# $$F_{xy} = \sum_i \left( -\frac{(x - x_{vi})(y - y_{vi})}{\sigma_\theta^2 d_i^4}
#           + \frac{(x - x_{vi})(y - y_{vi})}{\sigma_d^2 d_i^2} \right)
# \quad\text{(corrected; eq. 27 prints } + \text{ on the first term).}$$
#
# First the derivative itself, by finite differences:

# %%
J_analytic = crlb.toa_doa_jacobian(vehicle, vs)
J_numeric = crlb.numeric_jacobian(
    lambda p: np.concatenate(crlb.toa_doa(p, vs), -1),
    vehicle,
    angle_mask=[False, False, True, True],
)
print("analytic dθ1/dx =", J_analytic[2, 0].round(6), " numeric =", J_numeric[2, 0].round(6))
print("max |analytic − numeric| over the Jacobian:", np.abs(J_analytic - J_numeric).max())

# %% [markdown]
# Now the three Fisher matrices at the start of the straight trajectory, for
# $\sigma_\theta = 0.5°$, $\sigma_d = 0.1$ m: the paper's printed form, the corrected closed form,
# and the brute-force $J^T R^{-1} J$ from finite differences (`crlb.numeric_fim`).

# %%
s_th, s_d = np.radians(0.5), 0.1
R = np.diag([s_d**2] * 2 + [s_th**2] * 2)
F_paper = crlb.fim_toa_doa(vehicle, vs, s_th, s_d, form="paper")
F_fixed = crlb.fim_toa_doa(vehicle, vs, s_th, s_d)
F_num = crlb.numeric_fim(
    lambda p: np.concatenate(crlb.toa_doa(p, vs), -1),
    vehicle,
    R,
    angle_mask=[False, False, True, True],
)
for name, F in [("paper eq. 27", F_paper), ("corrected", F_fixed), ("numeric", F_num)]:
    print(f"{name:13s} F_xy = {F[0, 1]:10.3f}   sqrt(CRLB) = {np.sqrt(crlb.crlb_trace(F)):.4f} m")

# %% [markdown]
# The corrected form matches brute force; the printed one does not. How much does the sign matter
# for the bound? Along the whole trajectory, as a ratio:

# %%
P = traj.position
b_paper = np.sqrt(crlb.crlb_trace(crlb.fim_toa_doa(P, vs, s_th, s_d, form="paper")))
b_fixed = np.sqrt(crlb.crlb_trace(crlb.fim_toa_doa(P, vs, s_th, s_d)))
line_figure(
    traj.t,
    {"paper / corrected sqrt(CRLB)": b_paper / b_fixed},
    title="Effect of the sign error on the bound along the straight trajectory",
    xaxis="t [s]",
    yaxis="ratio",
).show()
print(f"ratio range: {np.min(b_paper / b_fixed):.3f} … {np.max(b_paper / b_fixed):.3f}")

# %% [markdown] tags=["explorer"]
# ## 3. The bound over the whole tunnel
#
# For every **unbiased** estimator of the position — one whose mean is the true position — the
# Cramér–Rao lower bound (CRLB) holds, $\mathrm{Cov}(\hat p) \succeq F^{-1}$, and so
# $\mathrm{RMSE} \ge \sqrt{\operatorname{tr}(F^{-1})}$ (eq. 28, A17; the paper's section 3.3
# says "unbiased", eq. 28 does not repeat it; section 4 shows what the word excludes). Move the
# sliders: the angle term grows with distance ($\sigma_\theta d_i$ is a cross-range error in metres) while the range
# term does not, so far from the base station the bound is set by DOA. Tick *LOS path too* to add
# the direct path from the BS as a third station.

# %% tags=["explorer"]
crlb_explorer()

# %% [markdown]
# A static version of the same picture at the paper's largest noise level:

# %%
crlb_figure(sigma_theta_deg=2.0, sigma_d=2.0).show()

# %% [markdown]
# ## 4. Positioning: least squares and TSWLS against the bound
#
# Eq. 10 and 12 make the problem linear in $Z = [x,\ y,\ x^2 + y^2]^T$ (eq. 13–17):
#
# $$\underbrace{\begin{bmatrix} \hat d_i^2 - x_{vi}^2 - y_{vi}^2 \\ x_{vi}\sin\hat\theta_i - y_{vi}\cos\hat\theta_i \end{bmatrix}}_{H}
#  = \underbrace{\begin{bmatrix} -2x_{vi} & -2y_{vi} & 1 \\ \sin\hat\theta_i & -\cos\hat\theta_i & 0\end{bmatrix}}_{G} Z + N.$$
#
# Ordinary LS ignores that the rows have very different noise ($2 d_i n_{d_i}$ vs $d_i n_{\theta_i}$,
# eq. 29). TSWLS weights them with $W = BQB$ (eq. 30–32), then enforces $Z_3 = Z_1^2 + Z_2^2$ in a
# second WLS on the squares (eq. 33–38) and restores the signs (eq. 39).

# %%
runs = tk.mc_count(2000, 400)
scales = np.array([0.25, 0.5, 1.0, 2.0, 4.0, 8.0])  # multiples of (0.5 deg, 0.1 m)
rows = []
for s, rng in zip(scales, tk.montecarlo.spawn_rngs(1, len(scales))):
    sth, sd = s * np.radians(0.5), s * 0.1
    d_hat, th_hat = positioning.simulate_toa_doa(vehicle, vs, sth, sd, rng, size=runs)
    rows.append(
        [
            tk.metrics.rmse(positioning.ls_toa_doa(vs, d_hat, th_hat), vehicle),
            tk.metrics.rmse(positioning.tswls(vs, d_hat, th_hat, sd, sth), vehicle),
            float(crlb.crlb_rmse(vehicle, vs, sth, sd)),
        ]
    )
ls_r, tswls_r, bound = np.array(rows).T
fig = line_figure(
    scales,
    {"LS": ls_r, "TSWLS": tswls_r, "CRLB": bound},
    log_y=True,
    title=f"RMSE vs noise ({runs} trials per point)",
    xaxis="noise scale × (0.5°, 0.1 m)",
    yaxis="RMSE [m]",
    dash={"CRLB": "dash"},
)
fig.update_xaxes(type="log").show()
print("TSWLS / CRLB:", (tswls_r / bound).round(3), "  LS / CRLB:", (ls_r / bound).round(2))

# %% [markdown]
# TSWLS sits on the bound (its RMSE within 5 % of it at every noise level, the ratios printed
# above; a ratio just below 1 is the Monte-Carlo scatter of a sample of this size, not a breach
# of the bound); plain LS is about twice as far off, because it lets the noisier range rows
# dominate.
# The command line prints the same comparison at the paper's three noise levels:
# `tunnelkit reproduce jiang-crlb` (add `--format json` for machine-readable output).

# %%
rep = tk.reproduce.run("jiang-crlb", runs=runs, seed=0)
report_table(rep)

# %% [markdown]
# ### What the bound bounds, and what it does not
#
# The comparison above is fair because LS and TSWLS are (nearly) unbiased here. An estimator
# with a bias $b(p) = \mathrm E[\hat p] - p$ is not held by eq. 28. Its covariance is held by
# the **biased CRB**, and its mean-square error by that plus the squared bias:
#
# $$\mathrm{Cov}(\hat p) \succeq \Big(I + \frac{\partial b}{\partial p}\Big)\, F^{-1}
#   \Big(I + \frac{\partial b}{\partial p}\Big)^{T}, \qquad
#   \text{one parameter: } \mathrm{var}(\hat\theta) \ge
#   \frac{(1 + \partial b/\partial\theta)^2}{J(\theta)} .$$
#
# The simplest biased estimator shrinks TSWLS towards a guess $g$:
# $\hat p_s = g + c\,(\hat p - g)$ with $c = 1/2$. Its bias is $(c - 1)(p - g)$, so
# $\partial b/\partial p = (c - 1) I$ and its variance bound is $c^2 \operatorname{tr}F^{-1}$,
# a quarter of eq. 28's. At $(0.5°, 0.1\text{ m})$, with a guess 10 cm and then 1 m from the
# truth:

# %%
c_shrink = 0.5
d_hat, th_hat = positioning.simulate_toa_doa(
    vehicle, vs, s_th, s_d, tk.montecarlo.spawn_rngs(2, 1)[0], size=runs
)
p_tswls = positioning.tswls(vs, d_hat, th_hat, s_d, s_th)
crlb_1 = float(crlb.crlb_rmse(vehicle, vs, s_th, s_d))  # eq. 28 at this noise level
bias_tswls = float(np.linalg.norm(p_tswls.mean(0) - vehicle))
bias_ls = float(np.linalg.norm(positioning.ls_toa_doa(vs, d_hat, th_hat).mean(0) - vehicle))
print(f"TSWLS: bias {bias_tswls:.4f} m, RMSE {float(tk.metrics.rmse(p_tswls, vehicle)):.3f} m")
print(f"LS: bias {bias_ls:.4f} m (eq. 28 at this noise level: {crlb_1:.3f} m)")
shrunk = {}
for miss in (0.1, 1.0):
    g = vehicle + np.array([miss, 0.0])  # the guess, `miss` metres from the truth
    p_s = g + c_shrink * (p_tswls - g)
    shrunk[miss] = {
        "rmse": float(tk.metrics.rmse(p_s, vehicle)),
        "spread": float(np.sqrt(np.var(p_s, axis=0).sum())),
        "bias": float(np.linalg.norm(p_s.mean(0) - vehicle)),
    }
    print(
        f"guess {miss:3.1f} m off: RMSE {shrunk[miss]['rmse']:.3f} m (eq. 28: {crlb_1:.3f} m), "
        f"spread {shrunk[miss]['spread']:.4f} m (biased CRB: {c_shrink * crlb_1:.4f} m), "
        f"bias {shrunk[miss]['bias']:.3f} m"
    )

# %% [markdown]
# With the guess 10 cm off, the shrunk estimate's RMSE is *below* eq. 28 — no contradiction:
# eq. 28 does not apply to a biased estimator — and its spread sits on its own, biased bound
# (to within the sample's Monte-Carlo scatter).
# With the guess 1 m off, the bias costs far more than the shrinking saved. A good guess is
# prior information, and the bound that counts a prior is the Bayesian (posterior) CRLB of
# notebooks 05 and 06: an average over random truths, so a filter can go below it on one drive.
#
# Two more things to carry through the workbook. The CRLB is **local**: it uses only the
# curvature of the likelihood at the truth. Past a *threshold* (too little SNR, paths too close),
# maximum likelihood now and then picks a wrong peak and its error jumps far above the CRLB: the
# bound still holds, ML just stops attaining it (notebook 03). And a figure is called a bound
# only where it bounds the quantity shown beside it. The glossary's
# [Bounds](GLOSSARY.md#bounds) part defines, once, every bound the notebooks use: the
# [CRLB](GLOSSARY.md#crlb) and [biased CRB](GLOSSARY.md#biased-crb), the
# [threshold](GLOSSARY.md#threshold), the [posterior CRLB](GLOSSARY.md#pcrlb), the
# [misspecified CRB](GLOSSARY.md#mcrb) of notebooks 07 and 08, the
# [Ziv–Zakai bound](GLOSSARY.md#ziv-zakai) (a bound at every SNR) and the
# [method of interval errors](GLOSSARY.md#mie) (an approximation).

# %% [markdown]
# ## 5. The mirror ambiguity of TOA alone
#
# Both walls are parallel to the tunnel axis, so both virtual stations lie on one line through
# the BS, perpendicular to the walls. Two range circles centred on that line meet in two points,
# mirror images in it: TOA alone cannot say whether the vehicle is before or behind the base
# station. One bearing decides.

# %%
d_true, th_true = crlb.toa_doa(vehicle, vs)
cands = positioning.toa_only_candidates(vs, d_true)
pick = cands[
    np.argmin([np.abs(crlb.wrap_angle(crlb.toa_doa(c, vs)[1] - th_true)).sum() for c in cands])
]
print("TOA-only candidates:\n", cands.round(3), "\nDOA picks:", pick.round(3))
fig = tunnel_topview(tunnel, bs, title="TOA alone: two candidates; DOA picks the true one")
fig.add_scatter(
    x=cands[:, 0],
    y=cands[:, 1],
    mode="markers",
    name="TOA candidates",
    marker={"size": 12, "symbol": "x"},
)
fig.add_scatter(
    x=[pick[0]],
    y=[pick[1]],
    mode="markers",
    name="with DOA",
    marker={"size": 16, "symbol": "circle-open", "line": {"width": 3}},
)
fig.show()

# %% [markdown]
# The local picture is different: near the line of the stations the two circles cross at a grazing
# angle and the TOA-only Fisher information becomes singular, while with DOA it stays well
# conditioned.

# %%
along = np.linspace(-20, 20, 81)
pts = tunnel.from_tunnel_frame(
    np.stack([tunnel.to_tunnel_frame(bs)[0] + along, np.full_like(along, 7.5)], -1)
)
cond_toa = np.linalg.cond(crlb.fim_toa_doa(pts, vs, None, 0.1))
cond_both = np.linalg.cond(crlb.fim_toa_doa(pts, vs, np.radians(0.5), 0.1))
line_figure(
    along,
    {"TOA only": cond_toa, "TOA + DOA": cond_both},
    log_y=True,
    title="Condition number of F across the station line",
    xaxis="along the tunnel from the BS [m]",
    yaxis="cond(F)",
).show()

# %% [markdown]
# ## Exercises
#
# 1. Where in the tunnel is the bound smallest for $(\sigma_\theta, \sigma_d) = (2°, 2\text{ m})$,
#    and why is it not at the base station?
# 2. Add the LOS path. By how much does the median bound drop at $(0.5°, 0.1\text{ m})$?
# 3. Drop the DOA (`sigma_theta=None`) and find the along-tunnel positions where the TOA-only bound
#    exceeds 10 m.
#
# The solutions are the collapsed cells below, and Run All does not run them. Once you have
# tried an exercise, click the "Run solution" button under its solution (or run
# `tk.solution("01.2")` in a cell, for exercise 2): the solution runs on a copy of the
# notebook's variables, so it changes none of yours, and shows what it prints. A cell's blue
# bar shows its code. On the static site the solutions have already run: open one, then its
# "Show the solution's output". What to read in them follows.

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 01.1
# Solution 1: where is the bound smallest at (2 deg, 2 m)?
from tunnelkit.widgets.crlb import crlb_map

al, ac, rm = crlb_map(tunnel, vs, np.radians(2.0), 2.0)
i_min, j_min = np.unravel_index(np.nanargmin(rm), rm.shape)
j_bs = int(np.argmin(np.abs(al - tunnel.to_tunnel_frame(bs)[0])))
print(
    f"smallest bound {rm[i_min, j_min]:.2f} m at {al[j_min]:.0f} m along, {ac[i_min]:.1f} m "
    f"across; best at the BS's along position: {np.nanmin(rm[:, j_bs]):.2f} m"
)
assert abs(al[j_min] - al[j_bs]) > 2.0 and rm[i_min, j_min] < np.nanmin(rm[:, j_bs])

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 01.2
# Solution 2: the LOS path added (the BS as a third station), median over the map
from tunnelkit.widgets.crlb import crlb_map

med = {
    name: float(np.nanmedian(crlb_map(tunnel, st, np.radians(0.5), 0.1)[2]))
    for name, st in (("NLOS", vs), ("LOS", np.vstack([bs, vs])))
}
print(
    f"median bound at (0.5 deg, 0.1 m): NLOS {med['NLOS']:.3f} m, LOS {med['LOS']:.3f} m "
    f"({100 * (1 - med['LOS'] / med['NLOS']):.0f} % lower)"
)
assert med["LOS"] < med["NLOS"]

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 01.3
# Solution 3: TOA only, along the line of the last figure (offset so as not to sit exactly on
# the station line, where the information is singular)
along3 = np.linspace(-20.05, 19.95, 401)
pts3 = tunnel.from_tunnel_frame(
    np.stack([tunnel.to_tunnel_frame(bs)[0] + along3, np.full_like(along3, 7.5)], -1)
)
b_toa = crlb.crlb_rmse(pts3, vs, None, 0.1)
above = along3[b_toa > 10]
print(
    f"TOA-only bound above 10 m for {above.min():+.2f}..{above.max():+.2f} m along the tunnel "
    f"(step 0.1 m); largest {b_toa.max():.1f} m, at 1 m from the line "
    f"{b_toa[np.argmin(np.abs(along3 - 1.0))]:.2f} m"
)
# above 10 m only within about a decimetre of the line, below it a metre away
assert above.size and np.abs(above).max() < 0.15 and b_toa[np.argmin(np.abs(along3 - 1.0))] < 10

# %% [markdown]
# <details><summary>What to read in the solutions</summary>
#
# 1. Not at the base station: near the stations' line (across the tunnel at the BS) the range
#    gradients of the two virtual stations are (anti)parallel, so range says little about the
#    along-track coordinate. The smallest bound lies some metres along the tunnel, where range and
#    bearing gradients are closest to orthogonal.
# 2. The direct path is the shortest, so its bearing is the most informative: the median drops
#    by the percentage printed.
# 3. The singularity is sharp: the TOA-only bound passes 10 m only within about a decimetre of the
#    station line and is below it a metre away.
#
# </details>

# %% [markdown]
# ## Checks

# %%
assert np.abs(vs - vs_eq3).max() < 1e-12
assert np.allclose(vs, [[-13.3333, 13.3333], [7.8799, -7.8799]], atol=1e-3)
assert np.allclose(J_analytic, J_numeric, rtol=1e-6, atol=1e-9)
assert np.allclose(F_fixed, F_num, rtol=1e-6)
assert not np.allclose(F_paper, F_num, rtol=1e-3), (
    "the printed eq. 27 should differ from brute force"
)
eff = tswls_r / bound
assert np.all(np.abs(eff - 1) < 0.05), eff  # TSWLS on the bound over the noise sweep (5 %)
assert np.all((ls_r / bound > 1.7) & (ls_r / bound < 2.3)), ls_r / bound  # LS: about twice
# a biased (shrunk) estimate: below eq. 28 with a good guess, on its biased CRB, far off with a
# bad guess
near, far = shrunk[0.1], shrunk[1.0]
assert near["rmse"] < 0.8 * crlb_1 and far["rmse"] > 3 * crlb_1
assert all(0.9 < s["spread"] / (c_shrink * crlb_1) < 1.1 for s in (near, far))
assert bias_tswls < 0.15 * crlb_1  # TSWLS: (nearly) unbiased, so eq. 28 applies to it
assert bias_ls < 0.15 * crlb_1  # LS as well: its excess is variance, not bias
assert all(abs(shrunk[m]["bias"] - (1 - c_shrink) * m) < 0.1 * crlb_1 for m in shrunk)  # (c-1)(p-g)
assert np.allclose(cands[0], vehicle, atol=1e-6) or np.allclose(cands[1], vehicle, atol=1e-6)
assert np.allclose(pick, vehicle, atol=1e-6)
assert cond_toa.max() > 1e3 * cond_both.max()
# the exercises' readings are asserted in their solutions (run in CI with TUNNELKIT_SOLUTIONS=1)
print("all checks passed")
