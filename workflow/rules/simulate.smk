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
