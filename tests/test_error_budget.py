"""The error budget (analysis.error_budget) on constructed ladders and headlines: which ladder
stands for which number, the 95 % bound, what limits a number, the discretisation of a threshold."""
import math

import numpy as np
import pytest
import xarray as xr

from confined_rod.analysis import error_budget as eb


def ladder(parameter, L, shifts, load=0.25, k_fr=0.8, protocol="straight", dof=None, h=(1.0, 0.5, 0.25), pub=1):
    """A convergence dataset as the kind stores it: three rungs of refinement variable ``h``, the
    publication rung ``pub`` (the middle one), ``shifts`` = {quantity: (shift, se)} of the
    publication rung against the finest rung; ``dof`` the degrees of freedom of se (None: no
    cmp_dof variable, the normal limit)."""
    q = list(shifts)
    shift, se, code = np.zeros((3, len(q))), np.zeros((3, len(q))), np.zeros((3, len(q)), dtype=np.int8)
    for j, k in enumerate(q):
        shift[2, j], se[2, j] = shifts[k]
        code[2, j] = 1
    data = {"cmp_shift": (("rung", "quantity"), shift), "cmp_shift_se": (("rung", "quantity"), se),
            "cmp_verdict_code": (("rung", "quantity"), code)}
    if dof is not None:
        data["cmp_dof"] = (("rung", "quantity"), np.full((3, len(q)), float(dof)))
    values = np.array(h)      # the parameter's value: h itself for l0, tol and dx_max, 1/h otherwise
    ds = xr.Dataset(data, coords={"quantity": ("quantity", np.array(q, dtype=object)),
                                  "h": ("rung", np.array(h)), "value": ("rung", values)})
    ds.attrs.update(kind="convergence", parameter=parameter, L=L, load=load, k_fr=k_fr, protocol=protocol,
                    publication_value=float(values[pub]))
    return ds


def headline(quantity="F_transmitted", L=320.0, value=0.1, se=0.002, protocol="straight", k_fr=0.8, load=0.25,
             terms=None):
    return eb.Headline(f"fig.{quantity}.L{L:g}.{protocol}.k{k_fr:g}", "fig", "a number", value, se, 5, quantity,
                       L, load, k_fr, protocol, terms=terms or {})


def budget(heads, ladders):
    datasets = {name: ds for name, ds in ladders.items()}
    datasets["fig"] = xr.Dataset(attrs={"kind": "none"})
    return eb.build(datasets, lambda name, ds: heads if name == "fig" else [])


def row(ds, key):
    return {r["headline"]: r for r in eb.rows(ds)}[key]


def test_bias_is_the_publication_rungs_shift_and_the_bound_adds_the_magnitudes():
    """Two ladders with known shifts of opposite sign: the bias per parameter is the shift's
    first-order distance to the limit (twice the shift: the finest rung halves h once), the bound
    sum |delta| + 1.96 sqrt(sum se^2) over those (no cancellation); the number is limited by its
    numerics when the bound exceeds 1.96 standard errors of the mean, by its statistics otherwise."""
    lads = {"conv_l0": ladder("l0", 80, {"F_transmitted": (-0.016, 0.0056)}),
            "conv_tol": ladder("tol", 80, {"F_transmitted": (+0.0001, 0.0)})}
    h_num = headline(value=0.1, se=0.0005)    # statistics 0.98 % at 95 % < bound 5.4 %
    h_stat = headline(L=40.0, value=0.1, se=0.004)   # statistics 7.8 %
    ds = budget([h_num, h_stat], lads)
    p = list(ds["budget_parameter"].values)
    i = list(ds["headline"].values).index(h_num.key)
    assert ds["bias"].values[i, p.index("l0")] == pytest.approx(2 * -0.016)
    assert ds["bias_se"].values[i, p.index("l0")] == pytest.approx(2 * 0.0056)
    expect = 2 * (0.016 + 0.0001) + eb.Z95 * 2 * 0.0056
    assert ds["bias_bound"].values[i] == pytest.approx(expect, rel=1e-12)
    assert row(ds, h_num.key)["limited_by"] == "numerics"
    assert row(ds, h_stat.key)["limited_by"] == "statistics"
    assert ds["stat_error"].values[i] == pytest.approx(0.005)      # relative
    # the parameters no ladder measured are named, and the ramp is not expected of a straight load
    assert set(row(ds, h_num.key)["not_measured"].split()) == {"k_ph", "k_w", "k_t", "dx_max"}
    for v in ds.data_vars.values():
        if v.dtype.kind == "f":
            assert np.isfinite(v.values).all()


def test_ladder_matching_nearest_rod_same_friction_and_ramp_only_for_ramps():
    """dx_max from the ladder nearest in ln L; a ladder of the same friction and load before
    another; the ramp ladder only for a ramped rod of its own friction and load; a quantity the
    ladder did not compare is not measured."""
    lads = {"dx320": ladder("dx_max", 320, {"F_transmitted": (0.01, 0.001)}),
            "dx1280": ladder("dx_max", 1280, {"F_transmitted": (0.03, 0.001)}),
            "ramp_c": ladder("ramp_steps", 320, {"F_transmitted": (0.005, 0.002)}, protocol="ramp"),
            "ramp_a": ladder("ramp_steps", 320, {"F_transmitted": (0.05, 0.002)}, k_fr=0.1, protocol="ramp")}
    near640 = headline(L=640.0)      # ln-distance: 320 and 1280 are equally far -> the name decides
    at900 = headline(L=900.0)
    ramp_c = headline(protocol="ramp", k_fr=0.8)
    ramp_b = headline(protocol="ramp", k_fr=0.3)
    decay = headline(quantity="decay_ratio", L=320.0)
    ds = budget([near640, at900, ramp_c, ramp_b, decay], lads)
    p = list(ds["budget_parameter"].values)
    b = {h: ds["bias"].values[i] for i, h in enumerate(ds["headline"].values)}
    src = {h: ds["bias_source"].values[i] for i, h in enumerate(ds["headline"].values)}
    has = {h: ds["has_bias"].values[i] for i, h in enumerate(ds["headline"].values)}
    assert b[at900.key][p.index("dx_max")] == pytest.approx(2 * 0.03)
    assert src[at900.key][p.index("dx_max")].startswith("dx1280")
    assert b[ramp_c.key][p.index("ramp_steps")] == pytest.approx(2 * 0.005)
    assert has[ramp_b.key][p.index("ramp_steps")] == 0        # no ramp ladder at k_fr 0.3
    assert has[near640.key][p.index("ramp_steps")] == 0      # not a ramp
    assert has[decay.key].sum() == 0                          # no ladder compared the decay ratio
    assert "ramp_steps" in row(ds, ramp_b.key)["not_measured"].split()


def test_threshold_terms_replace_the_ladders_and_a_missing_statistic_leaves_the_limit_unknown():
    lads = {"conv_l0": ladder("l0", 80, {"F_transmitted": (-0.016, 0.0056)})}
    thr = eb.Headline("fig.thr", "fig", "a threshold", 3.9, None, 1, "threshold", 20.0, 0.1, 0.8,
                      terms={"bracket": (5e-4, "bracket"), "discretisation": (-2e-3, "theory")})
    ds = budget([thr], lads)
    p = list(ds["budget_parameter"].values)
    assert ds["has_bias"].values[0, p.index("l0")] == 0
    assert ds["bias_bound"].values[0] == pytest.approx(5e-4 + 2e-3)
    assert row(ds, "fig.thr")["limited_by"] == "unknown"
    assert row(ds, "fig.thr")["stat_95_percent"] is None
    assert "not measured" in eb.to_csv(ds)


def test_distance_to_the_limit_is_one_over_one_minus_the_refinement_ratio_at_first_order():
    """f(h) = f* + a h: a publication rung at h_pub, a finest rung at h_fine; its shift from the
    finest rung is a (h_pub - h_fine) and its distance from the limit a h_pub, their ratio
    1/(1 - h_fine/h_pub): 2 for one halving, 4/3 for two (module docstring). The manuscript names
    each factor with the ladders it applies to."""
    from confined_rod.claims import manuscript

    a, h_pub = 0.3, 0.02
    for h_fine, expect in ((0.01, 2.0), (0.005, 4.0 / 3.0)):
        shift = a * (h_pub - h_fine)
        assert shift * eb.first_order_limit_factor(h_pub, h_fine) == pytest.approx(a * h_pub, rel=1e-12)
        assert eb.first_order_limit_factor(h_pub, h_fine) == pytest.approx(expect, rel=1e-12)
    assert eb.first_order_limit_factor(0.5, 0.5) == 1.0
    with pytest.raises(ValueError, match="h_fine = 1.0"):
        eb.first_order_limit_factor(0.5, 1.0)
    lads = {"conv_l0": ladder("l0", 80, {"F_transmitted": (-0.016, 0.0056)}, h=(1.0, 0.5, 0.125)),
            "conv_ramp": ladder("ramp_steps", 320, {"F_transmitted": (0.01, 0.004)}, protocol="ramp",
                                h=(1 / 128, 1 / 256, 1 / 512))}
    ds = budget([headline(protocol="ramp")], lads)
    p = list(ds["budget_parameter"].values)
    assert ds["bias_limit_factor"].values[0, p.index("l0")] == pytest.approx(4.0 / 3.0)
    assert ds["bias_limit_factor"].values[0, p.index("ramp_steps")] == pytest.approx(2.0)
    assert ds["bias_limit_factor"].values[0, p.index("k_ph")] == 1.0       # not measured
    text = manuscript._limit_factors_tex(ds)
    assert "l0 1.33" in text and "ramp\\_steps 2" in text, text


def test_a_number_at_coarser_numerics_reads_the_rung_that_covers_it():
    """conv_tol with rungs 1e-3, 1e-4 (publication) and 1e-6, members shifted by +1 % and +0.2 %
    from the finest seed by seed: a number at tol_eff = 1e-4 reads the publication rung's stored
    shift; one whose round-off floor forced tol_eff = 5.8e-4 (Fig 7's small load) the 1e-3 rung's
    +1 % (paired over the seeds); one at 2e-3, coarser than every rung, has no tol term and says
    why."""
    rng = np.random.default_rng(3)
    base = 0.1 * (1.0 + 0.05 * rng.standard_normal(12))
    lad = ladder("tol", 80, {"F_transmitted": (0.002, 0.0001)}, h=(1e-3, 1e-4, 1e-6))
    members = np.array([base * 1.01, base * 1.002, base])
    lad["F_transmitted_member"] = (("rung", "member"), members)
    lad["F_transmitted_has"] = (("rung", "member"), np.ones(members.shape, dtype=np.int8))
    lad["member_seed"] = (("rung", "member"), np.tile(np.arange(12), (3, 1)))

    def head(key, tol):
        return eb.Headline(key, "fig", key, 0.1, 0.002, 5, "F_transmitted", 320.0, 0.0125, 0.8,
                           numerics={"tol": tol})
    ds = budget([head("fig.pub", 1e-4), head("fig.floor", 5.8e-4), head("fig.beyond", 2e-3)], {"conv_tol": lad})
    p = list(ds["budget_parameter"].values).index("tol")
    heads = list(ds["headline"].values)
    at = {k: heads.index(k) for k in heads}
    assert ds["bias"].values[at["fig.pub"], p] == pytest.approx(0.002 / (1 - 1e-6 / 1e-4))
    assert ds["bias"].values[at["fig.floor"], p] == pytest.approx(0.01 / (1 - 1e-6 / 1e-3), rel=1e-9)
    assert ds["bias_se"].values[at["fig.floor"], p] == pytest.approx(0.0, abs=1e-12)   # the same factor per seed
    assert ds["bias_limit_factor"].values[at["fig.floor"], p] == pytest.approx(1.0 / (1.0 - 1e-6 / 1e-3))
    assert "rung 0.001 against the finest" in str(ds["bias_source"].values[at["fig.floor"], p])
    assert ds["has_bias"].values[at["fig.beyond"], p] == 0
    assert "not covered" in str(ds["bias_source"].values[at["fig.beyond"], p])
    assert "tol" in row(ds, "fig.beyond")["not_measured"].split()


def test_a_number_without_a_measured_bias_is_limited_by_the_unknown():
    """A share of seeds (Fig 2's defects) with a statistical error but no ladder for its
    quantity: its bias bound is 0 because nothing was measured, not because it is small."""
    share = eb.Headline("fig.share", "fig", "share of seeds with a defect", 0.5, 0.12, 10, "defect_share",
                        80.0, 0.25, 0.8, dof=math.inf)
    ds = budget([share], {"conv_l0": ladder("l0", 80, {"F_transmitted": (-0.016, 0.0056)})})
    assert ds["has_bias"].values[0].sum() == 0
    assert row(ds, "fig.share")["limited_by"] == "unknown"


def test_a_term_from_a_failing_ladder_is_a_lower_bound_and_limits_only_above_the_statistics():
    """A ramp ladder that fails on the decay ratio (its publication rung beyond the tolerance from
    the finest, code 2) and passes on F(L): the decay-rate headline's ramp term is flagged a lower
    bound, the transmitted force's is not; a lower bound above the statistical error limits the
    number (numerics), one below it leaves the limit unknown; the manuscript writes 'at least'."""
    from confined_rod.claims import manuscript

    lad = ladder("ramp_steps", 40, {"decay_ratio": (0.22, 0.064), "F_transmitted": (0.002, 0.02)},
                 load=0.25, k_fr=0.3, protocol="ramp")
    lad["cmp_verdict_code"].values[2, 0] = 2          # decay ratio beyond its tolerance
    lad.attrs["status"] = "fail: decay_ratio beyond"
    h_rate = headline("decay_ratio", L=40.0, value=0.9, se=0.01, protocol="ramp", k_fr=0.3)
    h_noisy = eb.Headline("fig.noisy", "fig", "a noisy rate", 0.9, 0.5, 5, "decay_ratio", 40.0, 0.25, 0.3, "ramp")
    h_force = headline("F_transmitted", L=40.0, value=0.2, se=0.01, protocol="ramp", k_fr=0.3)
    ds = budget([h_rate, h_noisy, h_force], {"conv_ramp_steps_b": lad})
    p = list(ds["budget_parameter"].values).index("ramp_steps")
    heads = list(ds["headline"].values)
    assert ds["bias_lower_bound"].values[heads.index(h_rate.key), p] == 1
    assert ds["bias_lower_bound"].values[heads.index(h_force.key), p] == 0
    assert row(ds, h_rate.key)["lower_bound"] == "ramp_steps"
    assert row(ds, h_rate.key)["largest_lower_bound"] == "yes"
    assert row(ds, h_rate.key)["limited_by"] == "numerics"     # bound >= 44 % against 2.8 %
    assert row(ds, "fig.noisy")["limited_by"] == "unknown"     # 44 % or more against 154 %
    assert row(ds, h_force.key)["lower_bound"] == ""
    macros = manuscript.Macros()
    manuscript.budget_macros(ds, macros)
    plain = macros.expected()
    assert plain["val@" + manuscript._key(f"budget.{h_rate.key}.bias")].startswith("at least ")
    assert plain["val@" + manuscript._key("budget.unknown_lower")] == "1"
    assert r"\ddag" in macros.raw[-1] and r"$\geq$" in macros.raw[-1]
    # the same ladder passing: a first-order estimate, as before
    lad.attrs["status"] = "pass"
    ds = budget([h_rate], {"conv_ramp_steps_b": lad})
    assert ds["bias_lower_bound"].values.sum() == 0


def test_two_numbers_with_one_key_are_refused():
    h = headline()
    with pytest.raises(ValueError, match="fig.F_transmitted"):
        budget([h, h], {})


@pytest.mark.parametrize("ratio", [0.01, 0.025, 0.1])
def test_euler_discretisation_matches_the_discrete_chain_and_its_lowest_order(ratio):
    """(4/l0^2) sin^2(pi l0/(2 lambda)) against pi^2/lambda^2 (the continuum), and -x^2/3 for
    small x = pi l0/(2 lambda): the discrete chain buckles at a lower load."""
    lam, l0 = 1.0, ratio
    exact = (4.0 / l0**2) * math.sin(math.pi * l0 / (2 * lam)) ** 2 / (math.pi**2 / lam**2) - 1.0
    assert eb.euler_discretisation(l0, lam) == pytest.approx(exact, rel=1e-12)
    x = math.pi * l0 / (2 * lam)
    assert eb.euler_discretisation(l0, lam) == pytest.approx(-x**2 / 3, rel=x**2)
    assert eb.euler_discretisation(l0, lam) < 0


# -- the figure kinds' headline numbers, through the postprocess step -------------------------------
from confined_rod.analysis import figures, postprocess  # noqa: E402

from .test_ensembles import _profile, _sim  # noqa: E402


def test_transmitted_force_headlines_are_the_fraction_with_the_standard_error_of_the_mean():
    sims = {"L20-s0": _sim(20.0, 0, 0.10), "L20-s1": _sim(20.0, 1, 0.12), "L20-s2": _sim(20.0, 2, 0.11),
            "L40-s0": _sim(40.0, 0, 0.08), "L40-s1": _sim(40.0, 1, 0.09)}
    ds = postprocess.build("f6", {"kind": "transmitted_force", "scenes": {}}, sims)
    heads = {h.key: h for h in figures.headlines("f6", ds)}
    h = heads["f6.fraction.L20"]
    assert h.value == pytest.approx(0.11 / 0.25, rel=1e-12)
    assert h.stat_error == pytest.approx(np.std([0.10, 0.12, 0.11], ddof=1) / np.sqrt(3) / 0.25, rel=1e-12)
    assert (h.n_seeds, h.quantity, h.L, h.k_fr) == (3, "F_transmitted", 20.0, 0.8)
    assert h.numerics == {"tol": 1e-4}      # the effective tolerance its members ran at


def test_force_profile_headlines_give_the_decay_rate_over_the_simple_model():
    """Members whose profile decays as the simple model with its rate scaled by 1.2, 1.0, 0.8:
    the decay ratio's mean is 1 and its standard error 0.2/sqrt(3) (up to the bulk fit's
    window, a few per cent); the printed-constant run has no headline."""
    members = {"c-s0": _profile(0, 1.2), "c-s1": _profile(1, 1.0), "c-s2": _profile(2, 0.8)}
    ds = postprocess.build("f4", {"kind": "force_profile", "scenes": {}}, members)
    heads = {h.key: h for h in figures.headlines("f4", ds)}
    frac = heads["f4.fraction.c"]
    assert frac.value == pytest.approx(float(ds["transmitted_fraction"][0]), rel=1e-14)
    decay = heads["f4.decay_ratio.c"]
    assert decay.n_seeds == 3 and decay.quantity == "decay_ratio"
    assert decay.value == pytest.approx(1.0, rel=0.05)
    assert decay.stat_error == pytest.approx(0.2 / np.sqrt(3), rel=0.1)
    ds.attrs["bending_constant"] = "paper"
    assert figures.headlines("f4", ds) == []


def test_budget_labels_set_their_units_in_math_and_escape_the_rest():
    from confined_rod.claims import manuscript

    tex = manuscript.budget_label_tex("first threshold [pi^2 EI/L^2], L/R = 10 (thr_L10)")
    assert tex == r"first threshold [$\pi^2 EI/L^2$], $L/R$ = 10 (thr\_L10)"
    assert manuscript.budget_label_tex("bulk decay rate / (k_fr R/4EI), panel a") == \
        r"bulk decay rate / ($k_{\rm fr}R/4EI$), panel a"


def test_few_seeds_get_students_factor_and_a_shift_from_another_rod_is_flagged_transferred():
    """Five seeds: the statistical 95 % half-width is t(4) = 2.776 standard errors, not 1.96; a
    ladder comparison of 10 paired seeds bounds its shift with t(9) = 2.262; the l0 ladder at
    L/R = 80 stands for a number at L/R = 320 as a transferred term, one at L/R = 80 is not."""
    from scipy.stats import t

    lads = {"conv_l0": ladder("l0", 80, {"F_transmitted": (-0.016, 0.0056)}, dof=9)}
    far, near = headline(L=320.0, value=0.1, se=0.002), headline(L=80.0, value=0.1, se=0.002)
    ds = budget([far, near], lads)
    p = list(ds["budget_parameter"].values).index("l0")
    r_far, r_near = row(ds, far.key), row(ds, near.key)
    assert r_far["stat_95_percent"] == pytest.approx(100 * t.ppf(0.975, 4) * 0.02, rel=1e-9)
    i = list(ds["headline"].values).index(far.key)
    assert ds["bias_bound"].values[i] == pytest.approx(2 * (0.016 + t.ppf(0.975, 9) * 0.0056), rel=1e-9)
    assert ds["bias_transferred"].values[i, p] == 1 and r_far["transferred"] == "l0"
    assert r_far["largest_transferred"] == "yes" and r_near["largest_transferred"] == "no"
    assert "transferred" in str(ds["bias_source"].values[i, p])


def test_a_share_of_seeds_has_its_wilson_interval():
    from confined_rod.analysis.figures.transition import wilson_interval

    lo, hi = wilson_interval(5, 10)
    assert (lo, hi) == pytest.approx((0.2366, 0.7634), abs=1e-4)       # the textbook values for 5/10
    assert wilson_interval(0, 10)[0] == 0.0 and wilson_interval(0, 10)[1] == pytest.approx(0.2775, abs=1e-4)
    with pytest.raises(ValueError, match="k = 11"):
        wilson_interval(11, 10)


def test_a_shift_of_the_bulk_decay_rate_is_carried_to_a_longer_rod_exactly():
    """A 2 % bias of the bulk decay rate (helices built with c_K 1.02 against 1.00, the same tip
    and lower region; link 0 at the loaded end) moves F(L) by a few per cent at L/R = 80 and by
    more at L/R = 320, where the bulk adds more to 1/|F_z|: the L/R = 80 ladder's shift with its
    decay-rate part carried to the longer rod's F(L) and bulk part gives the longer rod's own shift
    to round-off, where the shift taken as it is would miss it by a fifth. A bias of the ends only
    (a tip 2 R longer on one rung, no decay-rate bias) is taken as the same relative shift, and the
    same rod gets its own shift back."""
    from confined_rod.analysis import error_budget as EB
    from confined_rod.analysis import regions
    from confined_rod.analysis.figures.convergence import _split_by_region

    from .shapes import prescribed_helix

    def split(L, pub, fine):
        sims = {f"{r}-s{s}": prescribed_helix(L=L, seed=s, bottom=10.0, **{"tip": 6.0, **kw})
                for r, kw in (("pub", pub), ("fine", fine)) for s in (0, 1)}
        groups = [[f"pub-s{s}" for s in (0, 1)], [f"fine-s{s}" for s in (0, 1)]]
        shift, _, n, cov, at = _split_by_region(sims, groups, 0, 1)
        F = {r: abs(float(sims[f"{r}-s0"]["F_z"].values[-1])) for r in ("pub", "fine")}
        return (shift[:3], cov, at[0], at[1], n), F["pub"] / F["fine"] - 1.0, at

    rate = (0.02, 0.0, math.inf)         # the decay ratio's shift the ladder measures: c_K 1.02 / 1.00 - 1
    short, short_shift, _ = split(80.0, {"c_K": 1.02}, {"c_K": 1.0})
    _, long_shift, long_rod = split(320.0, {"c_K": 1.02}, {"c_K": 1.0})
    assert abs(long_shift) > 1.15 * abs(short_shift) > 0.01
    got, se, dof = EB.rescaled(short, long_rod, rate)
    assert got == pytest.approx(long_shift, rel=1e-9) and se == pytest.approx(0.0, abs=1e-12) and dof == 1
    same, _, _ = EB.rescaled(short, (short[2], short[3]), rate)
    assert same == pytest.approx(short_shift, rel=1e-9)
    ends, ends_shift, _ = split(80.0, {"tip": 8.0}, {})
    _, _, long_rod = split(320.0, {"tip": 8.0}, {})
    assert abs(ends_shift) > 1e-3
    assert EB.rescaled(ends, long_rod, (0.0, 0.0, math.inf))[0] == pytest.approx(ends_shift, rel=1e-9)
    assert regions.REGIONS == ("tip", "bulk", "lower")
