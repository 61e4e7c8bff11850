"""Figures: they only draw.

Each function takes data (tables, arrays, summaries) and returns a
:class:`matplotlib.figure.Figure`; none simulates, runs a tracker or switches the
matplotlib backend on import. :func:`~mhtrack.plotting.scene.save_figure` writes a figure.
"""
