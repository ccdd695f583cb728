"""Running ensembles: one realization (``realization``), the ensemble's statistics and fit
(``ensemble``, ``fit``), the engine that runs them (``engine``) on an executor (``executors``:
serial, a process pool (``pool``), or Dask (``dask_session``, ``dask_security``)), with the
memory check (``memory``) and the signals that end a run cleanly (``signals``)."""
