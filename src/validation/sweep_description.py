#!/usr/bin/python3
"""Run validation sections on variants of the s-bot parameter table (a tuning aid).

    sweep_description.py [--set PATH=VALUE ...] [--grid PATH=V1,V2,... ...]
                         [--sample N --range PATH=LO:HI ... [--seed S]]
                         [--only 4.1,4.2,4.3] [--trials 3] [--keep DIR] [--tables YAML]

Each variant is the table (sbot_description/config/sbot_parameters.yaml) with the --set values and
one combination of the --grid values applied. With --sample N there are N variants instead, each
drawing every --range PATH uniformly from [LO, HI] (a random search over many parameters, where a
grid would be too large; --seed makes the draw repeatable), and the best variants are listed at the
end by the cells they match. Its URDFs and sidecars are generated into a directory
of their own, and `sbot_validate` runs the sections on them through $SBOT_DESCRIPTION_DIR, so the
source tree is never touched. One line per variant: the cells matched per group and the mismatched
cells. --tables runs your own reference tables (sbot_validate --tables; docs/validation.md)
instead of the seed's, all of their sections unless --only names some: a parameter swept against
your own measurements.

PATH is a dotted path into the table, with [i] for list elements, e.g.
  --grid 'levels.detailed.turret.com_m[0]=0.030,0.035,0.040'
  --grid 'levels.medium.treels.creep_stiffness=3.0,5.6'       (Detailed inherits Medium's treels)
VALUE is YAML: 0.03, [0.03, 0, 0.011], true, text. A path names one place: the table is copied
without its YAML aliases first. A variant whose generated files equal the table's own is named and
not run (e.g. a path under `shared:`, which the levels copy when the table loads).

Runs $SBOT_VALIDATE if set, else this tree's build/ws/devel/lib/swarmbot3d/sbot_validate, else
`rosrun swarmbot3d sbot_validate`. Needs /usr/bin/python3 with PyYAML.
"""
import argparse
import filecmp
import itertools
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

import yaml

HERE = os.path.dirname(os.path.realpath(__file__))  # the source tree, also when run through the workspace links
ROOT = os.path.dirname(os.path.dirname(HERE))
DESCRIPTION = os.path.join(ROOT, "sbot_description")
TABLE = os.path.join(DESCRIPTION, "config", "sbot_parameters.yaml")
GENERATOR = os.path.join(DESCRIPTION, "scripts", "generate_urdf.py")

_STEP = re.compile(r"([^.\[\]]+)|\[(\d+)\]")

# A variant whose URDFs and sidecars come out byte for byte as the table's own. Typically a path
# under `shared:`: the levels read those entries through YAML aliases (`*name`) and merge keys
# (`<<: *name`) when the table loads, so the copies the levels hold do not follow a later change.
NO_CHANGE = ("changes nothing in the generated descriptions, not run (an entry under 'shared:' reaches "
             "the levels only through YAML aliases and merge keys when the table loads: set the level's own "
             "path, e.g. levels.medium.treels.creep_stiffness, which Detailed inherits)")


def path_steps(path):
    """'levels.medium.turret.com_m[0]' -> ['levels', 'medium', 'turret', 'com_m', 0]."""
    steps, pos = [], 0
    for m in _STEP.finditer(path):
        if m.start() != pos and path[pos:m.start()] != ".":
            raise ValueError("cannot read path '%s' at '%s'" % (path, path[pos:]))
        steps.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if not steps or pos != len(path):
        raise ValueError("cannot read path '%s'" % path)
    return steps


def unshared(node):
    """A copy in which no two places share a list or mapping. YAML aliases (`*turret_api`, the
    turret COM the levels share) load as one Python object, so setting one level's value would set
    every level's; a PATH names one place in the table."""
    if isinstance(node, dict):
        return {k: unshared(v) for k, v in node.items()}
    if isinstance(node, list):
        return [unshared(v) for v in node]
    return node


def set_value(table, path, value):
    """Replace an existing entry; a path that names nothing in the table is an error (typos)."""
    node = table
    steps = path_steps(path)
    for i, step in enumerate(steps):
        last = i == len(steps) - 1
        if isinstance(step, int):
            if not isinstance(node, list) or step >= len(node):
                raise ValueError("%s: element [%d] does not exist" % (path, step))
        elif not isinstance(node, dict) or step not in node:
            known = ", ".join(sorted(node)) if isinstance(node, dict) else "(not a mapping)"
            raise ValueError("%s: '%s' is not in the table here; known: %s" % (path, step, known))
        if last:
            node[step] = value
        else:
            node = node[step]


def parse_assignment(text, many):
    if "=" not in text:
        raise ValueError("expected PATH=VALUE, found '%s'" % text)
    path, value = text.split("=", 1)
    values = [yaml.safe_load(v) for v in value.split(",")] if many else [yaml.safe_load(value)]
    path_steps(path)  # refuse a malformed path before anything runs
    return path.strip(), values


# The seed's groups by their short names; another tables file's groups go by their titles.
SHORT_NAMES = {"Hardware cells of Tables 4.1-4.3": "hardware", "Table 4.5 cells": "4.5", "Table 4.6 cells": "4.6"}


def parse_range(text):
    """'PATH=LO:HI' -> (PATH, (LO, HI)), refused unless LO < HI are numbers."""
    if "=" not in text or ":" not in text.split("=", 1)[1]:
        raise ValueError("--range expects PATH=LO:HI, found '%s'" % text)
    path, bounds = text.split("=", 1)
    try:
        lo, hi = (float(b) for b in bounds.split(":"))
    except ValueError:
        raise ValueError("--range %s: LO and HI must be numbers, found '%s'" % (path, bounds))
    if not lo < hi:
        raise ValueError("--range %s: expected LO < HI, found %g:%g" % (path, lo, hi))
    path_steps(path)
    return path.strip(), (lo, hi)


def matched_cells(tally):
    """'hardware 14/16, 4.5 20/28' -> 34 (for ranking variants); 0 for an error message."""
    return sum(int(n) for n in re.findall(r" (\d+)/\d+", tally))


def summary(report_md):
    """'hardware 12/16, 4.5 21/28, ...' (every group the report tallies) and its mismatched rows."""
    with open(report_md, encoding="utf-8") as fh:
        text = fh.read()
    # A tally may end in "(N cells of this tally not run: --only)"; one that ran none is left out.
    counts = re.findall(r"^- (.+) matched: (\d+/\d+)(?: \(.*\))?$", text, re.M)
    tally = ", ".join("%s %s" % (SHORT_NAMES.get(n, n), c) for n, c in counts if not c.endswith("/0"))
    missed = [" | ".join(c.strip() for c in row.strip().strip("|").split("|") if "mismatch" not in c)
              for row in text.splitlines() if row.startswith("| ") and "**mismatch**" in row]
    return tally, missed


def validate_command():
    """$SBOT_VALIDATE, else this tree's build (./sbot.sh build), else rosrun."""
    if os.environ.get("SBOT_VALIDATE"):
        return [os.environ["SBOT_VALIDATE"]]
    local = os.path.join(ROOT, "build", "ws", "devel", "lib", "swarmbot3d", "sbot_validate")
    return [local] if os.access(local, os.X_OK) else ["rosrun", "swarmbot3d", "sbot_validate"]


def generate(table, workdir):
    """The URDFs and sidecars of `table` in workdir/urdf; an error message, or None."""
    os.makedirs(os.path.join(workdir, "urdf"))
    shutil.copytree(os.path.join(DESCRIPTION, "config"), os.path.join(workdir, "config"))
    params = os.path.join(workdir, "params.yaml")
    with open(params, "w", encoding="utf-8") as fh:
        yaml.safe_dump(table, fh, sort_keys=False)
    gen = subprocess.run(["/usr/bin/python3", GENERATOR, "--out", os.path.join(workdir, "urdf"), "--params", params,
                          "--quiet"], capture_output=True, text=True)
    if gen.returncode != 0:
        return "generator failed: " + (gen.stderr.strip().splitlines() or ["?"])[-1]
    return None


def same_files(dir_a, dir_b):
    """Whether two directories hold the same files with the same bytes."""
    names = sorted(os.listdir(dir_a))
    if names != sorted(os.listdir(dir_b)):
        return False
    return all(filecmp.cmp(os.path.join(dir_a, n), os.path.join(dir_b, n), shallow=False) for n in names)


def run_variant(table, only, trials, workdir, baseline_urdf=None, tables=None):
    """Generate and validate one variant: (tally, mismatched rows). A variant whose generated files
    equal `baseline_urdf`'s changes nothing the simulator reads and is not run."""
    error = generate(table, workdir)
    if error:
        return error, []
    if baseline_urdf and same_files(os.path.join(workdir, "urdf"), baseline_urdf):
        return NO_CHANGE, []
    env = dict(os.environ, SBOT_DESCRIPTION_DIR=workdir)
    out = os.path.join(workdir, "report")
    args = ["--out", out, "--trials", str(trials)] + (["--only", only] if only else [])
    args += ["--tables", tables] if tables else []
    val = subprocess.run(validate_command() + args, env=env, capture_output=True, text=True)
    report = os.path.join(out, "report.md")
    if not os.path.exists(report):
        return "sbot_validate failed (status %d): %s" % (val.returncode, val.stderr.strip()[-300:]), []
    return summary(report)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--set", action="append", default=[], metavar="PATH=VALUE")
    ap.add_argument("--grid", action="append", default=[], metavar="PATH=V1,V2,...")
    ap.add_argument("--range", action="append", default=[], metavar="PATH=LO:HI")
    ap.add_argument("--sample", type=int, default=0, metavar="N", help="N random variants over the --range paths")
    ap.add_argument("--seed", type=int, default=1, help="seed of the --sample draw (default 1)")
    ap.add_argument("--only", help="sbot_validate sections (default 4.1,4.2,4.3; with --tables: all)")
    ap.add_argument("--tables", help="reference tables for sbot_validate (default: the seed's)")
    ap.add_argument("--trials", type=int, default=3, help="trials per cell (default 3)")
    ap.add_argument("--keep", help="keep every variant's files (params, URDFs, report) under this directory")
    a = ap.parse_args()
    if a.trials < 1:
        ap.error("--trials expects a whole number >= 1, found %d" % a.trials)
    if bool(a.sample) != bool(a.range) or a.sample < 0:
        ap.error("--sample N (N >= 1) and --range PATH=LO:HI go together, found --sample %d with %d range(s)"
                 % (a.sample, len(a.range)))
    if a.sample and a.grid:
        ap.error("--grid and --sample are two ways of choosing variants: give one")
    if a.tables:
        if not os.path.isfile(a.tables):
            ap.error("--tables: %s is not a file" % a.tables)
        a.tables = os.path.abspath(a.tables)  # sbot_validate runs elsewhere
    elif a.only is None:
        a.only = "4.1,4.2,4.3"
    try:
        fixed = [parse_assignment(s, False) for s in a.set]
        grid = [parse_assignment(g, True) for g in a.grid]
        ranges = [parse_range(r) for r in a.range]
        with open(TABLE, encoding="utf-8") as fh:
            own = unshared(yaml.safe_load(fh))  # the table as it is, to tell variants that change nothing
        base = unshared(own)
        for path, (value,) in fixed:
            set_value(base, path, value)
        # Validate every grid path once before running anything.
        for path, values in grid + [(p, [lo]) for p, (lo, _) in ranges]:
            set_value(unshared(base), path, values[0])
    except (OSError, ValueError, yaml.YAMLError) as e:
        print("sweep_description: %s" % e, file=sys.stderr)
        return 2
    root = a.keep or tempfile.mkdtemp(prefix="sbot_sweep_")
    os.makedirs(root, exist_ok=True)
    # The table's own descriptions, to tell a variant that changes nothing (see NO_CHANGE). A variant
    # that sets the table's own values (a grid's reference point) is run as any other.
    baseline = os.path.join(root, "baseline")
    error = generate(own, baseline)
    if error:
        print("sweep_description: the table itself: %s" % error, file=sys.stderr)
        return 2
    if ranges:
        rng = random.Random(a.seed)
        grid = [(path, None) for path, _ in ranges]
        combos = [tuple(round(rng.uniform(lo, hi), 6) for _, (lo, hi) in ranges) for _ in range(a.sample)]
    else:
        combos = list(itertools.product(*[values for _, values in grid])) or [()]
    ranked = []
    print("%d variant(s); sections %s%s, %d trial(s) per cell; files in %s"
          % (len(combos), a.only or "all", " of " + a.tables if a.tables else "", a.trials, root))
    for n, combo in enumerate(combos):
        table = unshared(base)
        label = ", ".join("%s=%s" % (path, v) for (path, _), v in zip(grid, combo)) or "table as set"
        for (path, _), v in zip(grid, combo):
            set_value(table, path, v)
        tally, missed = run_variant(table, a.only, a.trials, os.path.join(root, "variant_%03d" % n),
                                    os.path.join(baseline, "urdf") if table != own else None, a.tables)
        print("%s: %s" % (label, tally))
        ranked.append((matched_cells(tally), n, label, tally))
        for m in missed:
            print("    mismatch: %s" % m)
        sys.stdout.flush()
    if ranges:
        print("best variants (cells matched, variant):")
        for cells, n, label, tally in sorted(ranked, key=lambda r: (-r[0], r[1]))[:5]:
            print("  %s  variant_%03d: %s" % (tally, n, label))
    if not a.keep:
        shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
