# %% [markdown]
# # 02 · When does a reflection stop looking like one point? SR-NF validity and $M_{\max}$
#
# *Italiano, Brambilla & Nicoli (2026), "In-Tunnel Single-Anchor Localization Exploiting Near-Field
# and Radio-Reflective Road Markings", [arXiv:2604.04217](https://arxiv.org/abs/2604.04217v1),
# section 3.1 (Theorems 3.1 and 3.4, eq. 25–42) and section 4.2.
# All references: `REFERENCES.md` at the top of the repository; terms and abbreviations: the
# [glossary](GLOSSARY.md).*
#
# **What you will learn**
#
# - what the single-reflector near-field (SR-NF) channel model assumes about a wall-reflected path,
#   and why it breaks when the array grows;
# - the proof of Theorem 3.1 step by step (eq. 26 → 34), each approximation checked numerically
#   against the exact geometry as it is made;
# - the paper's design example ($M_{\max} = 9.88$, so $M = 100$) and what the *exact* phase mismatch
#   says about it;
# - where the paper's closed forms (eq. 25, eq. 37, which it calls upper bounds) are tight, where
#   they are loose or too large, and a corrected second-order expression that, rounded down,
#   gives the exact $M_{\max}$ or one antenna more (an expansion, not a bound);
# - what $M_{\max}$ is and is not: the validity condition of one estimator, the one built on the
#   SR-NF model (eq. 51), not a rule for sizing an array (notebook 08 asks that question); its
#   tables for 5.9 GHz and 28 GHz tunnels with planar side walls, with sliders and with
#   `tunnelkit mmax` on the command line.

# %%
import numpy as np

import tunnelkit as tk
from tunnelkit import fresnel, geometry, reflection
from tunnelkit.constants import C, wavelength
from tunnelkit.plots import (
    derivation_figure,
    fresnel_topview,
    mismatch_figure,
    mmax_range_figure,
    ratio_map_figure,
    report_table,
)
from tunnelkit.signal_route import SignalRoute
from tunnelkit.widgets import mmax_explorer, mmax_figure

tk.setup_notebook()

# %% [markdown]
# ## 1. The setting: one wall, one UE, its virtual UE
#
# The base station's reference antenna sits at the origin; the tunnel runs along $x$. A ULA of
# $M$ antennas lies across the tunnel at $y_m = m d$, $d = \lambda/2$. The reflecting wall is the
# plane $y = W$; the UE is at $(R, y_u)$ with $y_u < W$. By the image method the wall-reflected
# path to antenna $m$ is as long as the straight line from the **virtual UE** (VUE)
#
# $$\mathbf p_v = (R,\; 2W - y_u).$$
#
# The SR-NF model (Italiano et al., after [TeNFiLoc](GLOSSARY.md#tenfiloc), the snapshot method of notebook 04) describes the same path instead as a spherical
# wave from **one point on the wall**, $\mathbf p_{s,0}$, the specular point of the reference
# antenna. For a small array the two pictures agree; for a large one the wavefront across the
# array is visibly centred on the VUE, not on the wall. The figure is Fig. 2 of the paper
# (`tunnelkit.plots.fresnel_topview`); the paper's design example is $R = 3.5$ m, $W = 3$ m,
# $y_u = 2.5$ m at $f_c = 5.9$ GHz with $\varepsilon_\Phi = 0.15$ rad (section 4.2).

# %%
R, W, y_u, fc, eps = 3.5, 3.0, 2.5, 5.9e9, 0.15
lam = wavelength(fc)
print(f"lambda = {lam * 100:.3f} cm, spacing d = {lam / 2 * 100:.3f} cm")
print(
    "VUE p_v =",
    fresnel.vue(R, W, y_u),
    " reflector p_s0 =",
    fresnel.reference_specular_point(R, W, y_u).round(4),
)
fresnel_topview(10, R, W, y_u, fc).show()

# %% [markdown]
# ## 2. The proof of Theorem 3.1, one step at a time
#
# ### Eq. 26–27: exact path lengths via the VUE
#
# $$d_{v,0} = \sqrt{R^2 + (2W - y_u)^2}, \qquad d_{v,m} = \sqrt{R^2 + (2W - y_u - y_m)^2}.$$
#
# Check: fold each path at *its own* specular point on the wall (`reflection.specular_point`) and add
# the two segments UE → wall → antenna; it must equal $d_{v,m}$.

# %%
M = 100
prof = fresnel.aperture_profile(M, R, W, y_u, fc)
ue = np.array([R, y_u])
ant = np.column_stack([np.zeros(M), prof.y])
wall = geometry.line(0.0, 1.0, -W)  # y - W = 0
s = reflection.specular_point(ue, ant, wall)
folded = np.linalg.norm(s - ue, axis=1) + np.linalg.norm(ant - s, axis=1)
err_2627 = np.abs(folded - prof.d_v).max()
print(f"max |folded path - d_v,m| over {M} antennas: {err_2627:.2e} m")

# %% [markdown]
# ### Eq. 28: the Fresnel expansion of the true path difference
#
# For $|y_m| \ll R$ the paper expands
#
# $$\delta^*_m = d_{v,m} - d_{v,0} \approx \frac{y_m^2 - 2(2W - y_u)\,y_m}{2R}. \tag{28}$$
#
# That step silently needs more than $|y_m| \ll R$: the denominator $d_{v,m} + d_{v,0}$ is replaced
# by $2R$, which is only accurate if $|2W - y_u| \ll R$ too (the **paraxial** assumption). In the
# design example $2W - y_u = 3.5\text{ m} = R$. Phase errors $\frac{2\pi}{\lambda}(\cdot)$ of the
# expansion at a few antennas:

# %%
k = 2 * np.pi / lam
err28 = k * (prof.delta_star_fresnel - prof.delta_star)
for m in (1, 9, 14, 99):
    print(
        f"m = {m:3d}: exact delta* = {prof.delta_star[m] * 100:8.3f} cm, "
        f"eq. 28 phase error {err28[m]:8.3f} rad"
    )

# %% [markdown]
# Already at the second antenna the expansion is off by far more than $\varepsilon_\Phi = 0.15$
# rad: eq. 28 gets the *linear* term wrong ($2(2W-y_u)y_m/(2R)$ instead of
# $(2W - y_u) y_m / d_{v,0}$, i.e. $\sin$ of the arrival angle replaced by $\tan$). The proof
# survives only because the same mistake is made in eq. 31 and cancels in eq. 33, as we check
# next.
#
# ### Eq. 29–32: the single reflector
#
# $$d_{p_0,m} = \sqrt{x_{p_0}^2 + (W - y_m)^2}, \qquad x_{p_0} = R\,\frac{W}{2W - y_u}, \tag{29–32}$$
#
# $$\delta^{SR}_m = d_{p_0,m} - d_{p_0,0} \approx \frac{y_m^2 - 2W y_m}{2 x_{p_0}}. \tag{31}$$

# %%
p0 = reflection.specular_point(ue, np.zeros(2), wall)  # reflection point seen by antenna 0
print(f"eq. 32: x_p0 = {prof.x_p0:.6f} m, specular point from geometry: {p0.round(6)}")
err31 = k * (prof.delta_sr_fresnel - prof.delta_sr)
print("eq. 31 phase error at m = 1, 9, 99:", err31[[1, 9, 99]].round(3), "rad")
lin28 = -2 * (2 * W - y_u) / (2 * R)  # coefficient of y_m in eq. 28
lin31 = -2 * W / (2 * prof.x_p0)  # coefficient of y_m in eq. 31 with eq. 32
print(f"linear coefficients: eq. 28 {lin28:.6f}, eq. 31 {lin31:.6f}")

# %% [markdown]
# ### Eq. 33–34: the linear terms cancel, a quadratic error remains
#
# $$\Delta\delta_m = \delta^*_m - \delta^{SR}_m \approx -\frac{W - y_u}{2RW}\, y_m^2, \qquad
# \frac{2\pi}{\lambda}\,\frac{|W - y_u|}{2RW}(M-1)^2 d^2 \le \varepsilon_\Phi. \tag{33, 34}$$
#
# Within the expansions the cancellation is exact (eq. 28 − eq. 31 *is* eq. 33). Against the exact
# mismatch, eq. 33 is too large by a factor that drifts slowly along the array — about 2.8 at the
# second antenna, 2.6 at the tenth, 1.4 at the hundredth (printed below): the paraxial error that
# cancelled in the linear term does not cancel in the quadratic one:

# %%
cancel = np.abs(k * (prof.delta_star_fresnel - prof.delta_sr_fresnel) - prof.mismatch_paraxial)
print(f"max |(eq. 28 - eq. 31) - eq. 33| = {cancel.max():.1e} rad")
print(
    "eq. 33 / exact mismatch at m = 1, 9, 99:",
    (prof.mismatch_paraxial[[1, 9, 99]] / prof.mismatch[[1, 9, 99]]).round(3),
)
derivation_figure(fresnel.aperture_profile(16, R, W, y_u, fc), lam=lam).show()

# %% [markdown]
# Solving eq. 34 with $d = \lambda/2$ for $M$ gives Theorem 3.1:
#
# $$M_{\max} \le 1 + 2\sqrt{\frac{R\,W\,\varepsilon_\Phi}{\lambda\,|W - y_u|\,\pi}}. \tag{25}$$
#
# The paper calls eq. 25 an upper bound on $M_{\max}$. It is one within the expansions it is
# derived from (eq. 28 and 31); against the exact mismatch it falls on either side — from 0.06
# to 1.08 times the exact value on the map of section 4 — so read eq. 25, and eq. 37 below, as
# approximations of $M_{\max}$, "bound" being the paper's name for them.
#
# ## 3. The paper's design example
#
# Section 4.2: $R = 3.5$ m, $W = 3$ m, $y_u = 2.5$ m, $\varepsilon_\Phi = 0.15$ rad at 5.9 GHz give
# $M_{\max} = 9.88$, and the simulations use a URA of $M = M_{\max}^2 \approx 100$ antennas
# ($10 \times 10$). `fresnel.mmax_exact` finds the largest ULA whose **exact** mismatch
# $\max_m \frac{2\pi}{\lambda}|\delta^*_m - \delta^{SR}_m|$ stays within $\varepsilon_\Phi$ (no
# expansion at all); `fresnel.mmax_exact_ura` does the same for the $M\times M$ URA of section 4.1
# (looking along the tunnel, tilted 30° down).

# %%
m25 = fresnel.mmax_2d(R, W, y_u, fc, eps)
edge34 = k * abs(W - y_u) / (2 * R * W) * ((m25 - 1) * lam / 2) ** 2  # eq. 34 at M = eq. 25
m_exact = fresnel.mmax_exact(R, W, y_u, fc, eps)
m_ura = fresnel.mmax_exact_ura(R, W, y_u, fc, eps)
print(f"eq. 25: Mmax = {m25:.2f} (eq. 34 there: {edge34:.4f} rad), M = {round(m25) ** 2}")
print(f"eq. 25 / exact ULA Mmax: {m25 / m_exact:.2f}")
print(
    f"exact ULA: Mmax = {m_exact}   (mismatch {fresnel.phase_mismatch(m_exact, R, W, y_u, fc):.4f}"
    f" rad; with {m_exact + 1}: {fresnel.phase_mismatch(m_exact + 1, R, W, y_u, fc):.4f} rad)"
)
mis0 = fresnel.phase_mismatch_ura(10, R, W, y_u, fc)
print(f"exact URA (section 4.1): {m_ura} x {m_ura};  10 x 10 mismatch {mis0:.4f} rad")
z_anchor = -3.3  # UE antenna at 1.5 m, 3.3 m below the paper's 4.8 m anchor
m_ura33 = fresnel.mmax_exact_ura(R, W, y_u, fc, eps, z_u=z_anchor)
mis33 = fresnel.phase_mismatch_ura(10, R, W, y_u, fc, z_u=z_anchor)
print(f"same, UE 3.3 m below the array: {m_ura33} x {m_ura33};  10 x 10 mismatch {mis33:.4f} rad")

# %% [markdown]
# In the theorem's own 2-D geometry — the UE in the plane of the array, $z_u = 0$ — the paper's
# choice holds with room to spare: the exact ULA tolerates the number of antennas printed above,
# more than eq. 25's, and the $10 \times 10$ URA stays within $\varepsilon_\Phi$. Eq. 25 is
# **conservative** here because the example lies outside its paraxial assumption:
# $(2W - y_u)/R = 1$, not $\ll 1$.
#
# That holds for $z_u = 0$ only. With the paper's anchor at 4.8 m and a UE antenna at 1.5 m (the
# workbook's preset; the paper gives no antenna height) the UE is 3.3 m below the array, and
# then the exact URA tolerates only $9 \times 9$: the $10 \times 10$ mismatch is 0.172 rad, above
# $\varepsilon_\Phi = 0.15$ rad (the last line above). Section 4's table repeats the check for
# each of its rows.
#
# Two more limits on this verdict. **It is about one estimator.** $M_{\max}$ says where the SR-NF
# model — a reflected path's curvature read as the distance to its reflection point, eq. 51 —
# stops describing the channel. An estimator built on eq. 51 needs it; one that models each
# reflected wavefront as centred on its VUE does not. It is the validity condition of that
# estimator, not a rule for sizing an array: how many antennas a tunnel needs is notebook 08's
# question (its section on SR-NF validity says the same).
#
# **It is about one surface**, the planar vertical side wall of the theorem. The tunnel of
# section 4.1 is a semicircular tube, 10 m wide and 5 m high, and a semicircle is vertical only
# at road level. The reflections the package finds along the paper's two drives (computed below)
# include no vertical wall: on the straight drive the ceiling, the road and the RRMs; on the
# slalom, at some epochs, also a wall facet, but more than 3 m above the road and tilted more
# than 30° from the vertical (printed below). The reflection that
# binds is the **ceiling**: its reflection point is close to the array, so its SR-NF mismatch is
# far larger, and the same $10 \times 10$ URA is not SR-NF-valid for it at any epoch of the
# straight drive (notebook 08 sweeps every surface along the drive; notebook 07 shows the
# array's upper elements against the faceted ceiling; notebook 03 shows what it means for the
# estimate of $\kappa$). The largest exact SR-NF phase mismatch over the $10 \times 10$ aperture,
# per reflecting surface, over every epoch of the straight drive (`italiano2026-straight`), and
# the wall reflections of the slalom drive (`italiano2026-slalom`):

# %%
route = SignalRoute.from_scenario("italiano2026-straight")
mism = {}
for kk in range(len(route.trajectory)):
    for path in route.paths(kk)[1]:
        if path.kind == "reflection":
            dd = np.max(np.abs(path.delta("exact") - path.delta("srnf")))
            mism.setdefault(path.surface_kind, []).append(2 * np.pi * route.config.fc / C * dd)
for surf, v in mism.items():
    v = np.array(v)
    print(
        f"{surf:8s} {v.min():7.3f}-{v.max():7.3f} rad; within eps_Phi = {eps} rad on "
        f"{np.mean(v <= eps):.0%} of its {v.size} path-epochs"
    )
slalom = SignalRoute.from_scenario("italiano2026-slalom")
facets = {f.name: f for f in slalom.tunnel.facets}


def tilt_deg(facet):
    """A facet's tilt from the vertical [deg] (0 for a vertical wall)."""
    return float(np.degrees(np.arcsin(abs(facet.normal[2]))))


wall_hits = [
    (kk, path.surface, float(path.point[2]), tilt_deg(facets[path.surface]))
    for kk in range(len(slalom.trajectory))
    for path in slalom.paths(kk)[1]
    if path.kind == "reflection" and path.surface_kind == "wall"
]
hit_z, hit_tilt = np.array([h[2] for h in wall_hits]), np.array([h[3] for h in wall_hits])
print(
    f"slalom: wall reflections at {len({h[0] for h in wall_hits})} of {len(slalom.trajectory)} "
    f"epochs, on {sorted({h[1] for h in wall_hits})}, tilted {hit_tilt.min():.1f}-"
    f"{hit_tilt.max():.1f} deg from the vertical, {hit_z.min():.2f}-{hit_z.max():.2f} m high"
)
near_vertical = [f for f in facets.values() if f.kind == "wall" and tilt_deg(f) < 10]
top_vertical = max(f.corners()[:, 2].max() for f in near_vertical)
print(f"facets within 10 deg of the vertical reach {top_vertical:.2f} m above the road")

# %% [markdown]
# ## 4. The honest comparison: closed forms vs exact geometry
#
# ### A corrected second-order expression
#
# The VUE and the reference specular point lie on **one ray** from the origin, at distances
# $\rho = \|\mathbf p_v\|$ (eq. 35) and $\rho_s = \rho W/(2W - y_u)$. Expanding both path
# differences to second order in the aperture (eq. 40 for each source) the linear terms
# $-\mathbf u^{\mathsf T}\mathbf p_m$ cancel exactly, without any paraxial assumption, and
#
# $$\Delta\delta_m \approx \frac{\|\mathbf P^\perp_{\mathbf U}\mathbf p_m\|^2}{2}
#   \Big(\frac1\rho - \frac1{\rho_s}\Big) = -\frac{W - y_u}{2\rho W}\,
#   \|\mathbf P^\perp_{\mathbf U}\mathbf p_m\|^2 .$$
#
# For the ULA, $\|\mathbf P^\perp_{\mathbf U}\mathbf p_m\|^2 = y_m^2 (R^2 + z_u^2)/\rho^2$, so
#
# $$M_{\max} \approx 1 + 2\sqrt{\frac{\varepsilon_\Phi\,\rho^3\, W}{\lambda\,\pi\,|W - y_u|\,(R^2 + z_u^2)}}
#   \quad\xrightarrow{\ \rho \to R\ }\quad \text{eq. 25.}$$
#
# (`fresnel.mmax_nonparaxial`). Compare eq. 41 as printed, $|\Delta\delta_m| \approx
# \|\mathbf P^\perp\mathbf p_m\|^2/(2\rho)$: it keeps the true wavefront's curvature and drops the
# SR model's own, i.e. it compares the VUE wavefront with a *plane* wave. Far from the anchor, eq.
# 37 is therefore conservative by $\sqrt{W/(W - y_u)}$ for $0 \le y_u < W$ but **optimistic**
# (too many antennas) when the UE is on the far side of the array, $y_u < 0$; close to the anchor
# the projection $\|\mathbf P^\perp\mathbf p_m\| = (M-1)d\,R/\rho < (M-1)d$ makes it conservative
# again.

# %%
mismatch_figure(m_exact, R, W, y_u, fc, eps).show()
for rr, yy in ((3.5, 2.5), (3.5, -3.0), (30.0, 2.5), (30.0, -3.0)):
    print(
        f"R = {rr:4.1f}, y_u = {yy:4.1f}: eq. 25 {fresnel.mmax_2d(rr, W, yy, fc, eps):6.2f}, "
        f"eq. 37 {fresnel.mmax_3d([rr, 2 * W - yy, 0.0], fc, eps):6.2f}, "
        f"2nd order {fresnel.mmax_nonparaxial(rr, W, yy, fc, eps):6.2f}, "
        f"exact {fresnel.mmax_exact(rr, W, yy, fc, eps):3d}"
    )

# %% [markdown]
# ### Where is eq. 25 tight? A map over $(R, y_u)$
#
# Ratio of eq. 25 to the exact $M_{\max}$ over distance and UE position (5.9 GHz, $W = 3$ m,
# $\varepsilon_\Phi = 0.15$ rad), on a log colour scale centred on 1: white is tight, **red** is a
# ratio below 1 — the closed form allows fewer antennas than the exact limit, which is
# *conservative* (safe) — and **blue** a ratio above 1, a closed form that allows more antennas
# than the geometry tolerates (*unsafe*). The paper's example in section 4.2 (ratio 0.66) is red.
# `fresnel.mmax_exact_grid` computes the exact value for the whole grid at once.

# %%
R_grid = np.geomspace(1.0, 300.0, 70)
y_grid = np.linspace(-5.0, W - 0.05, 60)
exact_map = fresnel.mmax_exact_grid(R_grid[None, :], W, y_grid[:, None], fc, eps)
ratio25 = fresnel.mmax_2d(R_grid[None, :], W, y_grid[:, None], fc, eps) / exact_map
pv_grid = np.stack(np.broadcast_arrays(R_grid[None, :], 2 * W - y_grid[:, None], 0.0), -1)
ratio37 = fresnel.mmax_3d(pv_grid, fc, eps) / exact_map
ratio_map_figure(
    R_grid,
    y_grid,
    ratio25,
    title="eq. 25 / exact Mmax (5.9 GHz, W = 3 m)",
    W=W,
    colorbar_title="eq. 25 / exact",
).show()
ratio_map_figure(
    R_grid,
    y_grid,
    ratio37,
    title="eq. 37 / exact Mmax (5.9 GHz, W = 3 m)",
    W=W,
    colorbar_title="eq. 37 / exact",
).show()
far = R_grid >= 100
floor_gap = np.floor(fresnel.mmax_2d(R_grid[far], W, y_grid[:, None], fc, eps)) - exact_map[:, far]
print(f"R >= 100 m: eq. 25 / exact in [{ratio25[:, far].min():.3f}, {ratio25[:, far].max():.3f}]")
print(f"R >= 100 m: floor(eq. 25) - exact in [{floor_gap.min():.0f}, {floor_gap.max():.0f}]")
print(f"eq. 25 / exact: from {ratio25.min():.3f} to {ratio25.max():.3f} over the map")
print(f"eq. 37 / exact > 1.05 (unsafe) on {np.mean(ratio37 > 1.05):.0%} of the map")
print(
    f"eq. 37 / exact < 0.95 on {np.mean(ratio37 < 0.95):.0%} of the map; > 1.05 on "
    f"{np.mean(ratio37[y_grid < 0] > 1.05):.0%} of its y_u < 0 half and "
    f"{np.mean(ratio37[y_grid >= 0] > 1.05):.0%} of its y_u >= 0 half"
)

# %% [markdown]
# Far from the base station ($R \gg 2W - y_u$) eq. 25 is tight — up to the rounding of the exact
# value to whole antennas, which alone moves the ratio by up to $1/M_{\max}$; close to it, eq. 25 is
# conservative by up to a factor of about 16 (its smallest ratio, 0.06, at the map's corner
# $R = 1$ m, $y_u = -5$ m), and the exact $M_{\max}$ even *grows* again at small $R$. Not because
# of the reflection, which at that corner is near-normal (the VUE is 1 m along and 11 m across),
# but because the VUE, at $(R,\, 2W - y_u)$, then lies almost on the array's axis (end-fire):
# the aperture seen across the line of sight shrinks by $R/\rho$, and the second-order
# expression above grows like $\sqrt{\rho^3/R^2}$ as $R \to 0$. Eq. 37 sees $y_u$ only through
# $\rho$: it is too small on most of the map and too large (unsafe) only when the UE is on the
# far side of the array, $y_u < 0$ (on more than half of that half of the map; the shares are
# printed above).
#
# ### Closed forms vs exact at ten geometries
#
# Two far-away geometries where eq. 25 is tight, the paper's example, and seven others (one with
# the UE $3.3$ m below the array, as for a 4.8 m high anchor; the URA is section 4.1's). Below
# the table, whether the paper's $10 \times 10$ URA stays within $\varepsilon_\Phi$ in each row.

# %%
ten = [
    dict(label="paper example", R=3.5, W=3.0, y_u=2.5, fc=5.9e9, eps_phi=0.15),
    dict(label="paraxial A", R=100.0, W=3.0, y_u=2.5, fc=5.9e9, eps_phi=0.15),
    dict(label="paraxial B", R=200.0, W=2.0, y_u=1.0, fc=28e9, eps_phi=0.15),
    dict(label="near", R=10.0, W=3.0, y_u=2.5, fc=5.9e9, eps_phi=0.15),
    dict(label="UE on BS line", R=30.0, W=5.0, y_u=0.0, fc=5.9e9, eps_phi=0.15),
    dict(label="UE across", R=30.0, W=5.0, y_u=-3.0, fc=5.9e9, eps_phi=0.15),
    dict(label="28 GHz", R=50.0, W=5.0, y_u=4.5, fc=28e9, eps_phi=0.15),
    dict(label="short, 28 GHz", R=5.0, W=5.0, y_u=1.0, fc=28e9, eps_phi=0.15),
    dict(label="UE near wall", R=20.0, W=3.0, y_u=2.9, fc=5.9e9, eps_phi=0.15),
    dict(label="paper, z_u=-3.3", R=3.5, W=3.0, y_u=2.5, z_u=-3.3, fc=5.9e9, eps_phi=0.15),
]
table10 = fresnel.design_report(ten)
report_table(table10).show()
ura10 = {
    d["label"]: fresnel.phase_mismatch_ura(
        10, d["R"], d["W"], d["y_u"], d["fc"], z_u=d.get("z_u", 0)
    )
    for d in ten
}
for d in ten:
    ok = "within" if ura10[d["label"]] <= d["eps_phi"] else "above"
    print(f"{d['label']:16s} 10 x 10 mismatch {ura10[d['label']]:.3f} rad, {ok} eps_Phi")
rows10 = table10.records()
excess = np.array([r["2nd-order"] - r["exact ULA"] for r in rows10])
floor_excess = np.array([np.floor(r["2nd-order"]) - r["exact ULA"] for r in rows10])
print(f"2nd order - exact ULA: {excess.min():+.2f} to {excess.max():+.2f} antennas")

# %% [markdown]
# The paper's $10 \times 10$ stays within $\varepsilon_\Phi$ for the paper's example with the UE
# in the plane of the array ($z_u = 0$, first row), not with the UE 3.3 m below it (last row), nor
# with the UE across the array at 30 m ("UE across"). The corrected second-order expression lies
# at most 1.3 antennas above the exact ULA value in this table; rounded down to whole antennas it
# gives the exact $M_{\max}$ or one antenna more — an expansion, not a bound.

# %% [markdown]
# ## 5. SR-NF validity tables for 5.9 GHz and 28 GHz tunnels
#
# What these tables answer: how large an array may be *for an estimator built on the SR-NF
# model* (eq. 51) before that model stops describing a side-wall reflection. That is the
# validity condition of one estimator, not the size an array should have — an estimator that
# centres each reflected wavefront on its VUE does not need it, and notebook 08 asks how many
# antennas a tunnel needs. The geometry is the theorem's, a planar vertical side wall, so the
# tunnel here has a rectangular cross-section (section 4.1's semicircular tube has no such wall,
# section 3): 10 m wide with the anchor in the middle, wall at $W = 5$ m, anchor 4.8 m high as in
# section 4.1, UE antenna at 1.5 m ($z_u = -3.3$ m), UE in the near lane ($y_u = 1.75$ m) or the far
# lane ($y_u = -1.75$ m), $\varepsilon_\Phi = 0.15$ rad. Each row: the largest ULA and $M \times M$
# URA for which the SR-NF model holds at that distance. The same numbers come from the command line:
# `tunnelkit mmax --R 50 --W 5 --y-u 1.75 --z-u -3.3 --fc 5.9GHz 28GHz`.

# %%
design = [
    dict(label=f"{f / 1e9:g} GHz, {lane}", R=r, W=5.0, y_u=yy, z_u=-3.3, fc=f, eps_phi=0.15)
    for f in (5.9e9, 28e9)
    for lane, yy in (("near lane", 1.75), ("far lane", -1.75))
    for r in (5.0, 20.0, 50.0, 100.0)
]
table_design = fresnel.design_report(
    design, title="SR-NF validity, planar side wall (W = 5 m, z_u = -3.3 m)"
)
report_table(table_design).show()
mmax_range_figure(50.0, 5.0, -1.75, 28e9, 0.15, 64, z_u=-3.3).show()

# %% [markdown] tags=["explorer"]
# ## 6. Explore
#
# Drag the sliders (they update on release). Panel (a) is Fig. 2 for the current geometry,
# (b) the phase mismatch across the array (exact, eq. 33, corrected second order, and
# $\varepsilon_\Phi$), (c) $M_{\max}$ against $R$ on log-log axes with the $\sqrt{R/\lambda}$
# Fraunhofer law for reference; the star is your design ($R$, $M$). The title is the verdict from
# the exact mismatch. $y_u$ cannot reach the wall: its maximum follows $W$.

# %% tags=["explorer"]
explorer = mmax_explorer()
explorer

# %% [markdown]
# ## Exercises
#
# 1. At 5.9 GHz with $W = 3$ m and $y_u = 2.5$ m, from which distance $R$ on is eq. 25 within 5 %
#    of the exact $M_{\max}$?
# 2. Put the UE in the opposite lane, $y_u = -2$ m, at $R = 30$ m, 28 GHz. Which of eq. 25,
#    eq. 37 and the second-order expression is unsafe (larger than the exact value)?
# 3. An engineer wants a $16 \times 16$ URA at 28 GHz in the tunnel of section 5 (far lane). From
#    which distance on does the SR-NF model hold for it?
#
# The solutions are the collapsed cells below, and Run All does not run them. Once you have
# tried an exercise, click the "Run solution" button under its solution (or run
# `tk.solution("02.2")` in a cell, for exercise 2): the solution runs on a copy of the
# notebook's variables, so it changes none of yours, and shows what it prints. A cell's blue
# bar shows its code. On the static site the solutions have already run: open one, then its
# "Show the solution's output". What to read in them follows.

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 02.1
# Solution 1: from which distance on is eq. 25 within 5 % of the exact Mmax?
Rs = np.geomspace(1, 300, 400)
r_ex = fresnel.mmax_2d(Rs, 3, 2.5, 5.9e9, 0.15) / fresnel.mmax_exact_grid(Rs, 3, 2.5, 5.9e9, 0.15)
off = np.abs(r_ex - 1) >= 0.05
r_from = Rs[np.flatnonzero(off)[-1] + 1]
print(f"eq. 25 within 5 % for every R >= {r_from:.1f} m, where (2W - y_u)/R = {3.5 / r_from:.2f}")
assert 0.2 < 3.5 / r_from < 0.5

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 02.2
# Solution 2: the opposite lane at 28 GHz
summ = fresnel.mmax_summary(30, 3, -2, 28e9, 0.15)
for name in ("exact", "eq25", "eq37", "nonparaxial"):
    v = getattr(summ, name)
    print(f"{name:12s} {v:6.2f}  {'unsafe' if v > summ.exact else 'safe'}")
assert summ.eq37 > summ.exact + 3  # eq. 37: unsafe by several antennas
assert summ.eq25 <= summ.exact  # eq. 25: just safe
assert summ.exact < summ.nonparaxial < summ.exact + 1  # unsafe, by less than one antenna

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 02.3
# Solution 3: a 16 x 16 URA at 28 GHz in the far lane of section 5's tunnel
R_try = np.arange(5.0, 60.0, 0.5)
mis16 = np.array([fresnel.phase_mismatch_ura(16, R, 5, -1.75, 28e9, z_u=-3.3) for R in R_try])
r16 = R_try[np.flatnonzero(mis16 > 0.15)[-1] + 1]
print(f"mismatch {mis16[R_try == 15][0]:.3f} rad at 15 m; within 0.15 rad from R = {r16:.1f} m on")
m16 = fresnel.mmax_exact_ura(r16, 5, -1.75, 28e9, 0.15, z_u=-3.3)
print("exact URA Mmax there:", m16)
assert m16 >= 16

# %% [markdown]
# <details><summary>What to read in the solutions</summary>
#
# 1. "$\ll 1$" need not be very small: eq. 25 is within 5 % once $(2W - y_u)/R$ is about a third.
# 2. Eq. 37 is unsafe by several antennas: it drops the factor $W/(W - y_u)$. Eq. 25 is close
#    and just safe (its paraxial ratio $(2W - y_u)/R$ is small). The second-order expression is
#    unsafe too, but by less than one antenna: it is an expansion to second order, not a
#    rigorous bound, and here the third-order terms tip it just above the exact value.
# 3. The mismatch falls with distance; from the printed distance on the SR-NF model holds for the
#    $16 \times 16$ URA, where the exact $M_{\max}$ of the URA reaches 16.
#
# </details>

# %% [markdown]
# ## Checks

# %%
assert abs(m25 - 9.88) < 0.01 and round(m25) ** 2 == 100  # section 4.2
assert abs(edge34 - eps) < 1e-12  # eq. 25 solves eq. 34
assert err_2627 < 1e-9 and abs(prof.x_p0 - p0[0]) < 1e-12  # eq. 26-27, eq. 32
assert cancel.max() < 1e-9 and abs(lin28 - lin31) < 1e-12  # linear terms cancel (eq. 33)
assert np.abs(err28[1:]).min() > eps  # eq. 28 alone is off outside the paraxial regime
assert m_exact == 15 and m_ura == 11  # exact: the paper's M = 100 (10 x 10) holds at z_u = 0
assert mis0 <= eps and m_ura33 == 9 and 0.165 < mis33 < 0.18  # ... not 3.3 m below the array
assert ura10["paper example"] <= eps < ura10["paper, z_u=-3.3"] and ura10["UE across"] > eps
assert abs(m25 / m_exact - 0.66) < 0.005  # the example's ratio on the map
ratio33 = prof.mismatch_paraxial[[1, 9, 99]] / prof.mismatch[[1, 9, 99]]  # eq. 33 / exact
assert 2.75 < ratio33[0] < 2.85 and 2.55 < ratio33[1] < 2.65 and 1.35 < ratio33[2] < 1.45
assert 0.055 < ratio25.min() < 0.065 and 1.075 < ratio25.max() < 1.085  # either side of exact
assert np.unravel_index(ratio25.argmin(), ratio25.shape) == (0, 0)  # corner R = 1 m, y_u = -5 m
assert np.all(exact_map[:, 0] > exact_map.min(axis=1))  # exact Mmax grows again at small R
assert R_grid[0] / (2 * W - y_grid[0]) < 0.1  # ... where the VUE is near the array axis (end-fire)
assert np.mean(ratio37 < 0.95) > 0.5 and np.mean(ratio37[y_grid < 0] > 1.05) > 0.5
assert not (ratio37[y_grid >= 0] > 1.05).any()  # eq. 37 unsafe only with y_u < 0
assert 1.25 < excess.max() < 1.35 and set(floor_excess) == {0, 1}  # 2nd order: exact or one more
# the tube: no vertical wall above road level, no wall reflection on the straight drive, the
# slalom's wall reflections on a steeply tilted facet
assert "wall" not in mism and top_vertical < 1.5
assert len(wall_hits) > 0 and hit_tilt.min() > 30 and hit_z.min() > 3
# ... but not for the ceiling of the section 4.1 tunnel, at any epoch of the drive
assert min(mism["ceiling"]) > eps, mism["ceiling"]
# the exercises' readings are asserted in their solutions (run in CI with TUNNELKIT_SOLUTIONS=1)
assert fresnel.phase_mismatch_ura(10, R, W, y_u, fc) <= eps
assert np.abs(floor_gap).max() <= 1 and abs(ratio25[:, far] - 1).max() < 0.08  # tight far away
assert ratio25.min() < 0.5  # ... and loose close to the anchor
assert (ratio37 > 1.05).any() and (ratio37 < 0.95).any()  # eq. 37: both ways wrong
rows = table10.records()
assert (
    len(rows) == 10
    and abs(rows[1]["eq.25/exact"] - 1) < 0.02
    and abs(rows[2]["eq.25/exact"] - 1) < 0.02
)
assert all(abs(r["2nd-order"] - r["exact ULA"]) <= 1 + 0.04 * r["exact ULA"] for r in rows)
assert explorer.figure.layout.title.text.startswith("SR-NF valid for M = 10")
assert mmax_figure(M=40).layout.title.text.startswith("SR-NF not valid")
print("all checks passed")
