"""The pattern study of docs/pattern-study.md: the least adhesion of every brick stage of
the steep courses of a dome, with and without the herringbone, in both laying orders.

Each (profile, pattern, order, course) is one ``masonry stages`` command, run unless
the ledger (``OUT/pattern_study.json``) already holds its folder: the study resumes
where it stopped, and a profile or course added later runs only what is new. Then
``pattern_study.csv`` (one row per command: the course's largest ``adhesion_kPa`` over
its stages and how many stages need adhesion, read from the folder's ``stages.csv``) and
``pattern_study.png`` (that largest value course by course, one panel per profile):

    python examples/pattern_study.py --out exports/pattern-study
    python examples/pattern_study.py --out exports/pattern-study --profiles preset1 \\
        --courses 44-62 --orders pattern-first --mu 0.5

``--profile NAME=ARGS`` adds a profile of one's own (``ARGS`` as ``masonry stages``
takes them, with ``--courses``); ``--dry-run`` prints the commands it would run.
"""

import argparse
import csv
import json
import shlex
import subprocess
import sys
from pathlib import Path

SECTOR = "--scene sector --boundary cyclic --radius 53.1127 --p 10 --cut 0.1"
PROFILES = {
    "preset1": ("--preset 1", (36, 62)),
    "hemisphere": ("--scene section --n 8 --r 1 --p 10 --cut 0.1 --stretch 0.92388",
                   (33, 57)),
    "preset1-revolution": (f"{SECTOR} --stretch 1.082392", (36, 62)),
    "hemisphere-revolution": (f"{SECTOR} --stretch 1", (33, 57)),
}
"""The four profiles of docs/revolution.md (their ``masonry stages`` arguments) and the
courses whose beds are steeper than about 35 degrees (atan 0.7), where a brick alone
needs adhesion."""

TITLES = {"preset1": "preset 1, polygonal", "hemisphere": "hemisphere, polygonal",
          "preset1-revolution": "preset 1, of revolution",
          "hemisphere-revolution": "hemisphere, of revolution"}
"""The figure's panel titles (a profile of one's own is titled by its name)."""

PATTERNS = ("herringbone", "none")
ORDERS = ("pattern-first", "along")
COLUMNS = ("profile", "pattern", "order", "mu", "course", "adhesion_max_kPa",
           "stages", "needing", "folder")


def parse(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="the study's folder")
    parser.add_argument("--profiles", nargs="+",
                        help=f"profiles to run (default all of {', '.join(PROFILES)}, "
                             "none with --profile)")
    parser.add_argument("--profile", action="append", default=[], metavar="NAME=ARGS",
                        help="a profile of one's own: masonry stages' model arguments")
    parser.add_argument("--courses", metavar="A-B",
                        help="the courses to lay (default each profile's steep ones)")
    parser.add_argument("--orders", nargs="+", default=list(ORDERS), choices=ORDERS)
    parser.add_argument("--patterns", nargs="+", default=list(PATTERNS), choices=PATTERNS)
    parser.add_argument("--mu", type=float, default=0.7, help="friction (default 0.7)")
    parser.add_argument("--dry-run", action="store_true", help="print the commands only")
    args = parser.parse_args(argv)
    if args.profiles is None:
        args.profiles = [] if args.profile else list(PROFILES)
    profiles = {name: PROFILES[name] for name in args.profiles if name in PROFILES}
    for given in args.profile:
        name, _, line = given.partition("=")
        profiles[name] = (line, None)
    unknown = [name for name in args.profiles if name not in PROFILES]
    if unknown or not profiles:
        parser.error(f"--profiles {' '.join(unknown)}: expected names of {', '.join(PROFILES)}"
                     " or a --profile NAME=ARGS")
    args.courses = _courses(parser, args.courses)
    if any(span is None for _, span in profiles.values()) and args.courses is None:
        parser.error("--profile NAME=ARGS needs --courses A-B")
    args.profiles = profiles
    return args


def _courses(parser, text):
    if text is None:
        return None
    first, _, last = text.partition("-")
    try:
        span = int(first), int(last or first)
    except ValueError:
        span = None
    if span is None or not 1 <= span[0] <= span[1]:
        parser.error(f"--courses {text}: expected A-B, two course numbers 1 <= A <= B")
    return span


def commands(args) -> list:
    """``(key, argv)`` of every command of the study, the key naming it in the ledger."""
    out = []
    for name, (line, span) in args.profiles.items():
        first, last = args.courses or span
        for pattern in args.patterns:
            # a plain dome has no pattern bricks to lay first: one order
            for order in (args.orders if pattern == "herringbone" else args.orders[:1]):
                for course in range(first, last + 1):
                    argv = ["masonry", "stages", *shlex.split(line), "--pattern", pattern,
                            "--mu", f"{args.mu:g}", "--by", "brick", "--course",
                            str(course), "--order", order, "--no-plots", "--out",
                            str(args.out / "runs"), "-q"]
                    key = (name, pattern, order, f"{args.mu:g}", course)
                    out.append(("|".join(map(str, key)), argv))
    return out


def run(args) -> int:
    ledger_path = args.out / "pattern_study.json"
    ledger = json.loads(ledger_path.read_text()) if ledger_path.exists() else {}
    every = commands(args)
    todo = [(key, argv) for key, argv in every
            if key not in ledger or not Path(ledger[key]).is_dir()]
    print(f"{len(every) - len(todo)} done, {len(todo)} to run", flush=True)
    for number, (key, argv) in enumerate(todo, 1):
        print(f"[{number}/{len(todo)}] {shlex.join(argv)}", flush=True)
        if args.dry_run:
            continue
        # masonry's own interpreter runs it, as the command line would
        done = subprocess.run([sys.executable, "-m", "masonry_cli.main", *argv[1:]],
                              capture_output=True, text=True, check=False)
        written = [line.split("written: ", 1)[1] for line in done.stdout.splitlines()
                   if line.startswith("written: ")]
        if done.returncode != 0 or not written:
            print(done.stdout + done.stderr, file=sys.stderr)
            return done.returncode or 1
        ledger[key] = written[-1]
        args.out.mkdir(parents=True, exist_ok=True)
        ledger_path.write_text(json.dumps(ledger, indent=1))
    if not args.dry_run:
        rows = table(ledger)
        write(rows, args.out)
    return 0


def table(ledger) -> list:
    """One row per ledger entry (:data:`COLUMNS`), from its folder's ``stages.csv``."""
    rows = []
    for key, folder in sorted(ledger.items()):
        profile, pattern, order, mu, course = key.split("|")
        with open(Path(folder) / "stages.csv", newline="") as handle:
            stages = list(csv.DictReader(handle))
        values = [float(s["adhesion_kPa"]) for s in stages if s["adhesion_kPa"] != ""]
        rows.append({"profile": profile, "pattern": pattern, "order": order,
                     "mu": float(mu), "course": int(course),
                     "adhesion_max_kPa": max(values) if len(values) == len(stages) else None,
                     "stages": len(stages), "needing": sum(v > 0 for v in values),
                     "folder": folder})
    return sorted(rows, key=lambda r: (r["profile"], r["mu"], r["pattern"], r["order"],
                                       r["course"]))


def write(rows, out: Path) -> None:
    """``pattern_study.csv`` and ``pattern_study.png`` in ``out``."""
    with open(out / "pattern_study.csv", "w", newline="") as handle:
        writer = csv.DictWriter(handle, COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    named = {r["profile"] for r in rows}
    profiles = [name for name in PROFILES if name in named] + sorted(named - set(PROFILES))
    figure, axes = plt.subplots(1, len(profiles), figsize=(4.2 * len(profiles), 3.6),
                                sharey=True, squeeze=False)
    styles = {("herringbone", "pattern-first"): ("tab:red", "-o", "herringbone, pattern-first"),
              ("herringbone", "along"): ("tab:red", ":x", "herringbone, along the course"),
              ("none", "pattern-first"): ("0.35", "-s", "plain (running bond)"),
              ("none", "along"): ("0.35", "-s", "plain (running bond)")}
    for axis, profile in zip(axes[0], profiles):
        for mu in sorted({r["mu"] for r in rows if r["profile"] == profile}):
            for (pattern, order), (colour, line, label) in styles.items():
                picked = [r for r in rows if (r["profile"], r["mu"], r["pattern"],
                                              r["order"]) == (profile, mu, pattern, order)]
                if picked:
                    axis.plot(*_gapped(picked), line, color=colour, markersize=3,
                              label=f"{label}, mu {mu:g}")
        axis.set_title(TITLES.get(profile, profile))
        axis.set_xlabel("course laid brick by brick")
        axis.xaxis.set_major_locator(MaxNLocator(integer=True))
        axis.grid(alpha=0.3)
    axes[0][0].set_ylabel("least adhesion over the course's stages, kPa")
    axes[0][-1].legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(out / "pattern_study.png", dpi=150)
    plt.close(figure)


def _gapped(rows) -> tuple:
    """Courses and values, with a break (NaN) where courses were skipped: a line joins
    consecutive courses only."""
    courses, values = [], []
    for row in rows:
        if courses and row["course"] > courses[-1] + 1:
            courses.append(courses[-1] + 0.5)
            values.append(float("nan"))
        courses.append(row["course"])
        values.append(float("nan") if row["adhesion_max_kPa"] is None
                      else row["adhesion_max_kPa"])
    return courses, values


def main(argv=None) -> int:
    return run(parse(sys.argv[1:] if argv is None else argv))


if __name__ == "__main__":
    sys.exit(main())
