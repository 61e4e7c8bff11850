"""Reports: the Markdown and JSON text and the figures of every study, written from the
results the experiments computed and stored (:mod:`mhtrack.experiments`), drawn with
:mod:`mhtrack.plotting`.

* :mod:`~mhtrack.reports.montecarlo` — ``summary.md`` and ``ospa_cardinality.png``;
* :mod:`~mhtrack.reports.p1` (text in :mod:`~mhtrack.reports.p1_text`) — Table 3, the
  report and Figs. 2–6 of ``reproduce p1``;
* :mod:`~mhtrack.reports.p2` (text in :mod:`~mhtrack.reports.p2_text`) —
  ``results.json``, the tables, the report and Figs. 2–4, 12–15 of ``reproduce p2``;
* :mod:`~mhtrack.reports.initiation` — the clustering and initiation figures of one run
  (``cluster --figure``, ``initiate --figure``);
* :mod:`~mhtrack.reports.html_report` — ``mhtrack report``: one self-contained HTML page of
  a run or a study (Plotly; :mod:`~mhtrack.reports.html_page`, ``html_scene``,
  ``html_metrics``, ``html_study``).
"""
