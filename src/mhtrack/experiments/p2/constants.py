"""P2 (Gong, Dai & Ma 2013, multi-radar track initiation) study constants: the θ, σr and λ
grids, P2's nominal setting, the initiator settings, P2's printed numbers (Tables 1–2),
the method labels and the output file names."""

from __future__ import annotations

#: P2 §2.2: θ ∈ {0, π/18, …, π} (degrees).
THETAS_DEG: tuple[float, ...] = tuple(float(10 * i) for i in range(19))
#: P2 Fig. 3: range errors (m) at λ = 50.
SIGMAS: tuple[float, ...] = (20.0, 30.0, 40.0, 50.0, 60.0)
#: P2 Fig. 4: clutter rates λ at σr = 20 m. P2 §2.2/§3.2: "单扫周期的杂波数 λ" (the clutter
#: count of one scan period), drawn for "the sensor's" field of view; read here as clutter
#: plots **per radar per scan** (``clutter_per="radar"``, 3λ per scan in all);
#: ``clutter_per="scan"`` (``--clutter-per scan``) reads it as λ per scan over all radars.
RATES: tuple[float, ...] = (50.0, 100.0, 150.0, 200.0, 250.0)
#: P2's nominal setting (§2.2, §3).
SIGMA0, RATE0, THETA0 = 20.0, 50.0, 20.0
#: Runs per job (a job is one grid point × a chunk of runs).
CHUNK = 50
#: Initiator settings (those of ``mhtrack initiate``; P2's r = 300 m, Nθ = Nρ = 90, 4 votes).
LOGIC_PARAMS: dict[str, float] = {"gate_radius": 300.0, "v_min": 50.0, "v_max": 400.0}

#: ``--clutter-per`` readings of λ.
CLUTTER_PER: tuple[str, ...] = ("radar", "scan")
#: ``--tracker-settings``: ``"paper"`` runs P2's steps only (adaptive K-means without our
#: repair, merge and gate; modified Hough with P2's acceleration constraint);
#: ``"best"`` (default) our configuration.
SETTINGS: tuple[str, ...] = ("best", "paper")
#: Fusion options of each setting (:class:`~mhtrack.initiation.fusion.AdaptiveKMeansFusion`).
FUSION_PARAMS: dict[str, dict[str, bool]] = {
    "best": {}, "paper": {"enforce_one_per_radar": False, "merge": False, "gate": False}}
#: Extra initiator parameters of each setting (``a_max`` of the modified Hough: ours,
#: P2 names the constraint without a value; :mod:`mhtrack.initiation.hough`).
INITIATOR_PARAMS: dict[str, dict[str, dict[str, float]]] = {
    "best": {}, "paper": {"modified-hough": {"accel_max": 150.0}}}

#: P2's printed numbers (P2 §3, Tables 1–2), their machine, their code.
PAPER_T_CLUSTER = {"random": 0.045, "adaptive": 0.034}
PAPER_T_INIT = {"logic": 0.17, "modified-logic": 0.18, "hough": 114.5,
                "modified-hough": 7.29}
PAPER_COMPLEXITY = {"random": 890, "adaptive": 585}
METHOD_LABELS = {"logic": "3/4 logic", "modified-logic": "modified 3/4 logic",
                 "hough": "Hough", "modified-hough": "modified Hough"}
CLUSTER_LABELS = {"random": "K-means, random start (oracle k)",
                  "adaptive": "adaptive K-means (P2 §1.2)"}
#: The adaptive fusion's label under each ``--tracker-settings`` (honest names: our
#: additions named).
ADAPTIVE_LABELS = {"paper": "adaptive K-means (P2 §1.2)",
                   "best": "adaptive K-means (P2 §1.2) + one-plot-per-radar repair, merge, "
                           "covariance gate (ours)"}
#: The modified Hough's label under each setting.
MODIFIED_HOUGH_LABELS = {"paper": "modified Hough (velocity, acceleration, time order, angle)",
                         "best": "modified Hough (velocity, time order, angle; no "
                                 "acceleration constraint)"}

FIGURES = {"fig2": "fig2_clustering.png", "fig3": "fig3_ptrue_theta.png",
           "fig4": "fig4_pfalse_theta.png", "fig12_15": "fig12_15_initiated.png"}
TABLES_FILE, REPORT_FILE, RESULTS_FILE, JOBS_DIR = ("tables.md", "report.md",
                                                    "results.json", "jobs")
