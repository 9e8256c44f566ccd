"""A run from its plan to its report: what a run checks before it samples, the summaries,
the figures, the HTML page and the streamed writing of every output.

Modules:

- ``bands``: The figures' bands (``attitude.report.plots``), rasterised per pixel column.
- ``beside``: One computation in a forked process beside the run, on the machine's other
  core.
- ``figures``: What the report's figures show, sampled from the exact motion, and where
  they zoom.
- ``guidance``: What a run says about its attitude laws: the law of each segment, the
  slews, the control losses and the ground sites' passes.
- ``page``: The report's HTML page: the summary as tables, the plots, links to the data
  files.
- ``plan``: Everything a run checks before it samples: one path for ``attitude check``
  and ``run``.
- ``plots``: The report's figures (PNG), drawn with matplotlib's object API on an Agg
  canvas.
- ``run``: A scenario run, from a scenario to its report folder, streamed in chunks.
- ``summaries``: The run's summary (``summary.json``, and the report page built from
  it): what each part of it says, from the objects that hold it.
- ``ticks``: The figures' ticks, tick labels, grid lines and axis labels, drawn as a few
  artists.
- ``torques``: What a run says about torques: which were modelled, the method, its step
  and error.
"""
