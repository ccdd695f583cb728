"""``frictionlab predict``: the rms slope in contact of a 3D contact from a fitted law
(given, or a run folder's), with its interval."""

from __future__ import annotations

import argparse

from ..errors import ExitCode, FrictionlabError


def add_parser(sub) -> None:
    p = sub.add_parser(
        "predict",
        help="rms slope in contact of a 3D contact from a fitted law",
        description="The rms slope in contact of a contact of area A, modulus E*, rms height h under force F, "
        "from a law xi = a + b ln f (given, or a run folder's), with its interval.",
        epilog="examples:\n  frictionlab predict --a 1.88 --b 0.08 --area 1e-4 --modulus 1e9 --rms-height 1e-6 --force 1e-5\n"
        "  frictionlab predict --from runs/fig2 --area 1e-4 --modulus 1e9 --rms-height 1e-6 --force 1e-5 --json",
    )
    p.add_argument("--a", type=float, help="the law's a")
    p.add_argument("--b", type=float, help="the law's b")
    p.add_argument("--a-ci", type=float, nargs=2, metavar=("LO", "HI"), help="interval of a (LO <= HI)")
    p.add_argument("--b-ci", type=float, nargs=2, metavar=("LO", "HI"), help="interval of b (LO <= HI)")
    p.add_argument("--confidence", type=float, help="level of the given intervals, in (0, 1) (default 0.95)")
    p.add_argument("--from", dest="from_run", metavar="RUN_DIR", help="take the law from a run folder (summary.json)")
    p.add_argument("--area", type=number, required=True, metavar="A", help="apparent contact area A")
    p.add_argument("--modulus", type=number, required=True, metavar="ESTAR", help="effective modulus E*")
    p.add_argument("--rms-height", type=number, required=True, metavar="H", help="rms height h of the surface")
    p.add_argument("--force", type=number, required=True, metavar="F", help="normal force F")
    p.add_argument("--rms-slope", type=number, metavar="S", help="the surface's rms slope: also print S * xi")
    p.add_argument("--json", action="store_true", help="as JSON")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    """``frictionlab predict``: print the law's xi (and interval) for the given A, E*, h, F."""
    from ..compute.fit import LogFit, format_number, json_safe
    from ..paper.predict import check_law, predict_xi, prediction_text, read_run_law

    if args.from_run:
        given = [name for name, value in (("--a", args.a), ("--b", args.b), ("--a-ci", args.a_ci), ("--b-ci", args.b_ci),
                                          ("--confidence", args.confidence)) if value is not None]  # fmt: skip
        if given:
            raise FrictionlabError(
                f"give either --from RUN_DIR or the law by hand, not both: {', '.join(given)} with --from "
                "(the run's summary.json holds its law, intervals and confidence)"
            )
        law, fitted_f, pairs = read_run_law(args.from_run, "--from")
    else:
        if args.a is None or args.b is None:
            raise FrictionlabError("give the law: --a A --b B (with --a-ci/--b-ci for an interval), or --from RUN_DIR")
        if (args.a_ci is None) != (args.b_ci is None):
            raise FrictionlabError("--a-ci and --b-ci go together (an interval needs both)")
        intervals = {"a_ci": tuple(args.a_ci), "b_ci": tuple(args.b_ci)} if args.a_ci else {}
        confidence = 0.95 if args.confidence is None else args.confidence
        law, fitted_f, pairs = LogFit(args.a, args.b, confidence=confidence, **intervals), None, None
        check_law(law, {field: "--" + field.replace("_", "-") for field in ("a", "b", "a_ci", "b_ci", "confidence")})
        if args.confidence is not None and args.a_ci is None:  # as --tls-cert without a tls:// scheduler
            raise FrictionlabError(f"--confidence {args.confidence:g} is the level of --a-ci and --b-ci, but there are "
                                   "none: it would be ignored; give the intervals, or leave --confidence out")  # fmt: skip
        for field in intervals:  # a typo (a and b swapped): xi printed beside an interval that excluded it
            value, (low, high) = getattr(law, field[0]), intervals[field]
            if not low <= value <= high:
                raise FrictionlabError(f"--{field[0]} {value!r} lies outside its interval --{field.replace('_', '-')} "
                                       f"{low!r} {high!r}: an interval of the law's {field[0]} holds it; check the values")  # fmt: skip
    prediction = predict_xi(
        law, force=args.force, modulus=args.modulus, rms_height=args.rms_height, area=args.area,
        pairs=pairs, fitted_f=fitted_f, rms_slope=args.rms_slope,
        names={field: "--" + field.replace("_", "-") for field in ("force", "modulus", "rms_height", "area", "rms_slope")},
    )  # fmt: skip
    if args.json:
        out = {k: v for k, v in prediction.__dict__.items()}
        out.update(extrapolated=prediction.extrapolated, beyond_full_contact=prediction.beyond_full_contact,
                   a=law.a, b=law.b)  # fmt: skip
        from .jsonout import emit

        emit("predict", {k: json_safe(v) for k, v in out.items()})
    else:
        print(f"law: xi = {format_number(law.a)} + {format_number(law.b)} ln f")
        print(prediction_text(prediction))
    return ExitCode.OK


def number(text: str) -> float:
    """``float(text)``, refused where it rounds a number that is not zero to 0 (1e-400): the
    check on the value would say 'Got 0.0', a number the user never typed."""
    value = float(text)
    if value == 0 and any(digit in "123456789" for digit in text.lower().split("e")[0]):
        raise argparse.ArgumentTypeError(f"{text} is below the smallest number above 0 a double holds (about 5e-324)")
    return value
