"""The build's progress with the time left, for the workflow's logger plugin
(``snakemake_logger_plugin_confined_rod``, selected by the profiles: ``logger: [confined-rod]``).

Every rule declares the resource ``est_s``, the job's estimated wall time in seconds: for a
scene's job the estimate from measured runs (``limits.estimated_wall_time`` via the rules'
priorities; nothing for a scene moved into place from its batch), for the other rules
:data:`RULE_ESTIMATE_S`.  When the build starts, the workflow hands over the estimate of every
job it is going to run (:func:`plan_of`, from Snakemake's DAG in the Snakefile's ``onstart``).
The time left is then the estimates of the jobs not yet started and the rest of the running
ones, scaled by how fast this machine runs them (the finished jobs' measured wall times
against their estimates), shared over the cores, and never less than the longest job left.
Without a plan (Snakemake announces a job only when it starts) the jobs not yet started are
counted per rule at the mean estimate of that rule's started jobs.  The lines are plain text,
one per report, legible on a terminal and in a log file."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

#: typical wall time (s) of one job of the rules without a per-job estimate: medians of the CI
#: build of 2026-12-03 (results/benchmarks; most of it the start-up of the interpreter)
RULE_ESTIMATE_S = {"postprocess": 2.0, "figure": 3.6, "convergence_check": 1.5, "claims": 14.0,
                   "paper_sources": 1.8, "paper": 2.5, "views": 6.2, "all": 0.0}
DEFAULT_ESTIMATE_S = 2.0
#: rule views draws every simulation: seconds per simulation beyond the job's start-up (the
#: publication build of 5bc6f88: 64.7 s for 1 101 simulations, a build's longest job but one
#: whose RULE_ESTIMATE_S, measured on the CI grid's 82, was 6.2 s)
VIEW_S_PER_SIM = 0.057
#: seconds between two reports (the last job is always reported)
REPORT_EVERY_S = 10.0
#: finished jobs (with an estimate) before the estimate is corrected by the measured speed
CALIBRATE_AFTER = 5
#: the measured speed is bounded to this factor either way (a few odd jobs must not swing it)
SPEED_BOUND = 10.0
#: a job estimated below this (s) measures the per-job work the estimates leave out (model())
SHORT_JOB_S = 10.0
#: attribute of the log record by which the workflow hands its plan to the logger plugin
PLAN_ATTRIBUTE = "confined_rod_plan"


def duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def views_estimate(n_sims: int) -> int:
    """The est_s of rule views: the start-up and VIEW_S_PER_SIM per simulation it draws."""
    return int(round(RULE_ESTIMATE_S["figure"] + VIEW_S_PER_SIM * n_sims))


def job_estimate(rule: str, est_s: float | None) -> float:
    """A job's estimated wall time (s): its ``est_s`` resource, else its rule's typical time."""
    return float(est_s) if est_s is not None else RULE_ESTIMATE_S.get(rule, DEFAULT_ESTIMATE_S)


def plan_of(jobs) -> dict[int, tuple[str, float]]:
    """{job id: (rule, estimated s)} of Snakemake jobs (``workflow.dag.needrun_jobs()``)."""
    plan = {}
    for job in jobs:
        res = job.resources
        est = res.get("est_s") if hasattr(res, "get") else None
        plan[int(job.jobid)] = (job.rule.name, job_estimate(job.rule.name, est))
    return plan


def plan_message(plan: dict[int, tuple[str, float]]) -> str:
    """The line that hands the plan over: the jobs and their summed estimate."""
    return f"progress: {len(plan)} jobs planned, {sum(e for _, e in plan.values()):.0f} job-s estimated"


@dataclass
class BuildProgress:
    cores: int = 1
    t0: float = field(default_factory=time.monotonic)
    counts: dict[str, int] = field(default_factory=dict)       # jobs to run per rule (run info)
    planned: dict[int, tuple[str, float]] = field(default_factory=dict)   # every job to run (plan_of)
    running: dict[int, tuple[str, float, float]] = field(default_factory=dict)  # rule, estimate, start
    started: dict[str, list[float]] = field(default_factory=dict)
    finished: set[int] = field(default_factory=set)
    done: int = 0
    done_estimate: float = 0.0     # the finished jobs' estimates ...
    done_measured: float = 0.0     # ... and their measured wall times (jobs with an estimate only)
    done_timed: int = 0
    busy: float = 0.0              # wall seconds of all finished jobs
    short_sums: list[float] = field(default_factory=lambda: [0.0] * 3)  # short jobs: n, estimated, measured
    last_report: float = -1e9

    @property
    def total(self) -> int:
        return len(self.planned) if self.planned else sum(self.counts.values())

    def plan(self, counts: dict[str, int]) -> None:
        """The jobs to run per rule (Snakemake's run info; the plan, :meth:`set_plan`, follows)."""
        self.counts = {r: int(n) for r, n in counts.items()}

    def set_plan(self, planned: dict[int, tuple[str, float]]) -> str:
        """The estimate of every job to run; the line announcing it."""
        self.planned = {int(j): (str(r), float(e)) for j, (r, e) in planned.items()}
        left = self.wall_left(self.t0)
        return (f"progress: {self.total} jobs to run, about {duration(left)} on {self.cores} "
                f"core{'s' if self.cores != 1 else ''} (estimated from measured runs)")

    def start(self, jobid: int, rule: str, est_s: float | None, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        est = self.planned[jobid][1] if jobid in self.planned else job_estimate(rule, est_s)
        self.running[jobid] = (rule, est, now)
        self.started.setdefault(rule, []).append(est)

    def _rule_mean(self, rule: str) -> float:
        seen = self.started.get(rule)
        return sum(seen) / len(seen) if seen else RULE_ESTIMATE_S.get(rule, DEFAULT_ESTIMATE_S)

    def _waiting(self) -> list[float]:
        """The estimates of the jobs not yet started (without a plan: per rule, its count left at
        the mean of its started jobs)."""
        if self.planned:
            return [e for j, (_, e) in self.planned.items() if j not in self.running and j not in self.finished]
        return [max(0, n - len(self.started.get(r, []))) * self._rule_mean(r) for r, n in self.counts.items()]

    def remaining_estimate(self) -> float:
        """Estimated job-seconds of the jobs not yet started and of the running ones (their whole
        estimates: :meth:`wall_left` subtracts what has been run)."""
        return sum(self._waiting()) + sum(est for _, est, _ in self.running.values())

    def model(self, now: float | None = None) -> tuple[float, float]:
        """(a, v): a job estimated at e > 0 seconds takes a + v e on this machine (a job estimated
        at 0, a scene moved into place from its batch, takes nothing). v is the finished jobs'
        measured over estimated time, a the mean excess of the jobs estimated at under
        SHORT_JOB_S (the work per job that the estimates leave out; the long jobs fix v, the short
        ones a), a >= 0 and v bounded by SPEED_BOUND either way; (0, 1) until CALIBRATE_AFTER jobs
        have finished."""
        if self.done_timed < CALIBRATE_AFTER or self.done_estimate <= 0:
            return 0.0, 1.0
        v = self.done_measured / self.done_estimate
        if now is not None and self.running:
            # the longest jobs start first and finish last: a running job will take at least what it
            # has run, which bounds the speed from below before the long jobs have finished
            run = [(now - t, est) for _, est, t in self.running.values() if est > 0]
            v = max(v, (self.done_measured + sum(r for r, _ in run)) / (self.done_estimate + sum(e for _, e in run)))
        v = min(SPEED_BOUND, max(1.0 / SPEED_BOUND, v))
        n_short, e_short, m_short = self.short_sums
        a = max(0.0, (m_short - v * e_short) / n_short) if n_short else 0.0
        return a, v

    def utilisation(self, now: float) -> float:
        """The share of the cores' time spent in jobs so far (the rest: Snakemake's own work between
        jobs, and cores idle for want of a ready job); 1 until CALIBRATE_AFTER jobs have finished."""
        elapsed = now - self.t0
        if self.done_timed < CALIBRATE_AFTER or elapsed <= 0:
            return 1.0
        busy = self.busy + sum(now - t for _, _, t in self.running.values())
        return min(1.0, max(0.2, busy / (elapsed * self.cores)))

    def wall_left(self, now: float) -> float:
        """Wall seconds left: the work left at the measured speed over the cores at the measured
        utilisation, at least the longest single job left."""
        a, v = self.model(now)
        a_job = a if self.planned else 0.0     # without a plan a waiting entry is a rule's jobs, not one job
        running = [max(0.0, (a if est > 0 else 0.0) + v * est - (now - t)) for _, est, t in self.running.values()]
        waiting = [(a_job if e > 0 else 0.0) + v * e for e in self._waiting()]
        work = sum(waiting) + sum(running)
        longest = max(waiting + running + [0.0]) if self.planned else 0.0
        return max(work / (self.cores * self.utilisation(now)), longest)

    def finish(self, jobid: int, now: float | None = None) -> str | None:
        """Record a finished job; a report line if one is due."""
        now = time.monotonic() if now is None else now
        _, est, t = self.running.pop(jobid, ("", 0.0, now))
        self.finished.add(jobid)
        self.busy += now - t
        self.done += 1
        if est > 0:
            self.done_estimate += est
            self.done_measured += now - t
            self.done_timed += 1
            if est < SHORT_JOB_S:
                for i, x in enumerate((1.0, est, now - t)):
                    self.short_sums[i] += x
        last = self.total and self.done >= self.total
        if not last and now - self.last_report < REPORT_EVERY_S:
            return None
        self.last_report = now
        elapsed = now - self.t0
        total = max(self.total, self.done)
        if last:
            return f"progress: {self.done} of {total} jobs done in {duration(elapsed)}"
        return (f"progress: {self.done} of {total} jobs done ({100 * self.done / total:.0f} %), "
                f"{duration(elapsed)} elapsed, about {duration(self.wall_left(now))} left")
