"""Where every random number of a run comes from.

Realization ``i`` of a run with root ``seed`` uses
``SeedSequence(seed, spawn_key=(0, i))``: the same child that
``SeedSequence(seed, spawn_key=(0,)).spawn`` would make, addressable directly,
so a realization's numbers do not depend on order, worker count or executor,
and any subset can be recomputed alone. The bootstrap of the fit uses the
separate stream ``spawn_key=(1,)``.
"""

from __future__ import annotations

import numpy as np

REALIZATION_KEY = 0
BOOTSTRAP_KEY = 1


def realization_seed(seed: int, index: int) -> np.random.SeedSequence:
    return np.random.SeedSequence(seed, spawn_key=(REALIZATION_KEY, index))


def realization_rng(seed: int, index: int) -> np.random.Generator:
    return np.random.default_rng(realization_seed(seed, index))


def bootstrap_rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(BOOTSTRAP_KEY,)))
