"""Convergence studies: Richardson extrapolation, the like-with-like rule and the
build-failing check, on synthetic scene datasets with known answers."""
import re

import numpy as np
import pytest
import xarray as xr

from confined_rod import layout
from confined_rod.analysis.figures import convergence as studies
from confined_rod.analysis.measure import bulk_pitch


def fake_sim(value, F, L_z=10.0, turns=2.0, param="l0"):
    """A minimal scene dataset: a helix of `turns` turns on a 40-link contact stretch."""
    n = 40
    phi = np.linspace(0.0, 2 * np.pi * turns, n)
    s = np.linspace(0.0, 20.0, n)
    z = 0.5 * s
    return xr.Dataset(
        {"phi": ("s_helix", phi), "z": ("s_link", z), "F_transmitted": ((), F), "L_z": ((), L_z),
         "converged": ((), 1), "wall_time": ((), 0.1)},
        coords={"s_link": s, "s_helix": ("s_helix", s)}, attrs={param: value})


def test_richardson_recovers_order_and_limit_of_a_power_law():
    h = np.array([1.0, 0.5, 0.25, 0.125])
    f = 3.0 + 0.7 * h**2
    p, lim, note = studies.richardson(h, f)
    assert note == "" and p == pytest.approx(2.0, rel=1e-9) and lim == pytest.approx(3.0, rel=1e-12)


def test_richardson_flags_non_monotone_and_non_geometric_ladders():
    assert "monoton" in studies.richardson(np.array([1.0, 0.5, 0.25]), np.array([1.0, 1.1, 1.05]))[2]
    assert "geometric" in studies.richardson(np.array([1.0, 0.5, 0.1]), np.array([1.0, 1.1, 1.15]))[2]
    # noise below the resolved level counts as converged, not as non-monotone
    p, lim, note = studies.richardson(np.array([1.0, 0.5, 0.25]), np.array([1.0, 1.0 + 1e-6, 1.0 - 1e-6]),
                                      resolved=1e-5)
    assert "converged" in note and lim == 1.0 - 1e-6 and p == 0.0
    # converged differences that still shrink as h^2 report their order, the finest value as limit
    h = np.array([1.0, 0.5, 0.25])
    p, lim, note = studies.richardson(h, 3.0 + 1e-7 * h**2, resolved=1e-5)
    assert p == pytest.approx(2.0, rel=1e-6) and lim == 3.0 + 1e-7 * 0.25**2
    assert "converged; observed order 2.00" in note


def ladder(F_of_h, turns=(2.0, 2.0, 2.0), pub=1.0, tol=0.05, unsettled=None):
    """A three-rung l0 ladder of constructed runs; ``unsettled``: the rung whose run ended at its
    step cap."""
    hs = (1.0, 0.5, 0.25)
    sims = {f"r{i}": fake_sim(h, F_of_h(h), turns=t) for i, (h, t) in enumerate(zip(hs, turns))}
    if unsettled:
        sims[unsettled].attrs["status"] = "step_cap"
    cfg = {"parameter": "l0", "tolerance": tol}
    return studies.build(cfg, sims, {"publication_value": pub})


def test_convergence_passes_and_fails_on_the_distance_from_the_limit():
    ds = ladder(lambda h: 0.1 * (1 + 0.02 * h))  # publication rung (h = 1) is 2 % off
    i = list(ds.observable.values).index("F_transmitted")
    assert float(ds.F_transmitted_limit) == pytest.approx(0.1, rel=1e-9)
    assert float(ds.observed_order[i]) == pytest.approx(1.0, rel=1e-6)
    assert float(ds.publication_distance[i]) == pytest.approx(0.02, rel=1e-6)
    assert ds.attrs["status"] == "pass"
    assert "pass" in studies.check(ds, "conv")
    bad = ladder(lambda h: 0.1 * (1 + 0.2 * h))  # 20 % off, tolerance 5 %
    assert bad.attrs["status"] == "fail"
    with pytest.raises(studies.ConvergenceError, match=r"l0 = 1 is F_transmitted 20 %"):
        studies.check(bad, "conv")
    # a failure the config reports instead of stopping the build: the verdict line, still a fail
    assert studies.check(bad, "conv", on_fail="warn").endswith(": fail")


def test_different_states_make_the_check_inconclusive_and_say_why():
    ds = ladder(lambda h: 0.1 * (1 + 0.02 * h), turns=(0.3, 2.0, 2.1))  # planar coarse rung, helical fine rungs
    assert ds.attrs["status"].startswith("inconclusive") and "different states" in ds.attrs["status"]
    assert "pitch" not in list(ds.observable.values)  # pitch is compared only between helices
    with pytest.raises(studies.ConvergenceError, match="inconclusive"):
        studies.check(ds, "conv", on_inconclusive="fail")
    assert "inconclusive" in studies.check(ds, "conv", on_inconclusive="warn")
    wound = ladder(lambda h: 0.1 * (1 + 0.02 * h), turns=(2.0, 2.0, 3.0))
    assert "winding differs" in wound.attrs["status"]
    # the figure never draws the planar rung's pitch (0) as a value
    fig = studies.plot(ds.assign_attrs(title="t"))
    pitch_ax = next(ax for ax in fig.axes if ax.get_visible() and "not helical" in ax.get_title())
    drawn = np.concatenate([ln.get_xdata() for ln in pitch_ax.get_lines()])
    assert 1.0 not in drawn and set(drawn) == {0.5, 0.25}
    assert "rung(s) 1 not helical" in pitch_ax.get_title()


def test_bulk_pitch_of_a_helix():
    sim = fake_sim(1.0, 0.1, turns=2.0)  # z = s/2 over 20 R and 2 turns: pitch 5 R
    assert bulk_pitch(sim) == pytest.approx(5.0, rel=1e-9)
    assert bulk_pitch(fake_sim(1.0, 0.1, turns=0.5)) == 0.0


def test_a_long_verdict_is_shortened_for_the_figure_title_at_its_clauses_not_cut_mid_number():
    from confined_rod.analysis.figures.convergence import TITLE_LINES, _title_lines
    ramp = ("inconclusive (about 150 seeds per rung would decide): F_transmitted at 256: shift +3.7 +- 2.8 % (95 % "
            "bound 9.2 %), resolution 10 %, AD p = 0.25, n = 16/16: undecided 3 %; about 69 seeds per rung would "
            "decide; pitch_ratio at 256: shift +2.5 +- 2.3 % (95 % bound 7 %), resolution 8.3 %, AD p = 0.1, "
            "n = 16/16: undecided 2 %; about 150 seeds per rung would decide")
    lines = _title_lines("convergence in $n_{ramp}$: ", ramp)
    text = " ".join(lines)
    assert len(lines) <= TITLE_LINES and "..." not in text
    assert ("$|F_z(L)|$ at 256: +3.7 $\\pm$ 2.8 % (95 % bound 9.2 %); pitch ratio at 256: +2.5 $\\pm$ 2.3 % "
            "(95 % bound 7 %)") in text
    assert "_" not in re.sub(r"\$[^$]*\$", "", text)       # no dataset key in a title (outside math)
    assert text.endswith(f"(full verdict: {layout.CHECKS})")
    k_w = ("inconclusive: F_transmitted: differences do not shrink monotonically (no asymptotic range); L_z: finest "
           "differences below a tenth of the tolerance (converged); pitch: finest differences below a tenth of the "
           "tolerance (converged)")
    text = " ".join(_title_lines("convergence in $k_w$: ", k_w))
    assert "L_z" not in text and "$|F_z(L)|$: differences do not shrink monotonically" in text
    assert _title_lines("convergence in $l_0$: ", "pass") == ["convergence in $l_0$: pass"]
    served = ("pass: local relation within 2 %, final states that fig4_Fonl_ramp.b, protocols.ramp report within "
              "their tolerances (largest shifts: helix_balance +0.1 % (resolution 0.3 %))")
    text = " ".join(_title_lines("convergence in $n_{ramp}$: ", served))
    assert "final states within the served figures' tolerances" in text and "fig4" not in text



def test_a_served_tolerance_is_not_widened_by_stuck_seeds_on_either_rung():
    """A rung with 3 of 20 seeds stuck in another state (a quarter of the others' value) must not
    widen the tolerance the shift is held to, whichever rung it is: the served figure's error is
    taken from the smaller spread of the publication and the finest rung, and the shift the stuck
    seeds make is then undecided, not passed (the case of the Fig 4(b) ramp ladder, whose stuck
    seeds turned up at the finest rung)."""
    import numpy as np

    from confined_rod.analysis import distributions
    from confined_rod.analysis.figures.convergence import STATE_KEYS, ladder_verdict, state_tolerances

    rng = np.random.default_rng(3)
    fine = 1.0 + 0.03 * rng.standard_normal(20)
    pub = fine * (1 + 0.002 * rng.standard_normal(20))
    pub[[6, 8, 11]] = 0.26                                       # stuck at the publication value only
    k = STATE_KEYS[0]
    members = {k: np.array([pub, fine])}
    has = np.ones((2, 20), dtype=np.int8)
    served = [{"name": "fig.b", "seeds": 3, "reports": [k]}]
    for rungs in ((0, 1), (1, 0)):
        tol, origin = state_tolerances(members, has, rungs, 0.03, served)[k]
        assert tol == pytest.approx(distributions.budget_tolerance(fine, 3))
        assert "smaller relative spread of the publication and the finest rung" in origin
    assert tol < distributions.budget_tolerance(pub, 3) / 3    # the stuck rung's spread would pass it
    seeds = np.tile(np.arange(20), (2, 1))
    members["helix_balance"] = np.array([fine, fine])           # the local relation holds
    for order, values in (((pub, fine), (128.0, 256.0)), ((fine, pub), (256.0, 512.0))):
        members[k] = np.array(order)                             # stuck at the publication rung, then the finest
        status, notes, _ = ladder_verdict(np.array(values), members, has, 0, 0.02, 0.03, seeds=seeds,
                                          served=served)
        assert status.startswith("inconclusive") and f"{k} at {values[1]:g}" in status, status


def test_a_pass_names_the_distributions_the_ad_test_tells_apart():
    """Two rungs with the same mean but different spreads (a shape difference the mean misses):
    the ladder passes on its means and says which distributions the AD test separates."""
    import numpy as np

    from confined_rod.analysis.figures.convergence import ladder_verdict

    rng = np.random.default_rng(0)
    narrow = 1.0 + 0.002 * rng.standard_normal(64)
    wide = np.where(np.arange(64) % 2 == 0, 0.985, 1.015) + 0.0005 * rng.standard_normal(64)
    members = {"F_transmitted": np.array([wide, narrow]), "helix_balance": np.array([narrow, narrow])}
    has = np.ones((2, 64), dtype=np.int8)
    status, _, _ = ladder_verdict(np.array([1.0, 0.5]), members, has, 0, 0.02, 0.03)
    assert status.startswith("pass"), status
    assert "Anderson-Darling test tells the rungs' distributions apart at 5 % for F_transmitted" in status
    same, _, _ = ladder_verdict(np.array([1.0, 0.5]), {k: np.array([narrow, narrow]) for k in members}, has, 0,
                                0.02, 0.03)
    assert same.startswith("pass") and "Anderson-Darling" not in same


def test_loosely_wound_seeds_are_counted_and_their_share_described_not_filtered():
    """Three of 20 seeds of the finest rung end loosely wound (wall force a quarter of the
    torque-free helix's, decay ratio 0.26). Their share is described with McNemar's exact p (0 and
    3 seeds loosely wound on one rung only: p = 2 (1/2)^3 = 0.25), and the decay ratio is still
    compared over every seed (the state it serves is the whole ensemble's): the rare state's shift
    of the mean is undecided with 20 seeds."""
    import numpy as np

    from confined_rod.analysis.figures.convergence import ladder_verdict

    rng = np.random.default_rng(5)
    tight = 1.0 + 0.03 * rng.standard_normal(20)
    pub = tight * (1 + 0.002 * rng.standard_normal(20))
    fine = tight.copy()
    fine[[2, 9, 14]] = 0.26
    wall = np.array([np.full(20, 1.05), np.where(np.isin(np.arange(20), [2, 9, 14]), 0.26, 1.05)])
    members = {"helix_balance": np.array([tight, tight]), "decay_ratio": np.array([pub, fine]),
               "wall_force_ratio": wall, "loosely_wound": (wall < 0.5).astype(float)}
    has = np.ones((2, 20), dtype=np.int8)
    seeds = np.tile(np.arange(20), (2, 1))
    served = [{"name": "fig.b", "seeds": 3, "reports": ["decay_ratio"]}]
    status, notes, table = ladder_verdict(np.array([256.0, 512.0]), members, has, 0, 0.02, 0.03, seeds=seeds,
                                          served=served)
    assert status.startswith("inconclusive") and "decay_ratio at 512" in status, status
    c = table["cmp"][table["quantity"].index("decay_ratio")]
    assert c.n_a == 20 and c.jumps == 3
    share = [n for n in notes if n.startswith("loosely wound at 256 against 512")]
    assert share and "0 of 20 and 3 of 20" in share[0] and "McNemar exact p = 0.25" in share[0], notes
    assert "not deciding" in share[0]
    same = {**members, "loosely_wound": np.zeros((2, 20))}
    _, notes, _ = ladder_verdict(np.array([256.0, 512.0]), same, has, 0, 0.02, 0.03, seeds=seeds, served=served)
    assert any("0 of 20 and 0 of 20" in n and "McNemar" not in n for n in notes)


def test_the_split_by_region_adds_up_to_the_shift_of_the_mean_even_across_a_jump():
    """Three seeds per rung built with prescribed decay rates (link 0 at the loaded end); one seed
    jumps to a bulk decaying at a quarter of the rate (F(L) changed by tens of per cent). The
    regions' shares sum exactly to mean F_i(L)/mean F_j(L) - 1, where a first-order split
    -F_j dX would miss by the jump's square; the bulk carries it all (tips and lower regions
    built alike)."""
    import numpy as np

    from confined_rod.analysis import regions
    from confined_rod.analysis.figures.convergence import _split_by_region

    from .shapes import prescribed_helix

    rates = {"pub": (1.1, 1.0, 0.25), "fine": (1.05, 1.0, 1.1)}
    sims, groups = {}, []
    for rung, cs in rates.items():
        names = []
        for seed, c in enumerate(cs):
            name = f"{rung}-s{seed}"
            sims[name] = prescribed_helix(c_K=c, seed=seed, tip=6.0, bottom=10.0)
            names.append(name)
        groups.append(names)
    shift, se, n, cov, (F_pub, X_bulk) = _split_by_region(sims, groups, 0, 1)
    F = {k: np.array([abs(float(sims[m]["F_z"].values[-1])) for m in g]) for k, g in zip(rates, groups)}
    exact = F["pub"].mean() / F["fine"].mean() - 1.0
    assert n == 3 and abs(exact) > 0.1
    assert shift[-1] == pytest.approx(exact, rel=1e-9)
    assert shift[:3].sum() == pytest.approx(exact, rel=1e-9)
    assert abs(shift[0]) < 1e-3 * abs(exact) and abs(shift[2]) < 1e-3 * abs(exact)
    # the shares' covariance carries the error of their sum; the rung's own F(L) and bulk part
    assert cov.sum() == pytest.approx(se[-1] ** 2, rel=1e-9)
    assert F_pub == pytest.approx(F["pub"].mean(), rel=1e-12)
    parts = [regions.force_parts(sims[m])["bulk"] for m in groups[0]]
    assert X_bulk == pytest.approx(np.mean(parts), rel=1e-12)


def test_a_loosely_wound_state_on_both_rungs_does_not_widen_the_tolerance_its_share_is_held_to():
    """2 of 32 seeds loosely wound at the publication rung, 9 of 32 at the finest (the Fig 4(b)
    ramp at 256 against 1024 steps): the decay ratio's tolerance comes from the spread of the seeds
    that are not loosely wound (the state's own spread would widen it past the shift its share
    makes), the shift of the mean is beyond it, and the failure names the share with McNemar's p
    (0 and 7 seeds loosely wound on one rung only: p = 2 (1/2)^7 = 0.016)."""
    import numpy as np

    from confined_rod.analysis import distributions
    from confined_rod.analysis.figures.convergence import ladder_verdict, state_tolerances

    rng = np.random.default_rng(11)
    n = 32
    tight = 0.93 + 0.03 * rng.standard_normal(n)
    loose_pub, loose_fine = np.isin(np.arange(n), [3, 17]), np.isin(np.arange(n), [3, 17, 1, 5, 8, 12, 20, 25, 29])
    pub = np.where(loose_pub, 0.22, tight * (1 + 0.002 * rng.standard_normal(n)))
    fine = np.where(loose_fine, 0.22, tight)
    wall = np.array([np.where(loose_pub, 0.22, 1.0), np.where(loose_fine, 0.22, 1.0)])
    members = {"helix_balance": np.array([tight, tight]), "decay_ratio": np.array([pub, fine]),
               "wall_force_ratio": wall, "loosely_wound": (wall < 0.5).astype(float)}
    has = np.ones((2, n), dtype=np.int8)
    served = [{"name": "fig.b", "seeds": 3, "reports": ["decay_ratio"]}]
    tol, _ = state_tolerances(members, has, (0, 1), 0.03, served)["decay_ratio"]
    expected = min(distributions.budget_tolerance(pub[~loose_pub], 3),
                   distributions.budget_tolerance(fine[~loose_fine], 3))
    assert tol == pytest.approx(expected)
    assert distributions.budget_tolerance(pub, 3) > 3 * tol     # the state's spread would have widened it
    seeds = np.tile(np.arange(n), (2, 1))
    status, _, _ = ladder_verdict(np.array([256.0, 1024.0]), members, has, 0, 0.02, 0.03, seeds=seeds,
                                  served=served)
    assert status.startswith("fail: decay_ratio at 1024"), status
    assert "2 of 32 and 9 of 32 seeds" in status and "McNemar exact p = 0.016" in status, status


def test_a_served_tolerance_names_whose_spread_it_took_when_every_seed_is_loosely_wound():
    """Every seed loosely wound on both rungs (the Fig 4(c) ramp): the ratios' spread comes from
    all seeds, and the tolerance's note says so instead of naming seeds that are not loosely wound."""
    import numpy as np

    from confined_rod.analysis.figures.convergence import state_tolerances

    rng = np.random.default_rng(5)
    n = 16
    loose = 0.2 + 0.05 * rng.standard_normal((2, n))
    members = {"decay_ratio": loose, "wall_force_ratio": loose, "loosely_wound": np.ones((2, n))}
    has = np.ones((2, n), dtype=np.int8)
    served = [{"name": "fig.c", "seeds": 3, "reports": ["decay_ratio"]}]
    _, origin = state_tolerances(members, has, (0, 1), 0.03, served)["decay_ratio"]
    assert "all seeds (fewer than two are not loosely wound)" in origin, origin
    assert "the seeds that are not loosely wound on" not in origin
    members["loosely_wound"] = np.zeros((2, n))
    _, origin = state_tolerances(members, has, (0, 1), 0.03, served)["decay_ratio"]
    assert "the seeds that are not loosely wound on the publication" in origin, origin


def test_a_single_run_ladder_says_whether_its_limit_is_extrapolated_or_the_finest_rung():
    """Richardson's limit where the differences shrink as a power (F 2 % off at h = 1); the finest
    rung's value where they are already below a tenth of the tolerance, named as such."""
    ds = ladder(lambda h: 0.1 * (1 + 0.02 * h))
    line = studies.check(ds, "conv")
    assert "Richardson's extrapolation for F_transmitted" in line, line
    assert "L_z" in line.split("the finest rung for")[1], line  # constructed L_z does not vary with h
    assert ds.F_transmitted_limit.attrs["comment"].startswith("Richardson")
    flat = ladder(lambda h: 0.1 * (1 + 1e-6 * h))
    assert "the finest rung for F_transmitted" in studies.check(flat, "conv")
    assert flat.F_transmitted_limit.attrs["comment"].startswith("finest rung's value")
