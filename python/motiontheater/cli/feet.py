"""The verbs of the feet: ``contacts`` (the footplant table) and ``skate`` (footskate metrics);
their floor, up and legs flags, which are the cleanup step's and ``view``'s too."""

from __future__ import annotations

import argparse

from ..model.registry import lookup
from .takes import add_output_options, add_take_options, output, take_of
from .verb import Verb


def add_ground_options(parser: argparse.ArgumentParser, names: tuple[str, ...] = ("floor", "up", "legs")) -> None:
    """The flags of the footskate verbs (skate, contacts, view's contacts; render's --up): they are
    the cleanup step's."""
    cleanup = {o.name: o for o in lookup("cleanup").options}
    for name in names:
        option = cleanup[name]
        parser.add_argument(
            option.flag,
            dest=name,
            type=option.parse,
            metavar=option.metavar,
            choices=option.choices or None,
            help=option.help,
        )


def _skate_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    parser.add_argument("--contacts", metavar="FILE", help="the footplants CSV to measure on (default: detected)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_ground_options(parser)
    add_take_options(parser)


def _skate(args: argparse.Namespace) -> int:
    from ..feet.skate import skate_metrics

    motion = take_of(args, args.input)
    report = skate_metrics(motion, args.contacts, legs=args.legs, up=args.up, floor=args.floor)
    print(report.to_json() if args.json else report.text())
    return 0


def _contacts_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    add_output_options(parser, "the CSV file to write")
    add_ground_options(parser)
    add_take_options(parser)


def _contacts(args: argparse.Namespace) -> int:
    from ..feet.footskate import contacts_of, prepare

    target = output(args, args.input)
    motion = take_of(args, args.input)
    arrays, ground, mpu = prepare(motion, legs=args.legs, up=args.up, floor=args.floor)
    table = contacts_of(None, motion, arrays, ground, mpu)
    table.to_csv(target)
    print(f"contacts: {len(table)} plants in {motion.frames} frames of {args.input}: wrote {target}")
    return 0


VERBS = [
    Verb(
        "skate",
        "measure footskate: sliding, skating ratio, penetration and float of each foot",
        _skate_arguments,
        _skate,
        description=(
            "Measure how much a take's planted feet slide (mm from where each plant began), how often "
            "they skate (the motion-generation papers' ratio: a foot within 5 cm of the floor moving faster "
            "than 0.5 m/s, which a walk's swing does too, and the same over the steps in which a point is "
            "planted: 0 on the plants detected on the take itself, which hold no point that fast), how deep "
            "they go below the floor and how high planted points float. The plants are detected unless "
            "--contacts gives a table; the floor is fitted unless --floor gives its level. Prints a Markdown "
            "table, or JSON. To measure what a cleanup did, give both takes the same table: detection on the "
            "cleaned take finds other plants."
        ),
        epilog=(
            "Example: motiontheater skate 01_01.amc\n"
            "Example: motiontheater contacts 01_01.amc -o plants.csv && motiontheater cleanup 01_01.amc "
            "--contacts plants.csv -o clean.amc && motiontheater skate clean.amc --asf 01.asf --contacts plants.csv"
        ),
    ),
    Verb(
        "contacts",
        "detect the footplants of a take and write them as a CSV table to read and edit",
        _contacts_arguments,
        _contacts,
        description=(
            "Detect when each foot's heel and ball stand on the floor (height above rest and speed, "
            "with hysteresis) and write the table: one row per plant, foot,point,first,last (frame "
            "numbers, both included). Edit it (delete a row, add one) and give it back to cleanup "
            "with --contacts."
        ),
        epilog="Example: motiontheater contacts 01_01.amc -o plants.csv",
    ),
]
