"""Benchmark: the exact solvers' contact CG, old against new, and against Tamaas.

The scene: a 512 x 512 periodic self-affine surface (power-law-2d, H = 0.8, rms
height 1, short cut-off 8 pixels, long cut-off the side, spacing 1), E* = 1, and
20 forces log-spaced from 20 to 1000 (about 0.5 % to 19 % contact). Each solver
runs a cold load (the first, the tenth and the last force, alone) and the
20-load sweep (warm-started, as a run solves it):

* ``polonsky-keer``: the constrained CG of Polonsky & Keer, the solver before
  this one, at the default tolerance 1e-8;
* ``pcg tolerance``: the preconditioned projected CG, stopped at the tolerance 1e-8;
* ``pcg certified``: the same CG with the certified stop (the default);
* Tamaas's PolonskyKeerRey at tolerance 1e-10 (``pip install tamaas``, the
  ``bench`` extra), its sweep on one solver object (warm), its cold loads each on
  a new one.

It prints FFT pairs (one forward and one inverse transform; the stable measure
on a shared machine), in double and in single precision (a single-precision
pair takes about half the time), and seconds of CPU and of wall time (the run of
least CPU time of ``--repeat``, the solvers alternating; CPU time, all threads
counted, is what a busy shared machine disturbs least), the ratios of CPU time to
the new default, and the contact counts checked at every load against cold
solves at tolerance 1e-12 (Tamaas's too). Run single-threaded::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_bem.py [--repeat 3] [--side 512] [--no-tamaas]

``--line``: ``bem-halfplane`` on an 8192-point power-law line (H = 0.8), a 20-load
sweep, old against new. ``--tamaas-surface``: the surface made by Tamaas's own
generator (``SurfaceGeneratorFilter2D``, the same spectrum, scaled to rms height 1)
instead of frictionlab's.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from frictionlab import Profile
from frictionlab.preset.seeds import realization_rng
from frictionlab_solvers import bem
from frictionlab_solvers.elastic import PeriodicHalfSpace
from frictionlab_spectra.power_law import PowerLaw
from frictionlab_spectra.surface import PowerLawSurface
from polonsky_keer import PolonskyKeerCG  # this folder's: the baseline
from tamaas_reference import load_tamaas, tamaas_sweep  # this folder's

SEED = 2024
FFT_PAIRS = [0, 0]  # float64, float32


class CountingOperator(PeriodicHalfSpace):
    """The periodic half-space, counting its FFT pairs in double and single precision."""

    def _apply(self, kernel, field, out):
        FFT_PAIRS[0] += 1
        return super()._apply(kernel, field, out)

    def _apply_single(self, kernel, field, out):
        FFT_PAIRS[1] += 1
        return super()._apply_single(kernel, field, out)


bem.PeriodicHalfSpace = CountingOperator  # the solvers build their operator from this name


class PolonskyKeer(bem.BEMHalfSpace):
    contact_cg = PolonskyKeerCG


class PolonskyKeerLine(bem.BEMHalfPlane):
    contact_cg = PolonskyKeerCG


def scene(side: int, tamaas=None):
    """The surface (frictionlab's power-law-2d, or with ``tamaas`` the same spectrum
    made by Tamaas's own generator) and the 20 forces."""
    if tamaas is None:
        profile = PowerLawSurface(hurst=0.8, points=side, spacing=1.0, short_cutoff=8.0, rms_height=1.0).generate(
            realization_rng(SEED, 0)
        )
    else:
        spectrum = tamaas.Isopowerlaw2D()  # wave numbers in units of 2 pi / side
        spectrum.q0, spectrum.q1, spectrum.q2, spectrum.hurst = 1, 1, side // 8, 0.8
        generator = tamaas.SurfaceGeneratorFilter2D([side, side])
        generator.spectrum, generator.random_seed = spectrum, SEED
        z = np.array(generator.buildSurface())
        profile = Profile(z / z.std(), 1.0)
    forces = np.geomspace(20.0, 1000.0, 20) * (side / 512) ** 2  # the same contact fractions at any side
    return profile, forces


def timed(work):
    """((CPU, wall) seconds, (float64, float32) FFT pairs, answer) of one run of ``work``."""
    FFT_PAIRS[:] = [0, 0]
    cpu, wall = time.process_time(), time.perf_counter()
    answer = work()
    return (time.process_time() - cpu, time.perf_counter() - wall), tuple(FFT_PAIRS), answer


def best(runs):
    """The run of least CPU time (pairs and answers are the same in each)."""
    return min(runs, key=lambda run: run[0][0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="best of this many runs")
    parser.add_argument("--side", type=int, default=512, help="surface side in pixels (forces scale with the area)")
    parser.add_argument("--no-tamaas", action="store_true", help="skip Tamaas even when it is installed")
    parser.add_argument("--line", action="store_true", help="bem-halfplane on an 8192-point line instead")
    parser.add_argument(
        "--tamaas-surface", action="store_true", help="the surface made by Tamaas's generator (same spectrum)"
    )
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1. Got {args.repeat} instead.")
    if args.side < 16:
        parser.error(f"--side must be at least 16. Got {args.side} instead.")
    if args.line:
        line_sweep(args.repeat)
        return
    tamaas = None if args.no_tamaas else load_tamaas()
    if tamaas is None and not args.no_tamaas:
        print("Tamaas is not installed (pip install tamaas, or the 'bench' extra): no comparison with it")
    if args.tamaas_surface and tamaas is None:
        parser.error("--tamaas-surface needs Tamaas (pip install tamaas, or the 'bench' extra) and no --no-tamaas")
    profile, forces = scene(args.side, tamaas if args.tamaas_surface else None)
    slopes = np.ones_like(profile.heights)
    cold = (0, 9, 19)
    solvers = {
        "polonsky-keer": PolonskyKeer(stop="tolerance"),
        "pcg tolerance": bem.BEMHalfSpace(stop="tolerance"),
        "pcg certified": bem.BEMHalfSpace(stop="certified"),
    }
    default = f"pcg {bem.BEMHalfSpace().params.stop}"
    runs = {name: {"sweep": [], **{j: [] for j in cold}} for name in solvers}
    if tamaas is not None:
        runs["Tamaas 1e-10"] = {"sweep": [], **{j: [] for j in cold}}
    for _ in range(args.repeat):
        for name, solver in solvers.items():
            runs[name]["sweep"].append(timed(lambda: solver.solve(profile, forces, "force", slopes).contact_count))
            for j in cold:
                runs[name][j].append(timed(lambda: solver.solve(profile, forces[j : j + 1], "force", slopes).contact_count))
        if tamaas is not None:
            runs["Tamaas 1e-10"]["sweep"].append(tamaas_sweep(tamaas, profile.heights, forces))
            for j in cold:
                runs["Tamaas 1e-10"][j].append(tamaas_sweep(tamaas, profile.heights, forces[j : j + 1]))

    exact = bem.BEMHalfSpace(tolerance=1e-12, stop="tolerance")
    reference = np.array([exact.solve(profile, forces[j : j + 1], "force", slopes).contact_count[0] for j in range(20)])
    side = args.side
    made = "Tamaas's generator" if args.tamaas_surface else "power-law-2d"
    print(f"bem-halfspace, {side} x {side} surface ({made}) H = 0.8, rms height 1, short cut-off 8 px, long cut-off {side} px, "
          f"E* = 1; 20 forces {forces[0]:g} .. {forces[-1]:g} (contact {reference[0] / side**2:.2%} .. "
          f"{reference[-1] / side**2:.2%}); best of {args.repeat}")  # fmt: skip
    print(f"  {'solver':<15}{'what':<25}{'FFT pairs f64 + f32':>20}{'CPU s':>8}{'wall s':>8}"
          f"{'x default (CPU)':>17}  contact counts")  # fmt: skip
    base = {what: best(runs[default][what]) for what in runs[default]}
    for name, by_what in runs.items():
        for what, results in by_what.items():
            seconds, pairs, counts = best(results)
            loads = slice(None) if what == "sweep" else slice(what, what + 1)
            wrong = int(np.count_nonzero(np.asarray(counts) != reference[loads]))
            label = "20-load sweep" if what == "sweep" else f"cold load {what + 1} (F {forces[what]:.4g})"
            pairs_text = f"{pairs[0]:11d} + {pairs[1]:6d}" if pairs is not None else f"{'-':>20}"
            verdict = "= 1e-12 solves" if wrong == 0 else f"{wrong} loads differ from 1e-12 solves"
            ratio = seconds[0] / base[what][0][0]
            print(f"  {name:<15}{label:<25}{pairs_text}{seconds[0]:8.2f}{seconds[1]:8.2f}{ratio:16.2f}x  {verdict}")


def line_sweep(repeat: int) -> None:
    """bem-halfplane: a 20-load sweep on an 8192-point power-law line (H = 0.8,
    spacing 1, forces per unit depth 0.5 .. 20), old against new."""
    profile = PowerLaw(hurst=0.8, points=8192, spacing=1.0).generate(realization_rng(SEED, 1))
    forces = np.geomspace(0.5, 20.0, 20)
    slopes = np.ones_like(profile.heights)
    solvers = {
        "polonsky-keer": PolonskyKeerLine(stop="tolerance"),
        "pcg tolerance": bem.BEMHalfPlane(stop="tolerance"),
        "pcg certified": bem.BEMHalfPlane(stop="certified"),
    }
    runs = {name: [] for name in solvers}
    for _ in range(repeat):
        for name, solver in solvers.items():
            runs[name].append(timed(lambda: solver.solve(profile, forces, "force", slopes)))
    exact = bem.BEMHalfPlane(tolerance=1e-12, stop="tolerance")
    reference = np.array([exact.solve(profile, forces[j : j + 1], "force", slopes).contact_count[0] for j in range(20)])
    print(f"bem-halfplane, 8192-point power-law line H = 0.8; 20 forces {forces[0]:g} .. {forces[-1]:g} per unit depth "
          f"(contact {reference[0] / 8192:.2%} .. {reference[-1] / 8192:.2%}); best of {repeat}")  # fmt: skip
    print(f"  {'solver':<15}{'FFT pairs f64 + f32':>20}{'CPU s':>8}{'wall s':>8}{'iterations':>11}  contact counts")
    for name, results in runs.items():
        seconds, pairs, curve = best(results)
        wrong = int(np.count_nonzero(curve.contact_count != reference))
        verdict = "= 1e-12 solves" if wrong == 0 else f"{wrong} loads differ from 1e-12 solves"
        print(f"  {name:<15}{pairs[0]:11d} + {pairs[1]:6d}{seconds[0]:8.2f}{seconds[1]:8.2f}"
              f"{int(curve.extras['iterations'].sum()):11d}  {verdict}")  # fmt: skip


if __name__ == "__main__":
    main()
