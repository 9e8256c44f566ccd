"""Monte Carlo dispersions on Dask: the dispersions and draws, a sample's metrics, the plan
and tasks, the job (on Dask, through ``attitude.jobs``), its statistics and report.

Modules:

- ``dispersions``: Dispersions: the ``[dispersions]`` table of a scenario file, and the
  samples drawn from it.
- ``job``: A Monte Carlo job from start to end: :func:`run_montecarlo`, the Python entry
  point.
- ``metrics``: The metrics of one Monte Carlo sample: the numbers ``summary.json``
  reports, and each body vector's Sun-angle extremes per time bin (a few kB a sample
  instead of the whole series).
- ``plan``: A Monte Carlo job's plan and its tasks: the job checked before anything runs
  (:func:`plan_montecarlo`, also run by ``attitude check``), what every task needs
  (:class:`Job`), and a batch of samples evaluated on a worker (:func:`evaluate_batch`):
  for each, the sample's document is drawn
  (``attitude.montecarlo.dispersions.draw_sample``), read as a file is read
  (``scenario_from_document``), checked and propagated (``plan_run``), and reduced to
  its metrics (``attitude.montecarlo.metrics``).  A sample that fails is a row with its
  parameters and its error; the job goes on.
- ``report``: The report of a Monte Carlo job: the table, its statistics, plots and a
  page.
- ``simulation``: Monte Carlo dispersions on Dask: a scenario's samples, on every core
  or on a cluster.
- ``statistics``: Statistics of a Monte Carlo table: percentiles, moments, and
  distribution-free bounds.
"""
