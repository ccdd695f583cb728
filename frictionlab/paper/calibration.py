"""Finding the rms height h that reproduces the paper's mean contact counts.

The paper (Fig. 2) reports about 4 points in contact at F = 1 and 12 at F = 20
(E = 1, N = L = 1e5, H = 1) but not h. With fixed amplitudes the contact count
depends on F / (E* h) only, so one ensemble at h = 1 over a wide force range
gives the mean count n(F/h) for every h at once; ``CountCurve.fit_rms_height``
solves n(1/h) = 4 and n(20/h) = 12 in the least-squares sense (in log). The
presets' h = 1e4 was found so, and the report's calibrated readings use it::

    python -m frictionlab.paper.calibration presets/benad2012-fig2.yaml
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from ..compute import engine
from ..compute.signals import WorkInterrupted, interrupted_exit_code, interrupted_word
from ..errors import RunError
from ..options import RunOptions
from ..preset import apply_overrides, build_scene, load_preset_file
from ..preset.builtin import resolve_preset_path
from .figures import COUNT_TARGETS


@dataclass(frozen=True)
class CountCurve:
    """Mean contact count against F / h, from one ensemble at h = 1: with fixed
    amplitudes the count depends on F / (E* h) only, so this serves every h."""

    log_g: np.ndarray  # log(F / h)
    log_n: np.ndarray  # log(mean count), non-decreasing in log_g

    def mean_count(self, force: float, h: float) -> float:
        return math.exp(float(np.interp(math.log(force / h), self.log_g, self.log_n)))

    def rms_height_alone(self, force: float, count: float) -> float:
        """The h that gives ``count`` at ``force`` (the curve inverted)."""
        return force / math.exp(float(np.interp(math.log(count), self.log_n, self.log_g)))

    def fit_rms_height(self, targets: dict[float, float]) -> float:
        """Least squares in log count over the targets."""
        from scipy.optimize import minimize_scalar

        def misfit(log_h):
            return sum((np.interp(math.log(F) - log_h, self.log_g, self.log_n) - math.log(n)) ** 2 for F, n in targets.items())

        alone = [math.log(self.rms_height_alone(F, n)) for F, n in targets.items()]
        best = minimize_scalar(misfit, bounds=(min(alone) - 1e-9, max(alone) + 1e-9), method="bounded")
        return math.exp(best.x)


def count_curve(data: dict, options: RunOptions = RunOptions(), listeners=()) -> CountCurve:
    """One ensemble of the preset ``data`` at h = 1 over a wide log force range."""
    wide = [
        "spectrum.params.rms_height=1.0", "spectrum.params.c0=null", "loading.start=1.0e-6", "loading.stop=1.0e+3",
        "loading.steps=2000", "loading.spacing=log", "fit.bootstrap=0", "sweep=null",
    ]  # fmt: skip
    outcome = engine.run(build_scene(apply_overrides(data, wide)), options, listeners=listeners)
    done = f"after {len(outcome.indices)} of {outcome.requested} realizations"
    if outcome.status in ("interrupted", "cancelled"):  # a part of the ensemble gives another h: never print it
        raise WorkInterrupted(f"the calibration's ensemble ended {outcome.status} {done}; no h from a part of it")
    if outcome.status != "completed":
        raise RunError(f"the calibration's ensemble {outcome.status} {done}: {outcome.error}")
    return CountCurve(np.log(outcome.loads), np.log(outcome.contact_count))


def calibrated_rms_height(
    data: dict, targets: dict[float, float] = COUNT_TARGETS, options: RunOptions = RunOptions(), listeners=()
) -> float:
    """h that gives the target mean contact counts (3 significant figures); ``listeners``
    hear the calibration's ensemble (its progress)."""
    return float(f"{count_curve(data, options, listeners).fit_rms_height(targets):.3g}")


def main(path: str) -> None:
    """Print the calibrated h of the preset at ``path`` (a file, or a built-in's name as
    ``frictionlab run`` takes it), and what each target alone gives."""
    curve = count_curve(load_preset_file(resolve_preset_path(path)))
    h = curve.fit_rms_height(COUNT_TARGETS)
    print(f"least-squares (in log) h = {h:.4g}")
    for F, n in COUNT_TARGETS.items():
        print(
            f"  F = {F:g}: mean count {curve.mean_count(F, h):.2f} (paper {n:g}); "
            f"this target alone gives h = {curve.rms_height_alone(F, n):.4g}"
        )
    counts_at = ", ".join(f"{curve.mean_count(F, 1e4):.2f} at F = {F:g}" for F in COUNT_TARGETS)
    print(f"  h = 1e4 (the presets'): {counts_at}")


def cli(argv: list[str] | None = None) -> int:
    """``python -m frictionlab.paper.calibration PRESET``: usage and input errors said in a line."""
    import argparse

    from ..errors import FrictionlabError, output_failed

    parser = argparse.ArgumentParser(
        prog="python -m frictionlab.paper.calibration",
        description="Find the rms height h that gives the paper's mean contact counts (4 at F = 1, 12 at F = 20).",
        epilog="example: python -m frictionlab.paper.calibration presets/benad2012-fig2.yaml (benad2012-fig2 anywhere)",
    )
    parser.add_argument(
        "preset", help="a preset file, or a built-in's name, of the Fig. 2 scene (its h is ignored: one ensemble at h = 1)"
    )
    args = parser.parse_args(argv)
    try:
        main(args.preset)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's last flush
    except BrokenPipeError as exc:  # `... | head -1`: the reader has enough
        return output_failed(exc)
    except FrictionlabError as exc:
        print(f"frictionlab: {exc}", file=sys.stderr)
        return int(exc.exit_code)
    except KeyboardInterrupt as exc:  # Ctrl-C or SIGTERM: said in a line, with the signal's exit code
        said = f": {exc}" if str(exc) else ""
        print(f"frictionlab: {interrupted_word()}{said}", file=sys.stderr)
        return int(interrupted_exit_code())
    return 0


if __name__ == "__main__":
    sys.exit(cli())
