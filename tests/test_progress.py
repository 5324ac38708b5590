"""The build's progress line: the plan of every job's estimate handed over by the workflow, the
correction by the measured speed, the time left against a simulated build, and the logger plugin
that Snakemake loads."""
from __future__ import annotations

import heapq
import importlib
import random
from types import SimpleNamespace

import pytest

from confined_rod.pipeline.progress import CALIBRATE_AFTER, REPORT_EVERY_S, RULE_ESTIMATE_S, BuildProgress, plan_of


def test_time_left_from_the_plan_and_the_measured_speed():
    p = BuildProgress(cores=2, t0=0.0)
    plan = {j: ("simulate", 8.0) for j in range(10)} | {10: ("figure", 3.0), 11: ("figure", 3.0)}
    assert "12 jobs to run, about 43 s on 2 cores" in p.set_plan(plan)   # (80 + 6) / 2
    now = 0.0
    for j in range(CALIBRATE_AFTER + 1):                  # the machine runs them 2x slower than estimated
        p.start(j, "simulate", None, now=now)
        now += 16.0
        line = p.finish(j, now=now)
    assert p.model(now) == pytest.approx((0.0, 2.0))     # no excess per job, twice the estimate
    # one core busy all along, the other idle: utilisation 1/2, so the 4 simulations and 2 figures
    # left (2 x (32 + 6) job-s at the measured speed) take 2 x 38 s / (2 x 1/2)
    assert p.utilisation(now) == pytest.approx(0.5)
    assert p.wall_left(now) == pytest.approx(2.0 * 38.0 / (2 * 0.5))
    assert line.startswith(f"progress: {CALIBRATE_AFTER + 1} of 12 jobs done") and "left" in line


def test_a_long_job_bounds_the_time_left_from_below():
    p = BuildProgress(cores=2, t0=0.0)
    p.set_plan({0: ("batch", 100.0), 1: ("figure", 1.0)})
    p.start(0, "batch", None, now=0.0)
    assert p.wall_left(10.0) == pytest.approx(90.0)       # its rest, not (90 + 1) / 2


@pytest.mark.parametrize("truth_over_estimate", [0.5, 1.0, 3.0])
def test_time_left_within_a_factor_1p5_from_a_tenth_of_the_jobs_on(truth_over_estimate):
    """A build of many short and a few long jobs, longest first on 2 cores, whose jobs take a
    random factor 0.5-2 of their estimate times a machine speed: from 10 % of the jobs on, the
    reported time left is within a factor 1.5 of the real one."""
    rnd = random.Random(1)
    est = [rnd.choice([1.0, 2.0, 3.0]) for _ in range(400)] + [rnd.uniform(20, 200) for _ in range(40)]
    order = sorted(range(len(est)), key=lambda j: -est[j])
    true = {j: est[j] * truth_over_estimate * rnd.uniform(0.5, 2.0) for j in order}
    p = BuildProgress(cores=2, t0=0.0)
    p.set_plan({j: ("simulate", est[j]) for j in order})
    free, events, queue, now, said = [0.0, 0.0], [], list(order), 0.0, []
    while queue or events:
        while queue and min(free) <= now:                 # a free core takes the next job
            j = queue.pop(0)
            c = free.index(min(free))
            p.start(j, "simulate", None, now=now)
            free[c] = now + true[j] + 0.3                 # 0.3 s of Snakemake's own work per job
            heapq.heappush(events, (free[c], j))
        now, j = heapq.heappop(events)
        p.finish(j, now=now)
        if p.done >= 0.1 * len(est) and queue:
            said.append((now, p.wall_left(now)))
    ratios = [left / (now - t) for t, left in said]       # now: the end of the build
    assert len(ratios) > 300
    assert 1 / 1.5 <= min(ratios) and max(ratios) <= 1.5, (min(ratios), max(ratios))


def test_without_a_plan_the_jobs_not_yet_started_count_at_their_rules_mean():
    p = BuildProgress(cores=2, t0=0.0)
    p.plan({"simulate": 10, "figure": 2})
    for j in range(10):
        p.start(j, "simulate", 8.0, now=0.0)
    assert p.remaining_estimate() == pytest.approx(80.0 + 2 * RULE_ESTIMATE_S["figure"])


def test_the_plan_reads_the_estimate_of_every_job_of_the_dag():
    jobs = [SimpleNamespace(jobid=3, rule=SimpleNamespace(name="batch"), resources={"est_s": 42}),
            SimpleNamespace(jobid=4, rule=SimpleNamespace(name="figure"), resources={"mem_mb": 1000})]
    assert plan_of(jobs) == {3: ("batch", 42.0), 4: ("figure", RULE_ESTIMATE_S["figure"])}


def test_reports_are_throttled_and_the_last_job_is_always_reported():
    p = BuildProgress(cores=1, t0=0.0)
    p.set_plan({j: ("postprocess", 2.0) for j in range(3)})
    for j in range(3):
        p.start(j, "postprocess", None, now=0.0)
    assert p.finish(0, now=100.0) is not None             # first report
    assert p.finish(1, now=101.0) is None                 # within REPORT_EVERY_S of it
    assert p.finish(2, now=102.0) == "progress: 3 of 3 jobs done in 1.7 min"
    assert REPORT_EVERY_S > 1.0


def test_snakemake_finds_the_plugin():
    from snakemake_interface_logger_plugins.registry import LoggerPluginRegistry

    assert importlib.import_module("snakemake_logger_plugin_confined_rod").LogHandler
    assert "confined-rod" in LoggerPluginRegistry().plugins


def test_the_log_reader_compares_each_estimate_with_the_real_time_left():
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "progress_error", Path(__file__).resolve().parents[1] / "tools" / "progress_error.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    log = ("progress: 10 of 100 jobs done (10 %), 2.0 min elapsed, about 16.0 min left\n"
           "Finished jobid: 7 (Rule: figure)progress: 50 of 100 jobs done (50 %), 6.0 min elapsed, about 3.0 min left\n"
           "progress: 100 of 100 jobs done in 10.0 min\n")
    out = tool.read(log)
    assert out["wall_s"] == 600.0
    assert [r["ratio"] for r in out["rows"]] == pytest.approx([2.0, 0.75])
    assert out["from_10_percent"]["worst_factor"] == pytest.approx(2.0)


def test_the_replay_runs_the_logged_jobs_through_the_estimator():
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "progress_error", Path(__file__).resolve().parents[1] / "tools" / "progress_error.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    block = "[Sun Dec  6 08:{m:02d}:{s:02d} 2026]\nrule batch:\n    jobid: {j}\n    resources: est_s={e}, mem_mb=1\n\n"
    done = "[Sun Dec  6 08:{m:02d}:{s:02d} 2026]\nFinished jobid: {j} (Rule: batch)\n"
    log = "".join(block.format(m=0, s=0, j=j, e=100) for j in (1, 2))                 # two jobs on two cores
    log += done.format(m=1, s=40, j=1) + done.format(m=1, s=40, j=2)
    log += "".join(block.format(m=1, s=40, j=j, e=100) for j in (3, 4)) + done.format(m=3, s=20, j=3)
    log += done.format(m=3, s=20, j=4)
    out = tool.replay(log)
    assert out["wall_s"] == 200.0 and out["lines"] == 4
    assert out["rows"][1]["true_left_s"] == 100.0 and out["rows"][1]["said_left_s"] == pytest.approx(100.0)


def _fit_tool():
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "fit_cost_model", Path(__file__).resolve().parents[1] / "tools" / "fit_cost_model.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool


def test_the_cost_fit_recovers_constructed_exponents_and_keeps_the_prior_of_one_it_cannot_see():
    """Runs timed exactly as t = 3 (L/640 R)^2.3 (ramp_steps/128)^0.7 at one l0 and dx_max: the fit
    returns 2.3 and 0.7 (the prior's pull, a pseudo-run of weight 0.1 towards 1.9 and 1 against 12
    runs spread over a factor 8 in L and 16 in ramp steps, moves them by ~1e-3), ln 3 for the
    coefficient, and for dx_max, which the runs do not vary, the prior 0.5."""
    import math

    from confined_rod import Scene, limits

    tool = _fit_tool()
    items = []
    for L in (80.0, 160.0, 320.0, 640.0):
        for n in (32, 128, 512):
            sc = Scene(L=L, load=0.25, k_fr=0.8, protocol="ramp", ramp_steps=n, name="x")
            items.append(tool.Run(sc, 3.0 * (L / 640.0) ** 2.3 * (n / 128.0) ** 0.7, ""))
    assert {limits.cost_class(r.scene) for r in items} == {"implicit/ramp/friction"}
    c = tool.fit_class(items)
    assert c["L_exponent"] == pytest.approx(2.3, abs=0.02)
    assert c["ramp_exponent"] == pytest.approx(0.7, abs=0.02)
    assert c["dx_exponent"] == pytest.approx(tool.PRIORS["dx"], abs=1e-9)
    assert c["log_coef"] == pytest.approx(math.log(3.0), abs=0.05)


def test_the_solver_estimate_reads_the_fitted_class_and_falls_back_to_the_prior(monkeypatch):
    """A class in the model is predicted from its coefficients (here exp(0) (L/640 R)^2, so a rod of
    L = 320 R costs 1/4 s), capped by a step budget at max_steps x N x the class's time per step
    and link (1000 steps of 640 links at 1 us: 0.64 s, above the model; 250 steps: 0.16 s), and
    beyond its longest fitted rod growing at least as the hand model's L^1.9 (the command line's
    budget must not trust an extrapolation of a shallower fit); a class it lacks from the prior
    model; the committed model names its classes as cost_class does and each class of ten runs
    or more fitted its build's runs within a factor 3 (rms of ln)."""
    import json
    import math

    from confined_rod import Scene, limits

    model = {"classes": {"implicit/straight/friction": {"log_coef": 0.0, "L_exponent": 2.0, "dx_exponent": 0.0}}}
    monkeypatch.setattr(limits, "cost_model", lambda: model)
    straight = Scene(L=320.0, load=0.25, k_fr=0.8, name="a")
    assert limits.estimated_solver_time(straight) == pytest.approx(0.25)
    model["classes"]["implicit/straight/friction"]["step_s_per_link"] = 1e-6
    budget = Scene(L=320.0, load=0.25, k_fr=0.8, max_steps=1000, name="c")
    assert limits.estimated_solver_time(budget) == pytest.approx(0.25)
    assert limits.estimated_solver_time(Scene(L=320.0, load=0.25, k_fr=0.8, max_steps=250, name="d")) == \
        pytest.approx(0.16)
    # beyond the longest fitted rod the length's exponent is at least the hand model's 1.9
    model["classes"]["implicit/straight/friction"] |= {"L_exponent": 1.0, "L_max": 640.0}
    at = {L: limits.estimated_solver_time(Scene(L=L, load=0.25, k_fr=0.8, name="e")) for L in (320.0, 640.0, 1280.0)}
    assert at[640.0] / at[320.0] == pytest.approx(2.0)
    assert at[1280.0] / at[640.0] == pytest.approx(2.0 ** limits.COST_PRIOR_L_EXPONENT)
    helix = Scene(L=320.0, load=0.25, k_fr=0.8, protocol="helix", name="b")
    assert limits.estimated_solver_time(helix) == pytest.approx(limits._prior_solver_time(helix))
    committed = json.loads(limits.COST_MODEL_FILE.read_text())
    solvers, protocols = {"implicit", "explicit"}, set(limits_protocols())
    for key, c in committed["classes"].items():
        solver, protocol, friction = key.split("/")
        assert solver in solvers and protocol in protocols and friction in ("friction", "frictionless")
        if c["runs"] >= 10:  # tools/fit_cost_model.MIN_RUNS_FOR_EXPONENTS: a fitted class, not a coefficient
            assert c["rms_log_error"] < math.log(3.0), key


def limits_protocols():
    from confined_rod.sim.scenes import PROTOCOLS

    return PROTOCOLS


def test_the_replay_can_take_each_jobs_estimate_from_the_current_cost_model():
    """--reestimate: a batch's estimate is its members' (named first-to-last in the figure's order)
    solver estimates and one start-up, a scene run alone its own and a start-up, a scene moved from
    its batch (logged est_s 0) nothing, a rule without scenes its logged estimate."""
    import importlib.util
    from pathlib import Path

    from confined_rod import limits, pipeline

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("progress_error", root / "tools" / "progress_error.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    est = tool.reestimator(str(root / "config" / "ci.yaml"))
    config = pipeline.check(pipeline.read_config(root / "config" / "ci.yaml"))
    members = ["L10-s0", "L10-s1", "L10-s2", "L20-s0"]
    assert est("batch", {"figure": "fig6_FonL", "batch": "L10-s0-to-L20-s0"}, 9.0) == pytest.approx(
        limits.JOB_STARTUP_S + sum(pipeline.solver_estimate(config, "fig6_FonL", m) for m in members))
    assert est("simulate", {"figure": "fig6_FonL", "scene": "L20-s1"}, 3.0) == pytest.approx(
        limits.JOB_STARTUP_S + pipeline.solver_estimate(config, "fig6_FonL", "L20-s1"))
    assert est("simulate", {"figure": "fig6_FonL", "scene": "L20-s1"}, 0.0) == 0.0
    assert est("figure", {"figure": "fig6_FonL"}, None) is None
