"""Find the rms height h that reproduces the study's mean contact counts (SPEC 7).

The study (Benad 2012, Fig. 2) reports about 4 points in contact at F = 1 and
12 at F = 20 (E = 1, N = L = 1e5, H = 1) but not h. With fixed amplitudes the
contact count depends on F / (E* h) only (SPEC 5), so one ensemble at h = 1
over a wide force range gives the mean count n(F/h) for every h at once; this
script solves n(1/h) = 4 and n(20/h) = 12 in the least-squares sense (in log)
and prints what each target alone would give. The method is
``frictionlab.report.count_curve`` (the report's readings use it too).

    python tools/calibrate_rms_height.py presets/benad2012-fig2.yaml
"""

import sys

from frictionlab.preset import load_preset_file
from frictionlab.report import COUNT_TARGETS, count_curve


def main(path: str) -> None:
    curve = count_curve(load_preset_file(path))
    h = curve.fit_rms_height(COUNT_TARGETS)
    print(f"least-squares (in log) h = {h:.4g}")
    for F, n in COUNT_TARGETS.items():
        print(
            f"  F = {F:g}: mean count {curve.mean_count(F, h):.2f} (study {n:g}); "
            f"this target alone gives h = {curve.rms_height_alone(F, n):.4g}"
        )
    counts_at = ", ".join(f"{curve.mean_count(F, 1e4):.2f} at F = {F:g}" for F in COUNT_TARGETS)
    print(f"  h = 1e4 (the presets'): {counts_at}")


if __name__ == "__main__":
    main(sys.argv[1])
