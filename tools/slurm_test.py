"""Run part of the CI config on a real one-node SLURM through profiles/slurm and compare.

    python tools/slurm_test.py [config/ci.yaml] [-o FILE]      # as root, after a local build

Needs Debian's slurmctld, slurmd, slurm-client and munge (.ci/run installs them) and a
complete local build of the same config in this checkout (results/ is the reference).

1. Cluster up, all state in one temporary directory (mode 700): a fresh munge key and
   munged on its own socket; a minimal slurm.conf (one node localhost with 2 CPUs,
   ProctrackType=proctrack/linuxproc, TaskPlugin=task/none, no accounting, its own
   ports) at /etc/slurm/slurm.conf, where srun inside a job looks (the plugin's job step
   drops SLURM_CONF; a file already there is put back at the end); slurmctld and slurmd.
   Waits until the node is idle.
2. In a copy of the checkout's tracked files (fresh results/), builds TARGETS through
   ``--profile profiles/slurm`` (with the test cluster's partition, no account and
   ``--slurm-status-command squeue``: without accounting sacct cannot answer), checks that
   every job ran as a SLURM job (squeue lists it COMPLETED) and compares every dataset with
   the local build, bitwise, run times and provenance stamps aside (tools/kill_resume.py).
3. Time limit: builds KILL_TARGET with a deliberately tiny runtime for the rule of its batch
   (``--set-resources batch:runtime=1``: one minute, SLURM's smallest limit; the job's
   TimeLimit must read 00:01:00). Once the job runs, it is made to hang (``scancel
   --signal=STOP``) and its limit is cut to zero (``scontrol update TimeLimit=0``): SLURM
   checks limits every 30 s, so this ends it as at its time limit (state TIMEOUT, "CANCELLED
   DUE TO TIME LIMIT") within 30 s instead of 60-90 s. The failed build must name the rule,
   the scene, the job's log and TIMEOUT, and leave no output behind; a rerun of the same
   command without the tiny runtime must resume and give the local build's dataset.
4. Tear-down: cancels every job, stops slurmd, slurmctld and munged by process id
   (SIGTERM, then SIGKILL after 10 s), checks that none is left and removes the directory.

Writes a JSON summary to stdout (and FILE); exit status 1 on any failure or difference.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from compare_builds import compare_dataset, layout  # noqa: E402
from kill_resume import tracked_copy  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))
PARTITION = "ci"
#: datasets built through SLURM and compared with the local build: Fig 7's seed ensemble
#: (three simulations and the dataset), Fig 4's three panels and its dataset
TARGETS = (layout.dataset_path("fig7_tiny_force"), layout.dataset_path("fig4_Fonl"))
#: the job killed at its time limit: the batch that runs a stability-map probe (the CI config's
#: 40 probes run as one batch of about 20 s; its name and log are read
#: from the config: batch_of_kill_target)
KILL_TARGET = layout.probe_path("stability_map", "explicit-l0-0p25")
KILL_RULE = "batch"
DAEMONS = ("slurmd", "slurmctld", "munged")
SYSTEM_CONF = Path("/etc/slurm/slurm.conf")


class Cluster:
    """A one-node SLURM with its own munge, all state in `self.dir`."""

    def __init__(self) -> None:
        self.dir = Path(tempfile.mkdtemp(prefix="slurm_test_"))
        os.chmod(self.dir, 0o700)
        # srun inside a job reads the default path: the plugin's job step drops SLURM_CONF from
        # its environment. An existing file there is kept aside and put back by stop().
        self.conf = SYSTEM_CONF
        self.saved = self.dir / "slurm.conf.saved"
        if self.conf.exists():
            shutil.copy2(self.conf, self.saved)
        self.created_dir = not self.conf.parent.exists()
        self.conf.parent.mkdir(parents=True, exist_ok=True)
        self.env = {**os.environ, "SLURM_CONF": str(self.conf)}
        self.pids: dict[str, int] = {}

    def pid_file(self, daemon: str) -> Path:
        return self.dir / f"{daemon}.pid"

    def start(self) -> float:
        t0 = time.perf_counter()
        munge = self.dir / "munge"
        munge.mkdir(mode=0o700)
        key = munge / "munge.key"
        key.write_bytes(os.urandom(1024))
        os.chmod(key, 0o400)
        sock = munge / "munge.sock"
        subprocess.run(["munged", f"--key-file={key}", f"--socket={sock}", f"--pid-file={self.pid_file('munged')}",
                        f"--log-file={munge / 'munged.log'}", f"--seed-file={munge / 'munged.seed'}", "--force"],
                       check=True, capture_output=True)
        (self.dir / "spool").mkdir()
        (self.dir / "state").mkdir()
        self.conf.write_text("\n".join([
            "ClusterName=confined_rod_ci", "SlurmctldHost=localhost",
            "AuthType=auth/munge", "CredType=cred/munge", f"AuthInfo=socket={sock}",
            "ProctrackType=proctrack/linuxproc", "TaskPlugin=task/none",
            "SelectType=select/cons_tres", "SelectTypeParameters=CR_CPU", "SchedulerType=sched/backfill",
            "SlurmUser=root", "SlurmdUser=root", "SlurmctldPort=16817", "SlurmdPort=16818",
            f"SlurmctldPidFile={self.pid_file('slurmctld')}", f"SlurmdPidFile={self.pid_file('slurmd')}",
            f"SlurmdSpoolDir={self.dir / 'spool'}", f"StateSaveLocation={self.dir / 'state'}",
            f"SlurmctldLogFile={self.dir / 'slurmctld.log'}", f"SlurmdLogFile={self.dir / 'slurmd.log'}",
            "AccountingStorageType=accounting_storage/none", "JobAcctGatherType=jobacct_gather/none",
            "JobCompType=jobcomp/none", "MpiDefault=none", "ReturnToService=2",
            "MinJobAge=600",            # squeue keeps finished jobs long enough for the status checks
            "NodeName=localhost CPUs=2 RealMemory=8000 State=UNKNOWN",
            f"PartitionName={PARTITION} Nodes=localhost Default=YES MaxTime=INFINITE State=UP", ""]))
        subprocess.run(["slurmctld", "-f", str(self.conf), "-i"], check=True, env=self.env, capture_output=True)
        subprocess.run(["slurmd", "-f", str(self.conf)], check=True, env=self.env, capture_output=True)
        for d in DAEMONS:
            self.pids[d] = self._read_pid(d)
        deadline = time.time() + 60
        while time.time() < deadline:
            state = subprocess.run(["sinfo", "-h", "-o", "%T"], env=self.env, capture_output=True, text=True).stdout
            if state.strip() == "idle":
                return time.perf_counter() - t0
            time.sleep(0.5)
        raise RuntimeError(f"the SLURM node did not become idle in 60 s (sinfo: {state.strip()!r}); see "
                           f"{self.dir / 'slurmctld.log'}")

    def _read_pid(self, daemon: str) -> int:
        deadline = time.time() + 20
        while time.time() < deadline:
            f = self.pid_file(daemon)
            if f.exists() and f.read_text().strip():
                return int(f.read_text().split()[0])
            time.sleep(0.1)
        raise RuntimeError(f"{daemon} wrote no pid file ({self.pid_file(daemon)})")

    def jobs(self) -> list[tuple[str, str, str]]:
        """(job id, state, comment) of every job SLURM still knows."""
        out = subprocess.run(["squeue", "-h", "-t", "all", "-o", "%i|%T|%k"], env=self.env, capture_output=True,
                             text=True).stdout
        return [tuple(line.split("|", 2)) for line in out.splitlines() if line.strip()]

    def stop(self) -> dict:
        """Cancel every job, stop the daemons by process id, remove the state directory."""
        subprocess.run(["scancel", "--partition", PARTITION], env=self.env, capture_output=True)
        left = []
        for d in DAEMONS:
            pid = self.pids.get(d)
            if pid is None and self.pid_file(d).exists():
                pid = int(self.pid_file(d).read_text().split()[0])
            if pid is None:
                continue
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                continue
            deadline = time.time() + 10
            while time.time() < deadline and _alive(pid):
                time.sleep(0.1)
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
                time.sleep(0.2)
            if _alive(pid):
                left.append(f"{d} ({pid})")
        if self.saved.exists():
            shutil.copy2(self.saved, self.conf)
            restored = self.conf.read_bytes() == self.saved.read_bytes()
        else:
            self.conf.unlink(missing_ok=True)
            if self.created_dir:
                shutil.rmtree(self.conf.parent, ignore_errors=True)
            restored = not self.conf.exists()
        shutil.rmtree(self.dir, ignore_errors=True)
        return {"daemons_left": left, "state_dir_removed": not self.dir.exists(), "slurm_conf_restored": restored}


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie of ours counts as stopped
    stat = Path(f"/proc/{pid}/stat")
    return not (stat.exists() and stat.read_text().split(")")[-1].split()[0] == "Z")


def profile_command(config: str, *targets: str, extra: tuple[str, ...] = ()) -> list[str]:
    return [SNAKEMAKE, *targets, "--configfile", config, "--profile", str(ROOT / "profiles" / "slurm"),
            "--slurm-status-command", "squeue", "--slurm-no-account", "--slurm-init-seconds-before-status-checks",
            "2", "--default-resources", f"slurm_partition={PARTITION}", "runtime=30", "mem_mb=1000",
            "--latency-wait", "5", *extra]


def compare(reference: Path, work: Path, files: list[str]) -> dict[str, list[str]]:
    diffs = {}
    for rel in files:
        mine = work / rel
        d = ["missing"] if not mine.exists() else compare_dataset(reference / rel, mine)
        if d:
            diffs[rel] = d
    return diffs


def batch_of_kill_target(config: str) -> tuple[str, str]:
    """(the name of the batch that runs KILL_TARGET, that batch's log)."""
    sys.path.insert(0, str(ROOT / "src"))
    from confined_rod import pipeline

    cfg = pipeline.expand(pipeline.read_config(ROOT / config))
    figure, scene = Path(KILL_TARGET).parent.name, Path(KILL_TARGET).stem
    batch = pipeline.batch_of(cfg, figure, scene)
    if batch is None:
        raise SystemExit(f"{KILL_TARGET} is in no batch of {config}: pick a target that is")
    return batch, layout.batch_log("probe", figure, batch)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config", nargs="?", default="config/ci.yaml")
    ap.add_argument("-o", "--output", help="also write the JSON summary here")
    args = ap.parse_args(argv)
    summary: dict = {"config": args.config, "targets": list(TARGETS)}
    kill_scene, kill_log = batch_of_kill_target(args.config)
    t_all = time.perf_counter()
    cluster = Cluster()
    ok = False
    try:
        summary["cluster_start_s"] = round(cluster.start(), 1)
        with tempfile.TemporaryDirectory(prefix="slurm_work_") as tmp:
            work = Path(tmp)
            tracked_copy(work)
            env = cluster.env
            # -- 2. the targets through the profile, compared with the local build
            t0 = time.perf_counter()
            run = subprocess.run(profile_command(args.config, *TARGETS), cwd=work, env=env, capture_output=True,
                                 text=True)
            summary["build_s"] = round(time.perf_counter() - t0, 1)
            if run.returncode != 0:
                raise RuntimeError("the build through profiles/slurm failed:\n" + run.stderr[-4000:])
            built = sorted(str(p.relative_to(work)) for folder in (layout.SIMS, layout.DATASETS)
                           for p in layout.under(work / layout.RESULTS, folder).rglob("*.nc"))
            done = [j for j in cluster.jobs() if j[1] == "COMPLETED"]
            summary["jobs_through_slurm"] = len(done)
            summary["files_compared"] = len(built)
            summary["differences"] = compare(ROOT, work, built)
            if len(done) < len(built):
                raise RuntimeError(f"{len(built)} files built but only {len(done)} SLURM jobs completed: some jobs "
                                   "did not run through SLURM")
            # -- 3. a job ended at its time limit, reported, and resumed
            t0 = time.perf_counter()
            tiny = ("--retries", "0", "--set-resources", f"{KILL_RULE}:runtime=1")
            proc = subprocess.Popen(profile_command(args.config, KILL_TARGET, extra=tiny), cwd=work,
                                    env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            job = None
            deadline = time.time() + 120
            while job is None and proc.poll() is None and time.time() < deadline:
                for jid, state, comment in cluster.jobs():
                    if state == "RUNNING" and f"rule_{KILL_RULE}" in comment and kill_scene in comment:
                        job = jid
                time.sleep(0.2)
            if job is None:
                proc.kill()
                raise RuntimeError(f"the {KILL_RULE} job of {kill_scene} was never seen running:\n"
                                   + (proc.communicate()[0] or "")[-3000:])
            shown = subprocess.run(["scontrol", "show", "job", job], env=env, capture_output=True, text=True).stdout
            limit = re.search(r"TimeLimit=(\S+)", shown)
            summary["timeout_submitted_limit"] = limit.group(1) if limit else "?"
            time.sleep(1.0)         # the job has started its work; now it hangs
            subprocess.run(["scancel", "--signal=STOP", "--full", job], env=env, check=True, capture_output=True)
            subprocess.run(["scontrol", "update", f"JobId={job}", "TimeLimit=0"], env=env, check=True,
                           capture_output=True)
            out, _ = proc.communicate(timeout=300)
            state = next((s for j, s, _ in cluster.jobs() if j == job), "?")
            shown = subprocess.run(["scontrol", "show", "job", job], env=env, capture_output=True, text=True).stdout
            summary["timeout_scontrol"] = re.findall(r"(?:JobState|RunTime|TimeLimit|ExitCode)=\S+", shown)
            logs = sorted((work / ".snakemake" / "slurm_logs").rglob(f"{job}.log"))
            summary["timeout_slurm_log_tail"] = logs[0].read_text().splitlines()[-12:] if logs else []
            summary["timeout"] = {
                "job": job, "slurm_state": state, "build_exit": proc.returncode,
                "reported_rule": f"rule {KILL_RULE}" in out, "reported_scene": kill_scene in out,
                "reported_log": kill_log in out, "reported_timeout": "TIMEOUT" in out,
                "output_left": (work / KILL_TARGET).exists(),
                "seconds_to_failure": round(time.perf_counter() - t0, 1)}
            msg = [line.strip() for line in out.splitlines() if re.search(r"Error in rule|TIMEOUT|log:", line)]
            summary["timeout"]["report"] = msg[:6]
            t0 = time.perf_counter()
            rerun = subprocess.run(profile_command(args.config, KILL_TARGET), cwd=work, env=env,
                                   capture_output=True, text=True)
            summary["timeout"]["resume_exit"] = rerun.returncode
            summary["timeout"]["resume_s"] = round(time.perf_counter() - t0, 1)
            summary["timeout"]["differences"] = compare(ROOT, work, [KILL_TARGET]) if rerun.returncode == 0 \
                else {KILL_TARGET: ["rerun failed: " + rerun.stderr[-2000:]]}
            leftovers = sorted(str(p.relative_to(work)) for p in (work / layout.RESULTS).rglob("*.tmp"))
            summary["leftover_temporaries"] = leftovers
            t = summary["timeout"]
            ok = (not summary["differences"] and t["slurm_state"] == "TIMEOUT" and t["build_exit"] != 0
                  and summary["timeout_submitted_limit"] == "00:01:00" and t["reported_timeout"]
                  and t["reported_rule"] and t["reported_scene"] and t["reported_log"] and not t["output_left"]
                  and t["resume_exit"] == 0 and not t["differences"] and not leftovers)
    except Exception as e:  # reported in the summary; the cluster is torn down below
        summary["error"] = str(e)
    finally:
        summary["teardown"] = cluster.stop()
    td = summary["teardown"]
    ok = ok and not td["daemons_left"] and td["state_dir_removed"] and td["slurm_conf_restored"]
    summary["wall_s"] = round(time.perf_counter() - t_all, 1)
    summary["result"] = "identical, timeout reported and resumed" if ok else "FAILED"
    text = json.dumps(summary, indent=1)
    print(text)
    if args.output:
        Path(args.output).parent.mkdir(parents=True, exist_ok=True)
        Path(args.output).write_text(text + "\n")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
