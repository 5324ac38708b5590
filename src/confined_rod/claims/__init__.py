"""The paper's claims (``paper/claims.yaml``), decided on the build's datasets, and the manuscript.

- :mod:`.spec`: the claims file, read and checked;
- :mod:`.evidence`: what the claims read (datasets, scene simulations) and what each has touched;
- :mod:`.measures`: the named measures, one module per subject, each returning a ``Measured``;
- :mod:`.derivations`: the paper's equations checked symbolically (sympy);
- :mod:`.verdicts`: the evaluation (a Verdict per claim), the independent findings, the tables;
- :mod:`.manuscript`: the manuscript's generated parts (macros, tables, figure floats) and the PDF.

Post-processing: reads datasets and never imports the simulator (pyproject.toml's import
contracts). The names the workflow and the tools use are re-exported here.
"""
from .evidence import ClaimError, Evidence, pick
from .measures import MEASURES, Measured
from .spec import finding_titles, load, required_figures, sim_figures
from .verdicts import (
                       NOT_DETERMINED,
                       VERDICTS,
                       Verdict,
                       evaluate,
                       evaluate_one,
                       findings,
                       fmt,
                       ours_only,
                       split_findings,
                       to_csv,
                       to_dataset,
                       unsettled_verdict,
)

__all__ = ["ClaimError", "Evidence", "pick", "MEASURES", "Measured", "finding_titles", "load", "required_figures",
           "sim_figures", "NOT_DETERMINED", "VERDICTS", "Verdict", "evaluate", "evaluate_one", "findings", "fmt",
           "ours_only", "split_findings", "to_csv", "to_dataset", "unsettled_verdict"]
