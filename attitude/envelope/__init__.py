"""The loss-of-control envelope: for a control loss at every instant of a nominal
timeline under attitude laws, the exact motion after it and how soon it goes wrong.

Modules:

- ``settings``: The ``[envelope]`` table (failure times, window, wheels, power threshold)
  and :class:`EnvelopeSettings`, checked against the scenario and the job's budget.
- ``power``: The panels' sunlit power fraction and the first time it falls below a
  threshold, by a Lipschitz search that cannot miss a dip.
- ``failure``: One control loss: the hand-off, the motion over the window, its metrics
  from the exact pointing search; a batch of failures on a worker.
- ``plan``: The envelope checked (:func:`plan_envelope`, also run by ``attitude check``)
  and the job every worker gets: the nominal states at every failure time, handed off.
- ``engine``: The failures on Dask, by the Monte Carlo's engine.
- ``report``: The table (Parquet, CSV), the plots against the failure time,
  summary.json (the worst τ and its margins) and the page.
- ``job``: :func:`loss_of_control_envelope`, the Python entry point.
"""
