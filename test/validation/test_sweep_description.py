#!/usr/bin/python3
"""sweep_description.py: a variant's value reaches the generated URDF that sbot_validate runs on, a
variant that changes no generated file is named and not run, and a path that names nothing in the
parameter table is refused by name before anything runs."""
import os
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
TOOL = os.path.join(ROOT, "src", "validation", "sweep_description.py")


def sweep(*args):
    return subprocess.run(["/usr/bin/python3", TOOL] + list(args), capture_output=True, text=True)


class SweepDescription(unittest.TestCase):
    def test_a_grid_value_reaches_the_model_and_the_report(self):
        keep = tempfile.mkdtemp(prefix="sweep_test_")
        r = sweep("--grid", "levels.detailed.turret.com_m[0]=0.031,0.049", "--only", "4.2", "--trials", "1",
                  "--keep", keep)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("2 variant(s)", r.stdout)
        self.assertRegex(r.stdout, r"com_m\[0\]=0.031: hardware \d+/3")
        for n, x in ((0, "0.031"), (1, "0.049")):
            with open(os.path.join(keep, "variant_%03d" % n, "urdf", "detailed.urdf"), encoding="utf-8") as fh:
                urdf = fh.read()
            turret = urdf[urdf.index('<link name="turret">'):]
            self.assertRegex(turret[:400], r'<origin xyz="%s 0 ' % re.escape(x))
            # Medium shares the table's calibrated turret COM with Detailed (a YAML alias): the
            # path names Detailed's only.
            with open(os.path.join(keep, "variant_%03d" % n, "urdf", "medium.urdf"), encoding="utf-8") as fh:
                medium = fh.read()
            medium_turret = medium[medium.index('<link name="turret">'):]
            self.assertRegex(medium_turret[:400], r'<origin xyz="0.03 0 ')
            self.assertTrue(os.path.exists(os.path.join(keep, "variant_%03d" % n, "report", "report.md")))

    def test_a_variant_that_changes_no_generated_file_is_named_and_not_run(self):
        # Entries under `shared:` reach the levels through YAML aliases and merge keys at load time:
        # setting one afterwards changes no level (a sweep over one would run identical models).
        keep = tempfile.mkdtemp(prefix="sweep_test_")
        r = sweep("--grid", "shared.treels_api.creep_stiffness=3.0,5.6", "--only", "4.2", "--trials", "1",
                  "--keep", keep)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertRegex(r.stdout, r"creep_stiffness=3.0: changes nothing in the generated descriptions, not run")
        self.assertIn("levels.medium.treels.creep_stiffness", r.stdout, "says which path to set instead")
        self.assertFalse(os.path.exists(os.path.join(keep, "variant_000", "report")))
        # 5.6 is the table's own value: the reference point of the grid, run as any other.
        self.assertRegex(r.stdout, r"creep_stiffness=5.6: hardware \d+/3")

    def test_a_sweep_runs_against_another_labs_tables(self):
        # --tables: the variants (here the Medium's front and rear sphere radius) are validated
        # against your own reference tables, and each line tallies that file's group.
        d = tempfile.mkdtemp(prefix="sweep_test_")
        tables = os.path.join(d, "lab.yaml")
        with open(tables, "w", encoding="utf-8") as fh:
            fh.write("groups:\n  - {name: lab, title: Lab cells, required: true}\nreport:\n  - table:\n"
                     "      id: lab1\n      title: Gaps\n      group: lab\n      experiment: gap\n"
                     "      level: medium\n      param: {unit: cm, scale: 100, decimals: 1}\n"
                     "      references: [measured]\n      cells:\n        - {param: 0.030, measured: pass}\n")
        r = sweep("--grid", "levels.medium.wheels.front_rear.radius_m=0.020,0.018", "--tables", tables, "--trials", "1")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("sections all of " + tables, r.stdout)
        self.assertRegex(r.stdout, r"radius_m=0.02: Lab cells \d/1")
        self.assertRegex(r.stdout, r"radius_m=0.018: Lab cells \d/1")
        self.assertNotIn("hardware", r.stdout, "the seed's tables did not run")
        r = sweep("--grid", "levels.medium.wheels.front_rear.radius_m=0.020", "--tables", os.path.join(d, "none.yaml"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("none.yaml is not a file", r.stderr)

    def test_a_misspelt_path_is_refused_by_name(self):
        r = sweep("--grid", "levels.medium.turet.com_m[0]=0.03")
        self.assertEqual(r.returncode, 2)
        self.assertIn("'turet' is not in the table", r.stderr)
        self.assertIn("turret", r.stderr, "lists the keys that exist")
        r = sweep("--set", "levels.medium.turret.com_m[9]=0.03")
        self.assertEqual(r.returncode, 2)
        self.assertIn("element [9] does not exist", r.stderr)

    def test_a_random_sample_draws_each_path_within_its_range_repeatably(self):
        args = ("--sample", "2", "--seed", "7", "--range", "levels.detailed.turret.com_m[0]=0.031:0.032",
                "--only", "4.2", "--trials", "1")
        keep = tempfile.mkdtemp(prefix="sweep_test_")
        r = sweep(*(args + ("--keep", keep)))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("2 variant(s)", r.stdout)
        drawn = [float(x) for x in re.findall(r"com_m\[0\]=([0-9.]+): hardware \d+/3", r.stdout)]
        self.assertEqual(len(drawn), 2, r.stdout)
        for n, x in enumerate(drawn):
            self.assertTrue(0.031 <= x <= 0.032, "drawn %g outside the range" % x)
            with open(os.path.join(keep, "variant_%03d" % n, "urdf", "detailed.urdf"), encoding="utf-8") as fh:
                urdf = fh.read()
            turret = urdf[urdf.index('<link name="turret">'):]
            self.assertRegex(turret[:400], r'<origin xyz="%s 0 ' % re.escape("%g" % x))
        self.assertNotEqual(drawn[0], drawn[1])
        self.assertIn("best variants", r.stdout)
        # The same seed draws the same variants.
        again = [float(x) for x in re.findall(r"com_m\[0\]=([0-9.]+):", sweep(*args).stdout)]
        self.assertEqual(again, drawn)

    def test_a_malformed_sample_is_refused_by_name(self):
        r = sweep("--sample", "3", "--range", "levels.detailed.turret.com_m[0]=0.05:0.01")
        self.assertEqual(r.returncode, 2)
        self.assertIn("expected LO < HI", r.stderr)
        r = sweep("--sample", "3", "--range", "levels.detailed.turret.com_m[0]=0.01")
        self.assertEqual(r.returncode, 2)
        self.assertIn("PATH=LO:HI", r.stderr)
        r = sweep("--sample", "3")
        self.assertEqual(r.returncode, 2)
        self.assertIn("go together", r.stderr)
        r = sweep("--sample", "3", "--range", "levels.detailed.turet.com_m[0]=0.01:0.02")
        self.assertEqual(r.returncode, 2)
        self.assertIn("'turet' is not in the table", r.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
