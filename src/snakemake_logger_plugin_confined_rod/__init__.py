"""Snakemake logger plugin of the confined_rod workflow: adds to Snakemake's own output one plain
line of progress with the estimated time left (``confined_rod.pipeline.progress``) every ten
seconds or so.  Selected by the workflow's profiles (``logger: [confined-rod]``); it writes to
stderr beside Snakemake's default handler, which it leaves in place."""
from __future__ import annotations

import sys
from logging import LogRecord

from snakemake_interface_logger_plugins.base import LogHandlerBase
from snakemake_interface_logger_plugins.common import LogEvent

from confined_rod.pipeline.progress import PLAN_ATTRIBUTE


class LogHandler(LogHandlerBase):
    def __post_init__(self) -> None:
        from confined_rod.pipeline.progress import BuildProgress

        self.progress = BuildProgress()

    def _say(self, line: str | None) -> None:
        if line and not getattr(self.common_settings, "dryrun", False):
            sys.stderr.write(line + "\n")       # one write: Snakemake's own lines cannot split it
            sys.stderr.flush()

    def emit(self, record: LogRecord) -> None:
        event = getattr(record, "event", None)
        try:
            plan = getattr(record, PLAN_ATTRIBUTE, None)
            if plan is not None:
                self._say(self.progress.set_plan(plan))
            elif event == LogEvent.RESOURCES_INFO and getattr(record, "cores", None):
                self.progress.cores = max(1, int(record.cores))
            elif event == LogEvent.RUN_INFO:
                stats = dict(getattr(record, "stats", {}) or {})
                stats.pop("total", None)
                if stats:
                    self._say(self.progress.plan(stats))
            elif event == LogEvent.JOB_INFO:
                res = getattr(record, "resources", None)
                names = getattr(res, "_names", None) or {}
                est = dict(zip(names, res)).get("est_s") if names else None
                self.progress.start(int(getattr(record, "jobid", 0)), str(getattr(record, "rule_name", "")), est)
            elif event == LogEvent.JOB_FINISHED:
                self._say(self.progress.finish(int(getattr(record, "job_id", 0))))
        except Exception as exc:            # progress must never break a build
            print(f"progress: not available ({type(exc).__name__}: {exc})", file=sys.stderr)

    @property
    def writes_to_stream(self) -> bool:
        return False

    @property
    def writes_to_file(self) -> bool:
        return False

    @property
    def has_filter(self) -> bool:
        return True

    @property
    def has_formatter(self) -> bool:
        return True

    @property
    def needs_rulegraph(self) -> bool:
        return False
