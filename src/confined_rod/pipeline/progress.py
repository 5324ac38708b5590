"""The build's progress with the time left, for the workflow's logger plugin
(``snakemake_logger_plugin_confined_rod``, selected by the profiles: ``logger: [confined-rod]``).

Every rule declares the resource ``est_s``, the job's estimated wall time in seconds: for a
scene's job the estimate from measured runs (``limits.estimated_wall_time`` via the rules'
priorities; the start-up alone for a scene moved into place from its batch), for the other
rules :data:`RULE_ESTIMATE_S`.  Snakemake announces a job when it starts, so the jobs not yet
started are counted per rule (its run info) at the mean estimate of that rule's started jobs.
Once a few jobs have finished, the estimate is corrected by how fast this machine runs them
(elapsed against estimated, bounded to a factor 4 either way).  The lines are plain text, one
per report, legible on a terminal and in a log file."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

#: typical wall time (s) of one job of the rules without a per-job estimate: medians of the CI
#: build of 2026-12-03 (results/benchmarks; most of it the start-up of the interpreter)
RULE_ESTIMATE_S = {"postprocess": 2.0, "figure": 3.6, "convergence_check": 1.5, "claims": 14.0,
                   "paper_sources": 1.8, "paper": 2.5, "views": 6.2, "all": 0.0}
DEFAULT_ESTIMATE_S = 2.0
#: seconds between two reports (the last job is always reported)
REPORT_EVERY_S = 10.0
#: finished jobs before the estimate is corrected by the measured speed
CALIBRATE_AFTER = 5


def duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


@dataclass
class BuildProgress:
    cores: int = 1
    t0: float = field(default_factory=time.monotonic)
    counts: dict[str, int] = field(default_factory=dict)       # jobs to run per rule (run info)
    running: dict[int, tuple[str, float]] = field(default_factory=dict)
    started: dict[str, list[float]] = field(default_factory=dict)
    done: int = 0
    done_estimate: float = 0.0
    last_report: float = -1e9

    @property
    def total(self) -> int:
        return sum(self.counts.values())

    def plan(self, counts: dict[str, int]) -> str:
        self.counts = {r: int(n) for r, n in counts.items()}
        return (f"progress: {self.total} jobs to run, about {duration(self.remaining_estimate() / self.cores)} on "
                f"{self.cores} core{'s' if self.cores != 1 else ''} (estimated from measured runs)")

    def start(self, jobid: int, rule: str, est_s: float | None) -> None:
        est = float(est_s) if est_s is not None else RULE_ESTIMATE_S.get(rule, DEFAULT_ESTIMATE_S)
        self.running[jobid] = (rule, est)
        self.started.setdefault(rule, []).append(est)

    def _rule_mean(self, rule: str) -> float:
        seen = self.started.get(rule)
        return sum(seen) / len(seen) if seen else RULE_ESTIMATE_S.get(rule, DEFAULT_ESTIMATE_S)

    def remaining_estimate(self) -> float:
        """Estimated job-seconds not yet done: running jobs and the jobs not yet started."""
        waiting = sum(max(0, n - len(self.started.get(r, []))) * self._rule_mean(r) for r, n in self.counts.items())
        return waiting + sum(est for _, est in self.running.values())

    def speed(self, now: float) -> float:
        """Measured wall time over estimated, once enough jobs have finished (1 before)."""
        if self.done < CALIBRATE_AFTER or self.done_estimate <= 0:
            return 1.0
        return min(4.0, max(0.25, (now - self.t0) * self.cores / self.done_estimate))

    def finish(self, jobid: int, now: float | None = None) -> str | None:
        """Record a finished job; a report line if one is due."""
        now = time.monotonic() if now is None else now
        _, est = self.running.pop(jobid, ("", 0.0))
        self.done += 1
        self.done_estimate += est
        last = self.total and self.done >= self.total
        if not last and now - self.last_report < REPORT_EVERY_S:
            return None
        self.last_report = now
        elapsed = now - self.t0
        total = max(self.total, self.done)
        if last:
            return f"progress: {self.done} of {total} jobs done in {duration(elapsed)}"
        left = self.speed(now) * self.remaining_estimate() / self.cores
        return (f"progress: {self.done} of {total} jobs done ({100 * self.done / total:.0f} %), "
                f"{duration(elapsed)} elapsed, about {duration(left)} left")
