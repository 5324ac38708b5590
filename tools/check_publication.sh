#!/usr/bin/env bash
# The publication build in full from scratch (the README's main command) with every check that
# CI runs on the CI config: artifacts, the manuscript, figure text sizes, and the per-rule build
# times. About 50 min on 2 cores today, beyond CI's time limit, so it is run by hand before a
# release (or on a cluster through profiles/slurm). Usage: bash tools/check_publication.sh
set -euo pipefail
cd "$(dirname "$0")/.."
export NUMBA_CACHE_DIR="${NUMBA_CACHE_DIR:-$PWD/.numba_cache}"
mkdir -p "$NUMBA_CACHE_DIR"
rm -rf results
t0=$SECONDS
.venv/bin/snakemake --cores 2
pub_wall=$((SECONDS - t0))
echo "publication build took ${pub_wall} s"
.venv/bin/python tools/check_artifacts.py config/config.yaml
.venv/bin/python tools/check_paper.py config/config.yaml
.venv/bin/python tools/check_figure_text.py config/config.yaml
.venv/bin/python tools/build_times.py --results results --wall "$pub_wall" \
    --note "tools/check_publication.sh: the publication build from scratch" -o benchmarks/results/publication_build.json
