rule simulate:
    """Relax one scene to equilibrium and store its dataset (one netCDF per scene)."""
    input:
        code=SIMULATION_CODE,
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
    resources:
        mem_mb=1000,
        runtime=30,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/probe.py"
