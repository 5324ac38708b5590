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
