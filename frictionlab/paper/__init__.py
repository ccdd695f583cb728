"""The reproduction of the source paper (Benad 2012, the MDR study of the rms slope in
contact): its Figs. 2 to 5 rerun from the presets ``presets/benad2012-fig*.yaml``, the
readings of its method, REPRODUCTION.md (``frictionlab report``), and its law applied
to a 3D contact (``frictionlab predict``). Built on the framework's public modules only.

Modules: ``figures`` (what the paper reports, running the figures' presets),
``readings``, ``calibration`` (the rms height from the paper's contact counts),
``plots``, ``markdown``, ``reproduce`` (the whole report), ``predict``. Nothing is
imported here, so ``frictionlab --help`` stays fast.
"""
