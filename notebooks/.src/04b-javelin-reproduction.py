# %% [markdown]
# # 04b · Appendix: JAVELIN's Tables 1–2, the road-marking ablation and our design, measured
#
# *Italiano, Brambilla & Nicoli (2026), "In-Tunnel Single-Anchor Localization Exploiting Near-Field
# and Radio-Reflective Road Markings", [arXiv:2604.04217](https://arxiv.org/abs/2604.04217v1),
# sections 4.2–4.3 (Tables 1–2, Fig. 7) and the JAVELIN design of sections 3.2–3.5 (eq. 43–68).
# All references: `REFERENCES.md` at the top of the repository; terms and abbreviations: the
# [glossary](GLOSSARY.md). Read notebook 04 first: it teaches
# the tracker; this appendix measures it.*
#
# **What you will learn**
#
# - Tables 1–2 of the paper beside ours, over 20 runs per condition, with the paper's design and
#   ours on the paper's measurement route (CPD) and on the maximum-likelihood route, reported on
#   a held-out seed: the designs were chosen on other (tuning) seeds;
# - the error CDFs of Fig. 7 for both trajectories;
# - the road-marking ablation (JAVELIN-N against JAVELIN-NoRRMs), whose result we do not
#   reproduce;
# - our changes to the paper's design, one at a time, and what each is worth;
# - where our tunnel and our reading of the paper differ from the paper's setup.

# %%
import inspect

import numpy as np
from tqdm.auto import tqdm

import tunnelkit as tk
from tunnelkit import simulation as ex
from tunnelkit.constants import C
from tunnelkit.metrics import position_errors
from tunnelkit.plots import cdf_figure, javelin_table_figure
from tunnelkit.reproduce.javelin_tables import DEAD_RECKONING, radio_gains, table_rows
from tunnelkit.signal_route import SignalRoute
from tunnelkit.simulation import collect_routes
from tunnelkit.tracking.javelin import designs
from tunnelkit.tracking.javelin.measured import design_from_errors

tk.setup_notebook()

# %% [markdown]
# ## 1. The drives of Tables 1–2
#
# The setup of notebook 04, section 1: the tunnel, the base station, its two 10 × 10 URAs, the
# four RRMs and the SRS come from sections 4.1–4.2 of the paper; the vehicle's speed and the time
# between epochs, which the paper does not give, from the package's presets
# (`italiano2026-straight`, `italiano2026-slalom`). The paper's four conditions on the straight
# drive — **L** (LoS), **N@0.5** (LoS blocked with probability 0.5 per epoch), **N** (always
# blocked), **NoRRMs** (no road markings, LoS blocked: our reading of the paper) — and three on
# the slalom. Every drive goes through the signal route once and is measured twice from the same
# tensors: the paper's CPD route (eq. 11–24) and the ML route (notebook 03, section 7). Full
# mode: 20 runs per condition (our choice: the paper does not say how many runs its tables
# average), 140 drives, minutes (the progress bar shows the estimate); quick mode: one run of the
# first 6 epochs, fewer conditions.
#
# **A held-out seed.** A design scored on the drives it was chosen on is scored too kindly, so
# every drive here comes from a seed that no choice of our design saw (the paper's design has
# nothing tuned; which choice saw which drives: [docs/javelin-seeds.md](../docs/javelin-seeds.md)).

# %%
seed = ex.HELD_OUT_SEED
runs = tk.mc_count(20, 1)
n_epochs = 6 if tk.quick_mode() else None
straight_conditions = ("L", "N", "NoRRMs") if tk.quick_mode() else ("L", "N@0.5", "N", "NoRRMs")
slalom_conditions = ("L",) if tk.quick_mode() else ("L", "N@0.5", "N")
routes = {
    scenario: collect_routes(scenario, conds, runs, seed, progress=True, n_epochs=n_epochs)
    for scenario, conds in (
        ("italiano2026-straight", straight_conditions),
        ("italiano2026-slalom", slalom_conditions),
    )
}
straight, straight_ml = (routes["italiano2026-straight"][e] for e in ("paper", "ml"))
slalom, slalom_ml = (routes["italiano2026-slalom"][e] for e in ("paper", "ml"))
print(f"held-out seed {seed}; drives per condition:")
print({sc: {c: len(d) for c, d in r["ml"].items()} for sc, r in routes.items()})

# %% [markdown]
# ## 2. Tables 1–2 beside the paper
#
# The paper names three scores (section 4.3) but gives neither their formulas nor a run count;
# we score each configuration by these three numbers over the epochs $k = 1..K$ of a run,
# averaged over runs: the 2-D RMSE
# $\sqrt{\tfrac1K\sum_k\|\hat{\mathbf p}_{xy,k} - \mathbf p_{xy,k}\|^2}$, the 2-D MAE
# $\tfrac1K\sum_k\|\hat{\mathbf p}_{xy,k} - \mathbf p_{xy,k}\|$ and the lateral Y-MAE
# $\tfrac1K\sum_k|\hat y_k - y_k|$ (lane detection). Its JAVELIN-L reaches 0.20 m 2-D RMSE on the
# straight drive (Table 1) and 0.41 m on the slalom (Table 2).
#
# Columns: the paper's design (section 4.2) on the paper's route; the paper's design on the ML
# route, as printed (eq. 51) and with the curvature centred on the VUE; our design on the ML
# route; the paper's numbers. The same computation runs from the command line:
# `tunnelkit reproduce javelin-table1` / `javelin-table2` with `--seed` set to the held-out seed
# printed in section 1.

# %%
cols1, rows1 = table_rows(routes["italiano2026-straight"], "italiano2026_table1", progress=True)
javelin_table_figure(cols1, rows1, title=f"Table 1 (straight), {runs} run(s) per condition")

# %%
cols2, rows2 = table_rows(routes["italiano2026-slalom"], "italiano2026_table2", progress=True)
javelin_table_figure(cols2, rows2, title=f"Table 2 (slalom), {runs} run(s) per condition")

# %% [markdown]
# On the paper's route the paper's design is metres off: its CPD merges the paths that arrive
# together (notebook 04, section 3), and curvatures more than ten metres off fail a gate built
# for $\sigma_\kappa = 1.5$ m. On the ML route the same design with eq. 51 still does worse than
# with the curvature centred on the VUE, because the exact channel's wavefront is centred there;
# with the VUE curvature, nothing else changed, its error is at or below the paper's own
# JAVELIN-L on the straight drive (full mode), and below a metre on the slalom. Mind the start:
# every column here, the paper's design included, starts JAVELIN at the true position with 1 m
# of uncertainty (`ex.evaluate`'s default, section 6), while the paper's runs start from its
# $\sigma_P$ = 10 m; the paper's column is a different start, and a tracker told 1 m has less to
# settle. The JAVELIN-L rows of this run, side by side:

# %%
sl = {r[0]: dict(zip(cols2[2:], r[2:])) for r in rows2 if r[1] == "rmse_2d_m"}["JAVELIN-L"]
st = {r[0]: dict(zip(cols1[2:], r[2:])) for r in rows1 if r[1] == "rmse_2d_m"}["JAVELIN-L"]
for name, row in (("straight", st), ("slalom", sl)):
    print(f"JAVELIN-L {name:8s} 2-D RMSE [m]: " + ", ".join(f"{c} {v:.3f}" for c, v in row.items()))

# %% [markdown]
# **The baseline: dead reckoning.** A tracker has to beat what it would do without the radio. Each
# table's `dead reckoning` rows run the column's JAVELIN on the same drives, from the same start,
# with the same V2X speed and heading messages and every radio measurement dropped (predict only).
# Nothing a route does with the radio reaches them, so they are the same in every column of the
# paper's design. Our design's column has its own: ours steps on the midpoint of two messages
# where the paper's design holds the previous one (eq. 62), so on a turning drive its dead
# reckoning is free of the held step's lag (notebook 04, section 4, measures it on noise-free
# messages). The radio's gain is dead reckoning's
# 2-D RMSE over the tracker's, in the same column (above 1 the radio helps), per condition, in
# our design's column:

# %%
ours = cols1[5]  # "our design, ML route"
gains = {t: radio_gains(c, r) for t, c, r in (("straight", cols1, rows1), ("slalom", cols2, rows2))}
for t, by_row in gains.items():
    print(f"{t:8s} " + ", ".join(f"{n}: {g[ours]:.2f}x" for n, g in by_row.items()))

# %% [markdown]
# ## 3. Error CDFs (Fig. 7)
#
# The 2-D error of every epoch of every run, per configuration and trajectory: JAVELIN with the
# paper's design and the VUE curvature on the ML route, TeNFiLoc-L on the ML route.


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


cdfs = {}
for scenario, by_cond in tqdm(
    (("straight", straight_ml), ("slalom", slalom_ml)), desc="Fig. 7: scoring", leave=False
):
    cdfs[scenario] = {f"JAVELIN-{c}": errors(ds) for c, ds in by_cond.items()}
    cdfs[scenario]["TeNFiLoc-L"] = errors(by_cond["L"], method="TeNFiLoc")

# %%
fig7a = cdf_figure(
    cdfs["straight"],
    title=f"2-D error CDF, straight, ML route, JAVELIN = paper design + VUE κ, {runs} run(s)",
)
fig7a.update_xaxes(type="log", range=[-2, 2])

# %%
fig7b = cdf_figure(
    cdfs["slalom"],
    title=f"2-D error CDF, slalom, ML route, JAVELIN = paper design + VUE κ, {runs} run(s)",
)
fig7b.update_xaxes(type="log", range=[-2, 2])

# %% [markdown]
# ## 4. The road-marking ablation
#
# The paper mounts two RRM plates on the side walls, 3.3 m high, "midway between the vehicle and the
# anchor", and two at the junction of sidewalk and wall, inclined at 55°, without saying where along
# the tunnel. The preset puts all four along $10 \le x \le 30$ m (printed below), but the vehicle
# sees their reflections from further away: a plate reflects towards the BS whenever the specular
# point falls on it, which happens for a UE well beyond the plate's end. Where along each drive does
# an RRM path exist (the true paths of the scenario, every epoch)? The same count for the wall
# facets serves section 6.

# %%
preset = tk.load_scenario("italiano2026-straight")
plates = preset.section("tunnel")["plates"]
plate_x = (min(p["x_range"][0] for p in plates), max(p["x_range"][1] for p in plates))
rrm_x, wall_epochs, ceiling_epochs, n_drive = {}, {}, {}, {}
for scenario in routes:
    sr = SignalRoute.from_scenario(scenario)
    traced = [sr.paths(k)[1] for k in range(len(sr.trajectory))]
    n_rrm = [sum(p.surface_kind == "rrm" for p in ps) for ps in traced]
    x, y = sr.trajectory.position[:, 0], sr.trajectory.position[:, 1]
    rrm_x[scenario] = x[np.array(n_rrm) > 0]
    wall_epochs[scenario] = [
        k for k, ps in enumerate(traced) if any(p.surface_kind == "wall" for p in ps)
    ]
    ceiling_epochs[scenario] = [
        k for k, ps in enumerate(traced) if any(p.surface_kind == "ceiling" for p in ps)
    ]
    n_drive[scenario] = len(traced)
    print(
        f"{scenario}: RRM paths at {len(rrm_x[scenario])} of {len(x)} epochs, UE at "
        f"x = {rrm_x[scenario].min():.1f}-{rrm_x[scenario].max():.1f} m, at most {max(n_rrm)} "
        f"at a time (the plates span x = {plate_x[0]:g}-{plate_x[1]:g} m)"
    )
    walls = wall_epochs[scenario]
    print(
        f"    a wall path at {len(walls)} of {len(x)} epochs"
        + (
            f" (the UE {abs(y[walls]).min():.1f}-{abs(y[walls]).max():.1f} m from the axis there, "
            f"{abs(y).min():.1f}-{abs(y).max():.1f} m over the drive)"
            if walls
            else ""
        )
        + f"; a ceiling path at {len(ceiling_epochs[scenario])}"
    )

# %% [markdown]
# The paper finds that removing the markings hurts most of all (JAVELIN-NoRRMs 2.26 m against
# JAVELIN-N 0.88 m 2-D RMSE, Table 1). Compare JAVELIN-N (LoS blocked, RRMs present) with
# JAVELIN-NoRRMs (LoS blocked, no RRMs), and count the paths each condition delivers — with a
# usable curvature on every path.

# %%
rmse = {(r[0], c): v for r in rows1 if r[1] == "rmse_2d_m" for c, v in zip(cols1[2:], r[2:])}
for cond in ("N", "NoRRMs"):
    paths = np.mean(
        [np.mean([0 if e is None else len(e) for e in d.epochs]) for d in straight_ml[cond]]
    )
    print(
        f"JAVELIN-{cond:7s} paths/epoch {paths:4.2f}   2-D RMSE [m]: "
        + ", ".join(f"{c} {rmse[(f'JAVELIN-{cond}', c)]:.2f}" for c in cols1[2:-1])
    )

# %% [markdown]
# In our tunnel removing the markings costs little or nothing on the ML route, against the
# paper's finding (its Table 1 loses 1.38 m): in the two lines above, JAVELIN-NoRRMs's 2-D RMSE
# stays less than 0.2 m above JAVELIN-N's, with the paper's parameters (VUE curvature) and with
# ours. Without the LoS the road
# and ceiling bounces remain, measured about as well as the LoS, and locate the UE through their
# VUEs; exercise 3 looks at what the RRM paths add and what they cost.
#
# ## 5. Our design, one change at a time
#
# Our design changes the paper's one step at a time: (1) Doppler clutter rejection — a static
# reflector's path cannot have a radial speed above the vehicle's speed, so faster CPD components
# are dropped before association (the Doppler test of Algorithm 3, applied to every path);
# (2) the measurement noise $\mathbf R$ of eq. 64–68 calibrated on what the CPD extraction
# delivers (angles ~5°, $\sigma_\kappa = 50$ m, where section 4.2 of the paper assumes 2° and
# 1.5 m); (3) global nearest neighbour (scipy's `linear_sum_assignment`) instead of the greedy
# Algorithm 2; (4) VUEs moved with the mirrored UE displacement instead of eq. 63's random walk
# (notebook 04, section 4); (5) a newborn track is not used to update in its birth epoch (its
# position came from the very angles it would update with); (6) each prediction steps on the
# midpoint of two V2X messages, not on eq. 62's message held over the step (notebook 04,
# section 4: the held heading lags a turning drive). Settings (1)–(5) were tuned on the
# paper's extraction of tuning drives; (6) mends a model error and was not tuned. The last rows
# change the measurement route: the paper's design on the ML route (eq. 51 as printed, then the
# curvature centred on the VUE, the radius of the exact wavefront that the ML route measures),
# and our design on it: (1)–(6), the VUE curvature, a measurement noise set from the extraction
# error measured on tuning drives, and (7) a joint innovation test: a pair that makes the
# stacked innovation of the epoch inconsistent is left out of the update. (7) is there because when the LoS is blocked, eq. 61
# accepts any free path whose delay is within $\gamma$ of its curvature, and a road-marking
# reflection, its VUE as far from the array as the UE but well off its direction, can pass it
# and drag the UE towards that direction.
# Mean 2-D RMSE [m]:

# %%
abl_cols, abl_rows = ex.ablation(straight, ml=straight_ml, progress=True)
javelin_table_figure(abl_cols, abl_rows, title="ablation on the straight drives: 2-D RMSE [m]")

# %% [markdown]
# On the paper's route one step carries the table: the calibrated noise (2) lowers the error
# more than any other step, in every condition. Before it, with the LoS present (L), the UE is
# metres off, with or without the Doppler test; the other steps gain less. On the ML route the
# paper's own parameters with the VUE curvature are already close to our design (within half a
# metre in every condition), better in some: with measurements near their bound, the design
# matters far less than what the tracker is fed.
#
# Our ML-route design does not set its four measurement sigmas to the RMS error the ML route
# delivers on these drives: they are wider (the last row below, set on tuning drives, against
# the held-out rows above it), so that one gross error — two nearly coincident paths
# swapped or merged — does not make the gate reject the next good measurement (exercise 2 tries
# the narrower choice). The RMS measurement error over all the LoS drives here:

# %%
ecols, erows = ex.extraction_errors(straight_ml["L"] + slalom_ml["L"])
c_ml = designs.ours_ml().config
assumed = [
    np.degrees(c_ml.sigma_phi),
    np.degrees(c_ml.sigma_psi),
    c_ml.sigma_kappa,
    c_ml.sigma_delta_d,
]
display_rows = [*erows, ["our ML design assumes", None, *assumed, None]]
javelin_table_figure(
    ecols, display_rows, title=f"ML route: RMS measurement error, {runs} run(s)", digits=4
)

# %% [markdown]
# ## 6. Where our tunnel differs from the paper's
#
# - **Propagation.** The paper used a ray tracer on a Blender model with a single bounce; we use
#   the image method on 12 planar facets (the preset's approximation of the semicircle) plus the
#   road and four finite RRM plates. Both are single-bounce, but our facets give fewer, cleaner
#   wall paths.
# - **The LoS/ceiling pair.** With the array just under the crown, the ceiling reflection is
#   centimetres behind the LoS in delay and shares its Doppler; the road bounce is a few tenths of
#   a metre behind. The CPD of eq. 11 cannot separate such paths (notebook 04, section 3), which
#   is what keeps every design metres or decimetres off on the paper's route (the tables of
#   section 2). The paper does not mention the problem, and its ray tracer may have produced
#   weaker or better separated ceiling paths. The ML route fits all paths jointly and separates
#   them (notebook 03).
# - **Curvature.** The paper assumes $\sigma_\kappa = 1.5$ m. The paper's CPD route delivers
#   curvatures more than ten metres off (notebook 04, section 2); the ML route far less (the
#   table of section 5). Eq. 51 ties $\kappa$ to the
#   reflection point (SR-NF), while our channel is exact: the wavefront is centred on the VUE
#   (notebooks 02/03 show when the two agree). With accurate curvatures this matters: the paper's
#   design as printed (eq. 51) fails on the ML route, the same design with the VUE curvature
#   (`designs.paper_vue()`) tracks (section 2).
# - **Clock bias.** Section 4.2 gives "variance 50 ns"; we read it as a 50 ns standard deviation
#   (15 m of distance). TDoAs cancel it, but the LoS test of eq. 61 and TeNFiLoc's $\hat d$
#   fallback suffer.
# - **Start.** The paper assumes the open-sky position is known; in every column, the paper's
#   design included, we start at the truth with 1 m uncertainty rather than its $\sigma_P = 10$ m.
# - **Drive length.** The presets' drives are short (printed below: 29 epochs, about 40 m),
#   so start-up transients weigh in the averages.
# - **Side-wall paths.** Our cross-section is 12 flat facets, the lower ones (steeper than 45°)
#   walls. From the straight drive's lane no wall facet reflects towards the array under the
#   crown; on the slalom one does, at the epochs where the vehicle swings towards the wall
#   (section 4 prints how many, and how far from the axis the UE is then): one more path that
#   comes and goes with the swing. The ceiling facets next to the crown reflect at every epoch
#   of both drives.

# %%
sr_st = SignalRoute.from_scenario("italiano2026-straight")
pos = sr_st.trajectory.position
drive_m = float(np.linalg.norm(pos[-1] - pos[0]))
clock_ns, clock_m = 1e9 * sr_st.config.clock_bias_sigma, C * sr_st.config.clock_bias_sigma
start_sigma = inspect.signature(ex.evaluate).parameters["sigma_p0_ue"].default
n_facets = preset.section("tunnel")["n_facets"]
print(
    f"{n_facets} facets; clock bias sigma {clock_ns:.0f} ns = {clock_m:.1f} m; start uncertainty "
    f"{start_sigma:g} m (the paper's sigma_P {designs.paper().config.sigma_p0:g} m); drive "
    f"{len(pos)} epochs, {drive_m:.1f} m at {3.6 * preset.section('trajectory')['speed']:.0f} km/h"
)

# %% [markdown]
# ## Exercises
#
# 1. Run the ablation of section 5 on the slalom drives (`ex.ablation(slalom, ml=slalom_ml)`).
#    Does every step of our design help there too?
# 2. Our ML-route design (`designs.ours_ml()`) took its measurement noise from a few LoS drives
#    of a tuning seed. Set it instead from all the LoS drives of section 1
#    (`design_from_errors` on the table of section 5) and score JAVELIN-L on both
#    trajectories with both designs. Does more calibration data change the result? Mind what
#    the comparison is: the refit is fitted on the very held-out drives it is scored on, which
#    favours it — and a design chosen that way would leave the seed held out no longer.
# 3. Why do the road markings not help in our tunnel? For JAVELIN-N and JAVELIN-NoRRMs on the ML
#    route (`designs.paper_vue()`), count per drive the births (`keep_reports=True`, then
#    `r.manage.born` of each report) and the share of epochs that deliver an RRM path
#    (`d.kinds[k][t]` of each matched path `t` in `d.truth_index[k]`).
#
# The solutions are the collapsed cells below, and Run All does not run them. Once you have
# tried an exercise, click the "Run solution" button under its solution (or run
# `tk.solution("04b.2")` in a cell, for exercise 2): the solution runs on a copy of the
# notebook's variables, so it changes none of yours, and shows what it prints. A cell's blue
# bar shows its code. On the static site the solutions have already run: open one, then its
# "Show the solution's output". What to read in them follows.

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04b.1
# Solution 1
from IPython.display import display

sl_cols, sl_rows = ex.ablation(slalom, ml=slalom_ml, progress=True)
display(javelin_table_figure(sl_cols, sl_rows, title="ablation on the slalom drives: 2-D RMSE [m]"))
# the calibrated noise carries the table on the slalom too
assert sl_rows[2][1] < 0.5 * sl_rows[0][1], sl_rows

# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04b.2
# Solution 2
refit = design_from_errors(erows)
sol2 = {}
for name, by_cond in (("straight", straight_ml), ("slalom", slalom_ml)):
    scores = sol2[name] = {
        label: np.mean([ex.evaluate(d, cfg).metrics["rmse_2d_m"] for d in by_cond["L"]])
        for label, cfg in (("OURS_ML (3 drives)", designs.ours_ml()), ("refit (all drives)", refit))
    }
    print(name, {k: round(float(v), 3) for k, v in scores.items()})
c_refit = refit.config
refit_sig = [np.degrees(c_refit.sigma_phi), np.degrees(c_refit.sigma_psi), c_refit.sigma_kappa]
ratio_sig = np.array(assumed) / np.array([*refit_sig, c_refit.sigma_delta_d])
print("our ML design's sigmas / the refit's:", ratio_sig.round(1))
# the refit's sigmas many times narrower; both trajectories lose with them
assert np.all(ratio_sig > 5), ratio_sig
assert all(v["refit (all drives)"] > v["OURS_ML (3 drives)"] for v in sol2.values()), sol2


# %% jupyter={"outputs_hidden": true, "source_hidden": true} tags=["solution"]
# %%solution 04b.3
# Solution 3
def rrm_share_and_births(d):
    """Share of epochs with a matched RRM path, and JAVELIN's births on the drive."""
    rrm = [
        any(d.kinds[k][t] == "rrm" for t in d.truth_index[k] if t >= 0)
        for k, m in enumerate(d.epochs)
        if m is not None
    ]
    run = ex.evaluate(d, designs.paper_vue(), keep_reports=True).run
    return np.mean(rrm), sum(len(r.manage.born) for r in run.reports if r.manage)


for cond in ("N", "NoRRMs"):
    share, births = np.mean([rrm_share_and_births(d) for d in straight_ml[cond]], axis=0)
    print(f"JAVELIN-{cond:7s} epochs with an RRM path {share:5.1%}, births per drive {births:4.1f}")


def rrm_appearances(d):
    """How often an RRM path appears: more matched RRM paths than the epoch before."""
    n = [
        sum(d.kinds[k][t] == "rrm" for t in d.truth_index[k] if t >= 0) if m is not None else 0
        for k, m in enumerate(d.epochs)
    ]
    return int(np.sum(np.maximum(np.diff(n, prepend=0), 0)))


appear = [(rrm_appearances(d), rrm_share_and_births(d)[1]) for d in straight_ml["N"]]
print("JAVELIN-N, per drive (RRM path appearances, births):", appear)
assert all(births >= n for n, births in appear), appear  # every appearance a birth

# %% [markdown]
# <details><summary>What to read in the solutions</summary>
#
# 1. Read each row against the one above it. The noise calibrated on the extraction is again the
#    step that carries the table; the other steps are not a gain everywhere (look for a row
#    whose error is above the one before it). The ablation of section 5 was one trajectory; a
#    design choice has to be checked on the other as well.
# 2. More data is not automatically a better design. The pooled RMS over all the LoS drives has
#    sigmas many times smaller than our ML design's (section 5); with them both trajectories
#    lose (the output: compare the two numbers per trajectory; with one short run in quick mode
#    they are one draw) — although the refit is scored on the very drives it was fitted on. The extraction error is heavy-tailed — near
#    the bound in most epochs, off by metres in the few where nearly coincident paths are
#    swapped or merged — and a Gaussian $\mathbf R$ set to its RMS makes the gate reject the next
#    good measurement after such an epoch. How wide to make
#    $\mathbf R$ is a choice about the tails, to be made on tuning drives and checked on unseen
#    ones (the held-out seed), not read off one table.
# 3. With the markings present the RRM paths exist over part of each drive only (section 4
#    prints where, and how many at a time: on the straight drive from its start until the
#    vehicle comes within a few metres of the plates' near end; quick mode's short drives end
#    before that, so its output shows them in every epoch), so they appear and vanish, and
#    every appearance is a birth; without them the road and ceiling bounces, measured at their
#    bound, carry the UE alone. More paths are not better when the extra ones come and go.
#
# </details>

# %% [markdown]
# ## Checks

# %%
# section 1: the held-out seed (not a tuning seed), 20 runs of 7 conditions in full mode
assert seed == ex.HELD_OUT_SEED and seed not in ex.TUNING_SEEDS
n_drives = sum(len(d) for r in routes.values() for d in r["ml"].values())
assert tk.quick_mode() or (runs == 20 and n_drives == 140), (runs, n_drives)
assert ex.CONDITIONS["N@0.5"].los_probability == 0.5
col_pp, col_pm, col_pv, col_om = cols1[2:6]
# section 2: the paper's JAVELIN-L (Tables 1-2) as quoted
paper_ref = {
    t: {r[0]: r[-1] for r in rows if r[1] == "rmse_2d_m"} for t, rows in ((1, rows1), (2, rows2))
}
assert paper_ref[1]["JAVELIN-L"] == 0.20 and paper_ref[2]["JAVELIN-L"] == 0.41, paper_ref
paper_route = rmse[("JAVELIN-L", col_pp)]
ml_vue, ml_51 = rmse[("JAVELIN-L", col_pv)], rmse[("JAVELIN-L", col_pm)]
assert paper_route > 1.0, rmse  # the paper's design on the paper's route: metres off
# the paper's design on measurements near the bound: at or below the paper's JAVELIN-L (0.20 m)
# on the straight drive (section 2's claim, full mode); quick mode's one short run looser
assert ml_vue < (0.5 if tk.quick_mode() else paper_ref[1]["JAVELIN-L"]), rmse
assert ml_vue < paper_route and ml_vue < rmse[("TeNFiLoc-L", col_pm)]
assert ml_vue < ml_51  # eq. 51 does not describe the exact channel's wavefront
# slalom: the ML route beats the paper's route with either design, both below a metre
assert sl[col_om] < 1.0 and sl[col_om] < sl[col_pp], sl
assert sl[col_pv] < 1.0 and sl[col_pv] < sl[col_pp], sl
assert abl_rows[-2][1] < abl_rows[0][1]  # the ML route with the paper's design beats the paper's
# section 2's baseline: dead reckoning is one number per condition in the paper design's columns
# (our design, stepping on the midpoint, has its own), and each gain is its RMSE over the tracker's
for c, rows in ((cols1, rows1), (cols2, rows2)):
    base = {r[0]: r[2:-1] for r in rows if r[0].startswith(DEAD_RECKONING) and r[1] == "rmse_2d_m"}
    assert base and all(len(set(v[:3])) == 1 and min(v) > 0 for v in base.values()), base
    g = radio_gains(c, rows)["JAVELIN-L"][col_om]
    jl = {r[0]: r for r in rows if r[1] == "rmse_2d_m"}
    assert abs(g - jl[f"{DEAD_RECKONING}-L"][5] / jl["JAVELIN-L"][5]) < 1e-12, g
# the ablation row and the table column of the paper design + VUE on the ML route: one computation
assert abs(abl_rows[-2][1] - ml_vue) < 1e-12
# section 4: the plates span x = 10-30 m; RRM paths exist beyond the plates' far end and not
# over the whole drive; the paper's JAVELIN-N and -NoRRMs as quoted
assert plate_x == (10.0, 30.0), plate_x
wall_plates = [p for p in plates if p["inclination_deg"] == 90.0]
assert len(wall_plates) == 2 and all(p["z"] == 3.3 for p in wall_plates), plates
assert sorted(p["inclination_deg"] for p in plates) == [55.0, 55.0, 90.0, 90.0], plates
straight_x = rrm_x["italiano2026-straight"]
assert straight_x.max() > plate_x[1] and straight_x.min() > plate_x[0], straight_x
assert (paper_ref[1]["JAVELIN-N"], paper_ref[1]["JAVELIN-NoRRMs"]) == (0.88, 2.26), paper_ref
# section 4: removing the markings costs little on the ML route (NoRRMs less than 0.2 m above N,
# with the paper's parameters + VUE curvature and with ours); the paper's Table 1 loses 1.38 m
assert abs(paper_ref[1]["JAVELIN-NoRRMs"] - paper_ref[1]["JAVELIN-N"] - 1.38) < 1e-9
for col in (col_pv, col_om):
    assert rmse[("JAVELIN-NoRRMs", col)] < rmse[("JAVELIN-N", col)] + 0.2, (col, rmse)
# section 5: our CPD noise (5 deg, 50 m); on the paper's route the calibrated noise (2) is the
# largest drop of every column, and L is metres off before it; on the ML route the paper's
# parameters + VUE beat our design in some condition
c_ours = designs.ours().config
assert (
    np.allclose(np.degrees([c_ours.sigma_phi, c_ours.sigma_psi]), 5.0)
    and c_ours.sigma_kappa == 50.0
)
assert abl_rows[0][1] > 1.0 and abl_rows[1][1] > 1.0, abl_rows  # L: metres off before (2)
drops = np.array([np.subtract(abl_rows[i - 1][1:], abl_rows[i][1:]) for i in range(1, 7)])
assert np.all(np.argmax(drops, axis=0) == 1), drops  # (2) the largest drop in every condition
assert any(a < b for a, b in zip(abl_rows[-2][1:], abl_rows[-1][1:])), abl_rows
# section 5: the calibrated noise carries the table on the paper's route (JAVELIN-L)
assert abl_rows[2][1] < 0.5 * abl_rows[1][1], abl_rows
# section 5: the ML design assumes wider sigmas than the held-out drives deliver
err_all = {r[0]: r for r in erows}["all"]
assert np.all(np.array(assumed) > np.array(err_all[2:6])), (assumed, err_all)
# section 6: the setup as quoted; no wall path on the straight drive, some on the slalom; a
# ceiling path at every epoch of both
assert n_facets == 12 and abs(clock_ns - 50.0) < 1e-6 and abs(clock_m - 15.0) < 0.1
assert start_sigma == 1.0 and designs.paper().config.sigma_p0 == 10.0
assert len(pos) == 29 and 38.0 < drive_m <= 40.0, (len(pos), drive_m)
assert not wall_epochs["italiano2026-straight"], wall_epochs
assert 0 < len(wall_epochs["italiano2026-slalom"]) < n_drive["italiano2026-slalom"], wall_epochs
assert all(len(ceiling_epochs[sc]) == n_drive[sc] for sc in n_drive), ceiling_epochs
# ... and on the slalom: asserted in solution 1 (run in CI with TUNNELKIT_SOLUTIONS=1)
# section 5: on the ML route the paper's parameters + VUE are close to our design
assert all(abs(a - b) < 0.5 for a, b in zip(abl_rows[-2][1:], abl_rows[-1][1:])), abl_rows
print("all checks passed")
