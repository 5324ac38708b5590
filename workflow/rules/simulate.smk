rule simulate:
    """Relax one scene to equilibrium and store its dataset (one netCDF per scene)."""
    input:
        code=SIMULATION_CODE,
        stale=stale_sim,
    output:
        "results/sims/{figure}/{scene}.nc",
    params:
        scene=lambda wildcards: pipeline.scene_params(
            config, wildcards.figure, wildcards.scene
        ),
    log:
        "results/logs/simulate/{figure}/{scene}.log",
    benchmark:
        "results/benchmarks/simulate/{figure}/{scene}.tsv"
    threads: 1
    priority: job_priority
    resources:
        mem_mb=1000,
        runtime=simulate_runtime,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/simulate.py"


rule probe:
    """One point of a stability map: run it and record how it ended (equilibrium, time
    cap, escape, divergence or invalid input, with the message); never fails the build."""
    input:
        code=SIMULATION_CODE,
    output:
        "results/probes/{figure}/{scene}.nc",
    params:
        scene=lambda wildcards: pipeline.scene_params(
            config, wildcards.figure, wildcards.scene
        ),
    log:
        "results/logs/probe/{figure}/{scene}.log",
    benchmark:
        "results/benchmarks/probe/{figure}/{scene}.tsv"
    threads: 1
    priority: job_priority
    resources:
        mem_mb=1000,
        runtime=30,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/probe.py"


rule load_path:
    """One scene of a path figure (Fig 3): equilibria along a load sweep (up, down or
    fresh at each load) or the thresholds by bisection; confined_rod.paths.run_spec."""
    input:
        code=PATH_CODE,
        stale=stale_path,
    output:
        "results/paths/{figure}/{scene}.nc",
    params:
        scene=lambda wildcards: pipeline.scene_params(
            config, wildcards.figure, wildcards.scene
        ),
        spec=lambda wildcards: pipeline.path_spec(
            config, wildcards.figure, wildcards.scene
        ),
    log:
        "results/logs/load_path/{figure}/{scene}.log",
    benchmark:
        "results/benchmarks/load_path/{figure}/{scene}.tsv"
    threads: 1
    priority: path_priority
    resources:
        mem_mb=1000,
        runtime=60,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/load_path.py"
