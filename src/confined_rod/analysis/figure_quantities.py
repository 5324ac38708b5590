"""The quantities that post-processing derives and stores in the figure datasets (fits, ensemble
statistics, regions, the paper's printed numbers): name, symbol and unit, declared once. They
extend the table of :mod:`confined_rod.quantities` (scene parameters, scene-file variables); the
analysis side looks every quantity up here."""
from __future__ import annotations

from ..quantities import QUANTITIES as SCENE_FILE_QUANTITIES
from ..quantities import Quantity

#: the scene parameters a figure states where its scenes share them: copied onto its dataset
#: (analysis.postprocess), quoted by the manuscript (\val{<figure>.<parameter>}, the numbers among
#: them); its caption states them with the numerics (pipeline.configs.caption)
STATED_PARAMETERS = ("R", "EI", "load", "k_fr", "l0", "k_ph", "k_w", "friction_cap", "protocol", "seed", "solver",
                     "tol", "L", "bending_constant")
#: the numerical settings a caption names (with their units from the quantities' table)
NUMERICS = ("l0", "k_ph", "k_w", "tol")


def _member_stats(key: str, symbol: str, text: str, units: str, member: str) -> list["Quantity"]:
    """<key>_member, <key>_mean, <key>_std of an ensemble quantity (member: what a member's value is)."""
    return [Quantity(f"{key}_member", symbol, f"{text} ({member})", units),
            Quantity(f"{key}_mean", rf"\langle {symbol}\rangle", f"{text} (ensemble mean)", units),
            Quantity(f"{key}_std", r"\sigma", f"{text} (ensemble standard deviation)", units)]


#: what the figure datasets store beyond the scene parameters and the scene files' variables
FIGURE_QUANTITIES = [
    # derived (per-figure datasets)
    Quantity("F_abs", "|F_z|", "magnitude of the axial (compressive) force", "EI R-2"),
    Quantity("n_turns", "n_{turns}", "turns of the wall-contact stretch about the axis |phi_end - phi_start|/(2 pi)",
             "1"),
    Quantity("L_model", "L", "contour length of the rod (analytic curve)", "R"),
    Quantity("F_simple", "|F_z|", "axial force of the simple helix model, corrected: K = R F^2/(4 EI)", "EI R-2"),
    Quantity("F_simple_paper", "|F_z|", "axial force of the simple helix model as printed: K = R F^2/(2 EI)",
             "EI R-2"),
    Quantity("F_fit", "f", "power-law fit A (l0' + s)^c of |F_z(s)|", "EI R-2"),
    Quantity("in_fit", "", "joint inside the fit window (1) or not (0)", "1"),
    Quantity("fit_A", "A", "prefactor A of the fit A (l0' + s)^c", "EI R-2 R-c"),
    Quantity("fit_l0", "l_0'", "offset l0' of the fit A (l0' + s)^c", "R"),
    Quantity("fit_c", "c", "exponent c of the fit A (l0' + s)^c", "1"),
    Quantity("fit_cov", "", "covariance of the fit parameters (A, l0', c)", "mixed"),
    Quantity("fit_rms", "", "rms relative residual of the fit in its window", "1"),
    Quantity("s_h", "s_h", "arc length where the wall-contact stretch starts (the first run of links on the wall, "
             "after the isolated contacts of a detached tip)", "R"),
    Quantity("s_end", "s_e", "arc length where the wall-contact stretch ends (the last run of links on the wall)", "R"),
    Quantity("panel_value", "", "value of the parameter that differs between the panels", "1"),
    Quantity("n_fit", "", "number of joints in the fit window", "1"),
    Quantity("panel", "", "panel (scene id in the config)", "1"),
    Quantity("param", "", "fit parameter", "1"),
    Quantity("pitch", "P", "bulk pitch of the helix, 2 pi |dz/dphi| over the middle half of the contact stretch", "R"),
    Quantity("F_shift_by_region", "\\delta F_{region}/F", "share of the relative shift of the transmitted force "
             "|F_z(L)| between the publication rung and the finest rung of a ladder that a region of the rod "
             "carries: the mean over the paired seeds of -F_pub(L) F_fine(L) times the change of what the region "
             "adds to 1/|F_z|, over the finest rung's mean F(L) (exact: the regions sum to the shift of the mean)",
             "1"),
    Quantity("F_shift_split_seeds", "n", "paired seeds with a bulk on both rungs over which F_shift_by_region is "
             "taken", "1"),
    Quantity("F_shift_split_total", "\\delta F/F", "sum over the regions of F_shift_by_region: the "
             "relative shift of the mean |F_z(L)| over the seeds of the split", "1"),
    Quantity("F_shift_by_region_se", "\\sigma", "standard error of F_shift_by_region over the paired seeds", "1"),
    Quantity("F_shift_by_region_cov", r"\mathrm{cov}", "covariance of the regions' mean shares F_shift_by_region "
             "over the paired seeds (the error of a weighted sum of them)", "1"),
    Quantity("F_split_mean", r"\langle|F_z(L)|\rangle", "mean transmitted force of the rung over the seeds of the "
             "split by region", "EI R-2"),
    Quantity("bulk_part_split_mean", r"\langle X_{bulk}\rangle", "mean of what the bulk helix adds to 1/|F_z| "
             "over the seeds of the split by region, 1/|F(s_bulk_end)| - 1/|F(s_bulk_start)|", "R2 EI-1"),
    Quantity("bulk_part_member", "X_{bulk}", "what the member's bulk helix adds to 1/|F_z|, "
             "1/|F(s_bulk_end)| - 1/|F(s_bulk_start)| (0 without a bulk)", "R2 EI-1"),
    Quantity("pitch_theory", "P_{th}", "pitch of the discrete chain's torque-free helix on the wall at the load, "
             "2 pi l0 sqrt(1 - R^2 w^2)/(2 asin(w l0/2)) (theory.discrete_helix)", "R"),
    Quantity("value", "", "value of the refined parameter", "1"),
    Quantity("h", "h", "refinement variable (l0, 1/k_ph, 1/k_w or tol)", "1"),
    Quantity("observable", "", "observable of the convergence check", "1"),
    Quantity("observed_order", "p", "observed order of convergence (Richardson, three finest rungs)", "1"),
    Quantity("publication_distance", "", "relative distance of the publication setting from the limit", "1"),
    Quantity("wall_force_ratio", r"\frac{K}{RF_z^2/(4EI)}", "wall force per length over its lowest order "
             "R F_z^2/(4EI), median over the regular helix", "1"),
    Quantity("pitch_ratio", r"\frac{|d\varphi/ds|}{w(F_z)}", "pitch rate over that of a torque-free helix on the "
             "wall at the local force, median over the regular helix", "1"),
    Quantity("helix_balance", r"\frac{K}{\rho w^2(|F_z|/c - EIw^2)}", "wall force per length over the lateral "
             "balance of a helix on the wall with any axial torque, rho w^2 (|F_z|/c - EI w^2), median over the "
             "regular helix", "1"),
    Quantity("total_turns", r"n_{\circlearrowleft}", "turns of the rod about the pore axis, summed without sign "
             "over the off-axis links", "1"),
    Quantity("n_reversals", r"n_{rev}", "reversals of handedness of the coil", "1"),
    Quantity("quantity", "", "quantity compared between the rungs", "1"),
    Quantity("rod_region", "", "region of the rod, from the loaded end: tip, bulk helix, lower region", "1"),
    Quantity("shift", r"\delta", "relative shift of the publication rung's ensemble mean from this rung's", "1"),
    Quantity("dof", r"\nu", "degrees of freedom of the shift's standard error (paired seeds less one; "
             "Welch-Satterthwaite unpaired)", "1"),
    Quantity("shift_se", r"\sigma_\delta", "standard error of the relative shift (paired seed by seed where "
             "the rungs share seeds, Welch otherwise)", "1"),
    Quantity("resolution", r"\delta_{95}", "smallest relative shift of the mean detected with 95 % power by a "
             "two-sided 5 % test of these ensembles", "1"),
    Quantity("p_ad", "p_{AD}", "p-value of the Anderson-Darling k-sample test of the two ensembles (scipy's range "
             "0.001-0.25)", "1"),
    Quantity("verdict_code", "", "comparison with the publication rung: 0 not compared (no values or the rung "
             "itself), 1 within the tolerance, 2 beyond it, 3 undecided, 4 described but not deciding (no figure the "
             "ladder serves reports it)", "1"),
    Quantity("seeds_needed", "n", "seeds per rung that would decide an undecided comparison (0: decided; -1: none "
             "would, the shift equals the tolerance)", "1"),
    Quantity("compared_tolerance", "", "relative tolerance the comparison is decided against", "1"),
    Quantity("error", r"\epsilon", "relative error of |F_z(L)| against the reference run", "1"),
    Quantity("run_l0", "l_0", "link length of the run", "R"),
    Quantity("run_knob", "", "accuracy knob of the run: tol (explicit) or dx_max in R (implicit)", "1"),
    Quantity("run_k_ph", "k_{ph}", "stretching stiffness of the run", "EI R-2"),
    Quantity("F_reference", "|F_z(L)|_{ref}", "|F_z(L)| of the reference run the error is measured against",
             "EI R-2"),
    # printed numbers of the paper (reference data) and the comparison with ours
    Quantity("F_paper_fit", "f_{paper}", "the paper's printed fit A (l0' + s)^c of |F_z(s)|", "EI R-2"),
    Quantity("paper_fit_A", "A", "prefactor A of the paper's printed fit", "EI R-2 R-c"),
    Quantity("paper_fit_l0", "l_0'", "offset l0' of the paper's printed fit", "R"),
    Quantity("paper_fit_c", "c", "exponent c of the paper's printed fit", "1"),
    Quantity("has_paper_fit", "", "the paper prints a fit for this panel (1) or not (0)", "1"),
    Quantity("paper_fit_fraction", "f(L)/f(0)", "transmitted fraction f(L)/f(0) of the paper's printed fit", "1"),
    Quantity("paper_fit_F0", "f(0)", "value at the loaded end s = 0 of the paper's printed fit", "EI R-2"),
    Quantity("paper_rms_log_ratio", "", "rms of ln(f_paper/|F_z|) over the fit window (the paper's curve against "
             "our profile)", "1"),
    Quantity("fit_fraction", "f(L)/f(0)", "transmitted fraction f(L)/f(0) of our fit", "1"),
    Quantity("transmitted_fraction", "|F_z(L)|/|F_z(0)|", "transmitted fraction |F_z(L)|/|F_z(0)| of the simulated rod",
             "1"),
    Quantity("euler_ratio", r"|F_z(0)|/F_{crit}", "load over Euler's critical force pi^2 EI/L^2", "1"),
    # Fig 5: pitch profile and the local helix relation
    Quantity("F_link", "|F_z|", "axial force at the link centre (mean of its two joints)", "EI R-2"),
    Quantity("omega", r"d\phi/ds", "azimuthal rate of the link centres (signed: handedness)", "rad R-1"),
    Quantity("omega_helix", r"\omega_h(|F_z|)", "pitch rate of a torque-free helix on the wall carrying the local "
             "|F_z|: small root of 2 EI w^2 sqrt(1 - R^2 w^2) = |F_z|", "rad R-1"),
    Quantity("omega_lowest", r"\sqrt{|F_z|/2EI}", "lowest-order pitch rate sqrt(|F_z|/(2EI)) (paper's Eq. dotphi)",
             "rad R-1"),
    Quantity("F_helix", r"2EI\omega^2\sqrt{1-R^2\omega^2}", "axial force of a torque-free helix on the wall with the "
             "local |dphi/ds|: 2 EI w^2 sqrt(1 - R^2 w^2)", "EI R-2"),
    Quantity("helix_ratio", r"|F_z|/F_{helix}", "local ratio |F_z| / (2 EI w^2 sqrt(1 - R^2 w^2)), w = |dphi/ds|",
             "1"),
    Quantity("reversal", "", "a reversal of handedness (sign change of dphi/ds) lies between this link and the next",
             "1"),
    Quantity("s_reversal", "s", "arc length of a reversal of handedness (between two link centres)", "R"),
    Quantity("exponent_omega_F_whole", r"d\ln\omega/d\ln|F_z|", "slope of ln|dphi/ds| against ln|F_z| over the "
             "whole wall-contact stretch where the pitch is defined", "1"),
    Quantity("exponent_omega_F_bulk", r"d\ln\omega/d\ln|F_z|", "slope of ln|dphi/ds| against ln|F_z| over the "
             "bulk helix (confined_rod.analysis.regions) where the pitch is defined", "1"),
    Quantity("exponent_omega_F", "", "slope of ln|dphi/ds| against ln|F_z| over the contact stretch (1/2 if "
             "F_z ~ (dphi/ds)^2)", "1"),
    Quantity("drop_omega", "", "relative decrease of |dphi/ds| along the contact stretch (median of the first "
             "tenth against the last tenth)", "1"),
    Quantity("drop_F", "", "relative decrease of |F_z| along the contact stretch (same windows)", "1"),
    Quantity("threshold_estimate", "F_{est}", "estimate of the threshold: Euler's load of the rod lying diagonally "
             "across the pore (first), the second Euler mode 4 pi^2 EI/L^2 (second)", "EI R-2"),
    Quantity("F_euler", "F_E", "Euler's critical load pi^2 EI/L^2", "EI R-2"),
    Quantity("L2_over_EI", "L^2/EI", "L^2/EI of the thresholds scene (scales a load to Euler units)", "R2 EI-1"),
    Quantity("aspect", "L/R", "aspect ratio of the rod", "1"),
    Quantity("l0_over_R", "l_0/R", "link length of the threshold scene over its pore radius", "1"),
    Quantity("aspect_k_ph", "k_{ph}", "stretching stiffness of the threshold scene", "EI R-2"),
    Quantity("has_stiff_twin", "", "1 where the same rod was also bisected at a stiffer bond (a bond check)", "1"),
    Quantity("stiff_k_ph", "k_{ph}", "stretching stiffness of the bond check (0 where there is none)", "EI R-2"),
    Quantity("threshold_lo_stiff", "F_{lo}", "lower end of the bisection bracket of the same rod at the stiffer "
             "bond (0 where there is none)", "EI R-2"),
    Quantity("threshold_hi_stiff", "F_{hi}", "upper end of the bisection bracket of the same rod at the stiffer "
             "bond (0 where there is none)", "EI R-2"),
    Quantity("R2_over_EI", "R^2/EI", "R^2/EI of the threshold scene (scales a load to units of EI/R^2)", "R2 EI-1"),
    Quantity("branch_k_fr", "k_{fr}", "friction coefficient of the sweep", "1"),
    Quantity("branch_protocol", "", "protocol of the sweep (start of each fresh run, or of the first load)", "1"),
    Quantity("frame", "", "shape drawn: (a) planar state, (b) instability growing, (c) final state", "1"),
    Quantity("defect_at", "", "link nearest a defect (reversal of handedness) of the drawn run's final state (1) "
             "or not (0)", "1"),
    Quantity("n_defects", "n_{def}", "number of defects (reversals of handedness between stretches of >= 3 links)",
             "1"),
    Quantity("L_z_straight", "L_z", "L_z of the straight rod lying diagonally across the pore, "
             "sqrt(L^2 - 4R^2)(1 - load/k_ph)", "R"),
    # seed ensembles (confined_rod.analysis.ensembles)
    Quantity("member", "", "member of a seed ensemble (index; has_member says which are filled)", "1"),
    Quantity("has_member", "", "1 where the ensemble has this member (the values are 0 otherwise)", "1"),
    Quantity("member_seed", r"\mathrm{seed}", "random seed of the ensemble member's perturbation", "1"),
    Quantity("F_member", "|F_z(L)|", "force transmitted to the lower end by each ensemble member", "EI R-2"),
    Quantity("member_class", "", "final state of each member from its geometry (ensembles.final_class): helix, "
             "planar, defects (helix with a reversal of handedness), straight or twisted (out of a plane, not coiled)",
             "1"),
    Quantity("n_seeds", "n", "members of the seed ensemble", "1"),
    Quantity("loosely_wound_member", "", "1 where the member's bulk helix is loosely wound: a wall force per length "
             "below half the torque-free helix's, an unwinding torque locked in "
             "(analysis.local_relations.loosely_wound)", "1"),
    Quantity("n_loosely_wound", "", "members whose bulk helix is loosely wound "
             "(analysis.local_relations.loosely_wound)", "1"),
    Quantity("F_mean", r"\langle|F_z(L)|\rangle", "ensemble mean of the transmitted force", "EI R-2"),
    Quantity("F_std", r"\sigma", "ensemble standard deviation of the transmitted force (ddof = 1; 0 for one "
             "member)", "EI R-2"),
    Quantity("F_sem", r"\sigma/\sqrt{n}", "standard error of the ensemble mean of the transmitted force", "EI R-2"),
    Quantity("F_min", r"\min|F_z(L)|", "smallest transmitted force in the ensemble", "EI R-2"),
    Quantity("F_max", r"\max|F_z(L)|", "largest transmitted force in the ensemble", "EI R-2"),
    Quantity("state_class_name", "", "final-state class (ensembles.CLASSES): helix, planar, defects, straight, "
             "twisted", "1"),
    # jamming map
    Quantity("fraction_model", "F(L)/F(0)", "transmitted fraction of the corrected simple model, "
             "1/(1 + k_fr R L F0/(4EI))", "1"),
    Quantity("L_half", "L_{1/2}", "rod length at which the transmitted fraction first falls below 1/2 (see "
             "L_half_how)", "R"),
    Quantity("L_half_how", "", "how L_half was found: interpolated, or a bound where the grid does not bracket it",
             "1"),
    Quantity("L_half_model", "L_{1/2}", "L_half of the corrected simple model, 4EI/(k_fr R F0)", "R"),
    Quantity("boundary_load_lo", "F_{fold}", "largest load at which the rod still formed a helix (Fig 8 bisection, "
             "lower end)", "EI R-2"),
    Quantity("boundary_load_hi", "F_{fold}", "smallest load at which the rod folded or escaped (Fig 8 bisection, "
             "upper end)", "EI R-2"),
    Quantity("boundary_free_span", "g/R", "free span above the pore entrance of the threshold run (0: closed "
             "entrance, the rod can only fold)", "1"),
    Quantity("fraction_member", "|F_z(L)|/|F_z(0)|", "transmitted fraction of each ensemble member (0 where "
             "has_member is 0)", "1"),
    Quantity("fraction_std", r"\sigma", "ensemble standard deviation of the transmitted fraction (ddof = 1; 0 for "
             "one member)", "1"),
    Quantity("fraction_sem", r"\sigma/\sqrt{n}", "standard error of the ensemble mean of the transmitted fraction",
             "1"),
    Quantity("fraction_min", r"\min F(L)/F(0)", "smallest transmitted fraction in the ensemble", "1"),
    Quantity("fraction_max", r"\max F(L)/F(0)", "largest transmitted fraction in the ensemble", "1"),
    Quantity("transmitted_fraction_shown", "|F_z(L)|/|F_z(0)|", "transmitted fraction of the shown member (lowest "
             "seed)", "1"),
    Quantity("shown_seed", r"\mathrm{seed}", "seed of the member whose profile and fit the panel shows", "1"),
    Quantity("panel_ramp_steps", r"n_{ramp}", "number of steps of the panel's load ramp", "1"),
    Quantity("fit_c_member", "c", "exponent of our fit to each ensemble member (0 where has_fit_member is 0)", "1"),
    Quantity("has_fit_member", "", "1 where the member has a wall-contact stretch that was fitted", "1"),
    Quantity("fit_c_mean", r"\langle c\rangle", "ensemble mean of the fitted exponent (members whose fit determines "
             "it: fits.undetermined)", "1"),
    Quantity("fit_c_std", r"\sigma_c", "ensemble standard deviation of the fitted exponent (members whose fit "
             "determines it)",
             "1"),
    Quantity("F_abs_min", r"\min|F_z(s)|", "smallest |F_z(s)| over the ensemble's members at each joint", "EI R-2"),
    Quantity("F_abs_max", r"\max|F_z(s)|", "largest |F_z(s)| over the ensemble's members at each joint", "EI R-2"),
    Quantity("n_class", "n", "members of the ensemble ending in each final-state class", "1"),
    # the three regions of a loaded frictional rod and the local decay law (confined_rod.analysis.regions)
    Quantity("region", "", "region of the rod at the link: 0 tip (loaded end), 1 bulk helix, 2 lower region", "1"),
    Quantity("q_axial", "q", "axial wall friction over the largest the wall can give, f_z/min(k_fr N, f_cap l0), "
             "running mean over 4 R", "1"),
    Quantity("has_bulk", "", "1 where a bulk helix (axial friction at the limit over >= 8 R) was found", "1"),
    Quantity("s_bulk_start", "s_b", "arc length where the bulk helix starts (end of the tip region)", "R"),
    Quantity("s_bulk_end", "s_l", "arc length where the bulk helix ends (start of the lower region)", "R"),
    Quantity("tip_length", "s_b", "length of the tip region at the loaded end", "R"),
    Quantity("bulk_length", "s_l - s_b", "length of the bulk helix", "R"),
    Quantity("lower_length", "L - s_l", "length of the lower region above the support", "R"),
    Quantity("lower_q_mean", r"\langle q\rangle_{lower}", "mean axial friction utilisation over the lower region's "
             "links on the wall", "1"),
    Quantity("lower_force_drop", r"F(s_l)/F(L)", "|F_z| at the start of the lower region over |F_z(L)|", "1"),
    Quantity("lower_friction_use", r"\frac{\sum f_z}{\sum f_{max}}\Big|_{lower}", "share of the Coulomb limit the "
             "lower region's wall contacts carry axially, weighted by force", "1"),
    Quantity("bulk_decay_rate", r"d(1/|F_z|)/ds", "local decay rate d(1/|F_z|)/ds fitted over the bulk helix",
             "R EI-1"),
    Quantity("bulk_decay_rate_err", r"\delta", "uncertainty of the bulk decay rate: max(standard error, half the "
             "difference between the bulk's two halves)", "R EI-1"),
    Quantity("whole_decay_rate", r"d(1/|F_z|)/ds", "decay rate d(1/|F_z|)/ds fitted over the whole wall-contact "
             "stretch", "R EI-1"),
    Quantity("whole_decay_rate_err", r"\delta", "uncertainty of the whole-stretch decay rate (as for the bulk)",
             "R EI-1"),
    Quantity("decay_rate_model", r"k_{fr}R/(4EI)", "local decay law of the corrected simple model, k_fr R/(4EI)",
             "R EI-1"),
    Quantity("decay_rate_paper", r"k_{fr}R/(2EI)", "local decay law with the paper's K = R F^2/(2EI), k_fr R/(2EI)",
             "R EI-1"),
    Quantity("decay_ratio", r"\frac{d(1/|F_z|)/ds}{k_{fr}R/(4EI)}", "bulk decay rate over the corrected law "
             "k_fr R/(4EI) (1: the corrected law holds locally; 2: the paper's)", "1"),
    Quantity("fit_c_bulk", "c_{bulk}", "exponent c of the fit A (l0' + s)^c over the bulk helix only", "1"),
    Quantity("fit_c_bulk_err", r"\delta c_{bulk}", "standard error of the bulk-window exponent", "1"),
    Quantity("fit_rms_bulk", "", "rms relative residual of the bulk-window fit", "1"),
    Quantity("paper_rms_log_ratio_bulk", "", "rms of ln(f_paper/|F_z|) over the bulk helix (0 without a printed fit)",
             "1"),
    Quantity("paper_fit_decay_rate", r"d(1/f)/ds", "decay rate d(1/f)/ds of the paper's printed fit over our bulk "
             "window (0 without a printed fit or a bulk)", "R EI-1"),
    Quantity("has_fit_bulk", "", "1 where the bulk-window fit exists (a bulk, and a fit that converged)", "1"),
    Quantity("fall_whole", r"F(s_h)/F(s_e)", "factor by which |F_z| falls over the whole wall-contact stretch", "1"),
    Quantity("fall_bulk", r"F(s_b)/F(s_l)", "factor by which |F_z| falls over the bulk helix", "1"),
    Quantity("bulk_decay_rate_member", r"d(1/|F_z|)/ds", "bulk decay rate of each ensemble member (0 where "
             "has_bulk_member is 0)", "R EI-1"),
    Quantity("has_bulk_member", "", "1 where the ensemble member has a bulk helix", "1"),
    Quantity("bulk_decay_rate_mean", r"\langle d(1/|F_z|)/ds\rangle", "ensemble mean of the bulk decay rate "
             "(members with a bulk)", "R EI-1"),
    Quantity("bulk_decay_rate_std", r"\sigma", "ensemble standard deviation of the bulk decay rate (ddof = 1)",
             "R EI-1"),
    Quantity("fit_c_bulk_member", "c_{bulk}", "bulk-window exponent of each ensemble member (0 where "
             "has_fit_bulk_member is 0)", "1"),
    Quantity("has_fit_bulk_member", "", "1 where the member has a bulk-window fit", "1"),
    Quantity("fit_c_bulk_mean", r"\langle c_{bulk}\rangle", "ensemble mean of the bulk-window exponent (members "
             "whose fit determines it)", "1"),
    Quantity("fit_c_bulk_std", r"\sigma_{c,bulk}", "ensemble standard deviation of the bulk-window exponent "
             "(members whose fit determines it)", "1"),
    Quantity("fall_whole_member", r"F(s_h)/F(s_e)", "factor by which |F_z| falls over the whole wall-contact "
             "stretch, each ensemble member", "1"),
    Quantity("fall_bulk_member", r"F(s_b)/F(s_l)", "factor by which |F_z| falls over the bulk helix, each "
             "ensemble member (0 without a bulk)", "1"),
    Quantity("tip_length_member", "s_b", "tip-region length of each ensemble member", "R"),
    Quantity("paper_rms_log_ratio_member", "", "rms of ln(f_paper/|F_z|) over the member's own fit window, each "
             "ensemble member (0 without a printed fit)", "1"),
    Quantity("paper_rms_log_ratio_bulk_member", "", "rms of ln(f_paper/|F_z|) over the member's own bulk helix, "
             "each ensemble member (0 without a printed fit or a bulk)", "1"),
    Quantity("lower_length_member", "L - s_l", "lower-region length of each ensemble member", "R"),
    # protocol comparison (figure kind protocol_comparison)
    Quantity("fraction_mean", r"\langle F(L)/F(0)\rangle", "ensemble mean of the transmitted fraction", "1"),
    Quantity("lower_length_mean", r"\langle L - s_l\rangle", "ensemble mean of the lower-region length", "R"),
    Quantity("lower_length_std", r"\sigma", "ensemble standard deviation of the lower-region length", "R"),
    Quantity("tip_length_mean", r"\langle s_b\rangle", "ensemble mean of the tip-region length", "R"),
    Quantity("tip_length_std", r"\sigma", "ensemble standard deviation of the tip-region length", "R"),
    Quantity("n_reversals_member", "n_{rev}", "reversals of handedness of the wall-contact stretch of each member "
             "(measure.defects)", "1"),
    Quantity("n_reversals_mean", r"\langle n_{rev}\rangle", "ensemble mean number of reversals of handedness", "1"),
    Quantity("n_reversals_std", r"\sigma", "ensemble standard deviation of the number of reversals", "1"),
    Quantity("decay_ratio_member", r"\frac{d(1/|F_z|)/ds}{k_{fr}R/(4EI)}", "bulk decay rate over the corrected law "
             "of each member (0 where has_bulk_member is 0)", "1"),
    Quantity("decay_ratio_mean", r"\langle\cdot\rangle", "ensemble mean of the bulk decay rate over the corrected "
             "law (members with a bulk)", "1"),
    Quantity("decay_ratio_std", r"\sigma", "ensemble standard deviation of the bulk decay rate over the corrected "
             "law", "1"),
    # the axial torque budget (torque.py), per member in the bulk and along s
    *_member_stats("torque_closure", r"|\Gamma(L)|/\sum|\rho f_\varphi|", "axial torque of the wall friction on "
                   "the whole rod over the sum of its magnitudes: 0 when the budget closes (both ends free to turn)",
                   "1", "each member"),
    *[q for key, sym, text in (
        ("torque_friction_ratio", r"\tau\,\mathrm{sgn}\,w/\tau_0", "median over the bulk of the axial torque the "
         "friction left in the rod, signed along the handedness, over EI R^2 w0^3, w0 = sqrt(|F_z|/(2EI))"),
        ("torque_helix_ratio", r"\tau_{helix}\,\mathrm{sgn}\,w/\tau_0", "median over the bulk of the axial torque "
         "the local helix carries, rho^2 w (2EI w^2 - |F_z|/c), over EI R^2 w0^3"),
        ("torque_budget_residual", r"|\tau-\tau_{helix}|/(\tau_0+|\tau|)", "median over the bulk of the difference "
         "between the torque from the friction and from the local helix, link by link, over tau_0 + |tau|"),
        ("pitch_w0_ratio", "|w|/w_0", "median over the bulk of the pitch rate over the lowest-order "
         "torque-free rate w0 = sqrt(|F_z|/(2EI)) (pitch_ratio: over the exact one)"),
        ("K_ratio", r"K/K_{model}", "bulk wall force per length over the corrected simple model's R F_z^2/(4EI)"),
        ("K_ratio_from_torque", r"K_\tau/K_{model}", "bulk wall force per length predicted by the local pitch and "
         "the friction's torque, (EI rho^2 w^4 - w tau)/rho, over R F_z^2/(4EI)"),
        ("K_ratio_from_pitch", r"K_w/K_{model}", "bulk wall force per length predicted by the local pitch and "
         "force of a constant-pitch helix, rho w^2 (|F_z|/c - EI w^2), over R F_z^2/(4EI) (to lowest order "
         "x^2 (2 - x^2), x = |w|/w0)"),
        ("lower_torque_ratio", r"\tau(s_l)\,\mathrm{sgn}\,w/\tau_0", "axial torque the lower region receives "
         "from the bulk, at its start, signed along the bulk's handedness, over EI R^2 w0^3"),
        ("lower_azimuthal_share", r"\langle|f_\varphi|/|f|\rangle_{lower}", "mean azimuthal share of the friction "
         "on the lower region's links on the wall"),
        ("lower_utilisation", r"\langle|f|/f_{max}\rangle_{lower}", "mean friction utilisation |f|/min(k_fr N, "
         "friction_cap) on the lower region's links on the wall"),
        ("lower_stuck_share", r"\langle\mathrm{stuck}\rangle_{lower}", "share of the lower region's links on the "
         "wall in static friction"))
      for q in _member_stats(key, sym, text, "1", "each member; 0 where has_bulk_member is 0")],
    *_member_stats("lower_torque", r"\tau(s_l)\,\mathrm{sgn}\,w", "axial torque at the start of the lower region, "
                   "signed along the bulk's handedness", "EI R-1", "each member; 0 where has_lower_member is 0"),
    *_member_stats("bulk_torque_max", r"\max_{bulk}|\tau|", "largest axial torque carried in the bulk", "EI R-1",
                   "each member; 0 where has_lower_member is 0"),
    Quantity("torque_friction", r"\tau", "axial torque carried through the rod at the link centre, from the wall "
             "friction above it (-Gamma), signed along the bulk's handedness", "EI R-1"),
    Quantity("torque_helix", r"\tau_{helix}", "axial torque of the local helix, rho^2 w (2EI w^2 - |F_z|/c), signed "
             "along the bulk's handedness (0 off the helix)", "EI R-1"),
    Quantity("has_lower_member", "", "1 where the member has a bulk and a lower region on the wall", "1"),
    Quantity("converged_member", "", "the member reached the equilibrium criterion (1) or not (0)", "1"),
    Quantity("torque_scale", r"\tau_0", "EI R^2 w0^3, w0 = sqrt(|F_z|/(2EI)): the bending torque of a torque-free "
             "helix at the local force", "EI R-1"),
    Quantity("on_helix", "", "link on the wall within the contact stretch, with a defined pitch (1) or not (0)", "1"),
    # Fig 1: shapes
    Quantity("n_turns_scene", "n_{turns}", "turns of the wall-contact stretch about the axis", "1"),
    Quantity("detached_top", "s_h", "length of the detached upper end (loaded end to first wall contact)", "R"),
    Quantity("detached_bottom", "L - s_e", "length of the detached lower end (last wall contact to the support)", "R"),
    Quantity("end_contact_force", "N_{end}", "wall force on the link of the detached end's tip that touches the wall",
             "EI R-2"),
    Quantity("span_euler_load", "F_g", "Euler's load pi^2 EI/g^2 of the free span (pinned-pinned)", "EI R-2"),
    # the error budget of the headline numbers (analysis.error_budget)
    Quantity("headline", "", "headline number: <figure>.<quantity>.<where>", "1"),
    Quantity("budget_parameter", "", "numerical parameter or bias term of the budget", "1"),
    Quantity("headline_label", "", "what the headline number is", "1"),
    Quantity("headline_figure", "", "figure that reports the headline number", "1"),
    Quantity("headline_quantity", "", "kind of the headline number: F_transmitted (a transmitted fraction), "
             "decay_ratio, threshold or defect_fraction", "1"),
    Quantity("headline_protocol", "", "loading protocol of the headline's runs", "1"),
    Quantity("headline_note", "", "how the headline number and its statistical error are obtained", "1"),
    Quantity("headline_value", "", "headline number, in the reduced unit its label states", "1"),
    Quantity("stat_error", r"\sigma_{stat}", "relative standard error of the headline number over seeds "
             "(0 where not measured: has_stat_error)", "1"),
    Quantity("stat_factor", "t", "factor of stat_error giving its 95 % half-width: Student's t for n_seeds - 1 "
             "degrees of freedom (1.96 for a Wilson interval)", "1"),
    Quantity("has_stat_error", "", "the statistical error is measured (1) or not (0: a single frictional run)", "1"),
    Quantity("bias", r"\delta_p", "relative numerical bias of the headline from this parameter: the shift of the "
             "publication rung's ensemble mean from the finest rung of its ladder, or a bias term of a threshold",
             "1"),
    Quantity("bias_se", r"\sigma_p", "standard error of the relative numerical bias (0 for a bias term known "
             "exactly)", "1"),
    Quantity("has_bias", "", "the bias from this parameter is measured (1) or not (0)", "1"),
    Quantity("bias_factor", "t", "factor of bias_se in the 95 % bound of this bias term: Student's t for the "
             "ladder comparison's degrees of freedom", "1"),
    Quantity("bias_transferred", "", "the bias term was measured at another rod (L, k_fr or load) than the "
             "headline's and transferred as a relative shift (1) or at the headline's rod (0)", "1"),
    Quantity("bias_limit_factor", "", "distance of the publication numerics from the limit over the bias term "
             "(their shift from the ladder's finest rung) for a first-order term, 1/(1 - h_fine/h_pub); 1 where no "
             "ladder measured the term", "1"),
    Quantity("bias_lower_bound", "", "the bias term is a lower bound (1): read from a ladder that fails on the "
             "headline's quantity, with no asymptotic range to extrapolate; 0 a first-order estimate", "1"),
    Quantity("bias_source", "", "where the bias was measured (ladder and its rod) or how it is known", "1"),
    Quantity("bias_bound", r"B_{95}", "95 % bound of the relative numerical bias: sum over the parameters of "
             "|delta_p|, plus t (the largest bias_factor) times the root sum of squares of sigma_p", "1"),
    Quantity("limited_by", "", "what limits the headline number: 0 its statistics (t sigma_stat >= B_95), "
             "1 its numerics, 2 unknown (statistical error or every bias term not measured, or a bias known "
             "only from below that stays under the statistical error)", "1"),
]

QUANTITIES = SCENE_FILE_QUANTITIES.extended(FIGURE_QUANTITIES)
attrs, error_attrs, variable = QUANTITIES.attrs, QUANTITIES.error_attrs, QUANTITIES.variable
label, param_text = QUANTITIES.label, QUANTITIES.param_text
