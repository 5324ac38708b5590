rule batch:
    """Run the small scenes of a figure in one process (pipeline.batches: neighbours in the
    config, a seed ensemble's members together, up to pipeline.BATCH_S estimated solver seconds),
    each written to its own dataset in the batch's folder; each scene's own job (rule simulate or
    probe) then moves it into place. The job's start-up (~2 s) is paid once per batch."""
    input:
        code=SIMULATION_CODE,
    output:
        layout.batch_manifest("{kind}", "{figure}", "{batch}"),
    params:
        job=lambda wildcards: pipeline.batch_job(
            config, wildcards.kind, wildcards.figure, wildcards.batch
        ),
    log:
        layout.log_path("batch", "{kind}", "{figure}", "{batch}"),
    benchmark:
        layout.benchmark_path("batch", "{kind}", "{figure}", "{batch}")
    wildcard_constraints:
        kind="simulate|probe",
    threads: 1
    priority: batch_priority
    resources:
        mem_mb=1000,
        runtime=batch_runtime,
        est_s=batch_priority,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/batch.py"


rule simulate:
    """One scene's dataset: moved into place from its batch, or (a scene that runs alone, or one
    whose batch copy is gone) relaxed to equilibrium in this job (confined_rod.sim.runs)."""
    input:
        code=SIMULATION_CODE,
        stale=stale_sim,
        batch=lambda wildcards: pipeline.member_batch(
            config, "simulate", wildcards.figure, wildcards.scene
        ),
    output:
        layout.sim_path("{figure}", "{scene}"),
    params:
        cached=lambda wildcards: pipeline.member_cache(
            config, "simulate", wildcards.figure, wildcards.scene
        ),
        batch_log=batch_log("simulate"),
        scene=lambda wildcards: scene_json(wildcards),
        run=RUN_SCENE,
    log:
        layout.log_path("simulate", "{figure}", "{scene}"),
    benchmark:
        layout.benchmark_path("simulate", "{figure}", "{scene}")
    threads: 1
    priority: job_priority
    resources:
        mem_mb=1000,
        runtime=simulate_runtime,
        est_s=member_estimate("simulate"),
    conda:
        "../envs/confined_rod.yaml"
    shell:
        MEMBER_SHELL.format(kind="simulate")


rule probe:
    """One point of a stability map: how it ended (equilibrium, time cap, escape, divergence
    or invalid input, with the message); never fails the build. Moved into place from its batch,
    or run in this job (as rule simulate)."""
    input:
        code=SIMULATION_CODE,
        batch=lambda wildcards: pipeline.member_batch(
            config, "probe", wildcards.figure, wildcards.scene
        ),
    output:
        layout.probe_path("{figure}", "{scene}"),
    params:
        cached=lambda wildcards: pipeline.member_cache(
            config, "probe", wildcards.figure, wildcards.scene
        ),
        batch_log=batch_log("probe"),
        scene=lambda wildcards: scene_json(wildcards),
        run=RUN_SCENE,
    log:
        layout.log_path("probe", "{figure}", "{scene}"),
    benchmark:
        layout.benchmark_path("probe", "{figure}", "{scene}")
    threads: 1
    priority: job_priority
    resources:
        mem_mb=1000,
        runtime=30,
        est_s=member_estimate("probe"),
    conda:
        "../envs/confined_rod.yaml"
    shell:
        MEMBER_SHELL.format(kind="probe")


rule load_path:
    """One scene of a path figure (Fig 3): equilibria along a load sweep (up, down or
    fresh at each load) or the thresholds by bisection; confined_rod.sim.load_paths.run_spec."""
    input:
        code=PATH_CODE,
        stale=stale_path,
    output:
        layout.path_file("{figure}", "{scene}"),
    params:
        scene=lambda wildcards: pipeline.scene_params(
            config, wildcards.figure, wildcards.scene
        ),
        spec=lambda wildcards: pipeline.path_spec(
            config, wildcards.figure, wildcards.scene
        ),
    log:
        layout.log_path("load_path", "{figure}", "{scene}"),
    benchmark:
        layout.benchmark_path("load_path", "{figure}", "{scene}")
    threads: 1
    priority: path_priority
    resources:
        mem_mb=1000,
        runtime=60,
        est_s=path_priority,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/load_path.py"
