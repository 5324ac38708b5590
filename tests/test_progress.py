"""The build's progress line: jobs counted per rule, the estimate of the jobs not yet started,
the correction by the measured speed, and the logger plugin that Snakemake loads."""
from __future__ import annotations

import importlib

import pytest

from confined_rod.pipeline.progress import CALIBRATE_AFTER, REPORT_EVERY_S, RULE_ESTIMATE_S, BuildProgress


def test_time_left_from_the_estimates_and_the_measured_speed():
    p = BuildProgress(cores=2, t0=0.0)
    line = p.plan({"simulate": 10, "figure": 2})
    assert "12 jobs to run" in line
    for j in range(10):                                   # every simulation estimated at 8 s
        p.start(j, "simulate", 8.0)
    # nothing finished: 10 x 8 s of simulations and 2 figures at the rule's default, on 2 cores
    assert p.remaining_estimate() == pytest.approx(80.0 + 2 * RULE_ESTIMATE_S["figure"])
    now = 0.0
    for j in range(CALIBRATE_AFTER):                       # the machine runs them 2x slower than estimated
        now += 8.0                                         # two cores: 2 jobs of 16 s each per 16 s
        p.finish(j, now=now)
    assert p.speed(now) == pytest.approx(now * 2 / (CALIBRATE_AFTER * 8.0))
    left_est = p.remaining_estimate()
    assert left_est == pytest.approx((10 - CALIBRATE_AFTER) * 8.0 + 2 * RULE_ESTIMATE_S["figure"])
    line = p.finish(CALIBRATE_AFTER, now=now + REPORT_EVERY_S)
    assert line.startswith(f"progress: {CALIBRATE_AFTER + 1} of 12 jobs done") and "left" in line


def test_reports_are_throttled_and_the_last_job_is_always_reported():
    p = BuildProgress(cores=1, t0=0.0)
    p.plan({"postprocess": 3})
    for j in range(3):
        p.start(j, "postprocess", None)
    assert p.finish(0, now=100.0) is not None             # first report
    assert p.finish(1, now=101.0) is None                 # within REPORT_EVERY_S of it
    assert p.finish(2, now=102.0) == "progress: 3 of 3 jobs done in 1.7 min"


def test_snakemake_finds_the_plugin():
    from snakemake_interface_logger_plugins.registry import LoggerPluginRegistry

    assert importlib.import_module("snakemake_logger_plugin_confined_rod").LogHandler
    assert "confined-rod" in LoggerPluginRegistry().plugins
