"""Run folders: writing one (``rundir``, driven by ``runner``; sweeps of them, ``sweep``),
reading one back as untrusted input (``runfolder``, ``results``), the progress logs a
follower reads (``progresslog``, ``sweeplog``), and runs detached from their terminal
(``detached``)."""
