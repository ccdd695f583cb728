"""Where every random number of a run comes from.

Realization ``i`` of a run with root ``seed`` uses
``SeedSequence(seed, spawn_key=(0, i))``: the same child that
``SeedSequence(seed, spawn_key=(0,)).spawn`` would make, addressable directly,
so a realization's numbers do not depend on order, worker count or executor,
and any subset can be recomputed alone. The bootstrap of the fit uses the
separate stream ``spawn_key=(1,)``; replicate ensembles of a study (the same
scene on independent lines) take their root seeds from ``spawn_key=(2,)``.
"""

from __future__ import annotations

import numpy as np

REALIZATION_KEY = 0
BOOTSTRAP_KEY = 1
REPLICATE_KEY = 2


def realization_seed(seed: int, index: int) -> np.random.SeedSequence:
    return np.random.SeedSequence(seed, spawn_key=(REALIZATION_KEY, index))


def realization_rng(seed: int, index: int) -> np.random.Generator:
    return np.random.default_rng(realization_seed(seed, index))


def bootstrap_rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(BOOTSTRAP_KEY,)))


def replicate_seeds(seed: int, count: int) -> list[int]:
    """Root seeds of ``count`` independent ensembles of one scene: ``seed`` itself (the
    scene's own run), then ``count - 1`` seeds drawn from ``SeedSequence(seed, spawn_key=(2,))``."""
    drawn = np.random.SeedSequence(seed, spawn_key=(REPLICATE_KEY,)).generate_state(max(count - 1, 0), dtype=np.uint32)
    return [int(seed), *(int(s) for s in drawn)][:count]
