#!/usr/bin/python3
"""The rosbag importer: a generated dataset is written as a bag (simulator topics and message types,
an overhead tracker as geometry_msgs/PoseStamped), imported back with bag_to_dataset.py and loaded by
sbot_calibrate; commands and measurements must survive the trip. Usage: test_bag_importer.py SBOT_CALIBRATE
"""
import contextlib
import csv
import io
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import genpy
import genpy.dynamic
import rosbag
import rospy
import yaml

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "src", "calibration"))
import bag_to_dataset  # noqa: E402

SEP = "\n" + "=" * 80 + "\n"
HEADER = "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"


def msg_class(name, text, deps=""):
    return genpy.dynamic.generate_dynamic(name, text + deps)[name]


def sbot_msg(name):
    with open(os.path.join(ROOT, "sbot_msgs", "msg", name + ".msg")) as f:
        text = f.read()
    return msg_class("sbot_msgs/" + name, text, SEP + HEADER if "Header" in text else "")


PoseStamped = msg_class(
    "geometry_msgs/PoseStamped", "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
    SEP + HEADER + SEP + "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n"
    + SEP + "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"
    + SEP + "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n")
TrackSpeed = sbot_msg("TrackSpeed")
TrackState = sbot_msg("TrackState")
Slope = sbot_msg("Slope")


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


class BagImporterTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tool = sys.argv[1] if len(sys.argv) > 1 else "sbot_calibrate"
        cls.tmp = tempfile.mkdtemp(prefix="sbot_bag_importer_")
        subprocess.check_call([cls.tool, "generate", "--out", os.path.join(cls.tmp, "src"), "--seed", "4",
                               "--duration", "3", "--families", "straight,spin", "--torque", "--jobs", "1"],
                              stdout=subprocess.DEVNULL)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def write_bag(self, run, path, with_commands=True, tracker_lead=0.0, nan_pose_at=None):
        rows = read_csv(os.path.join(self.tmp, "src", run + ".csv"))
        base = 1000.0
        with rosbag.Bag(path, "w") as bag:
            for r in rows:
                t = rospy.Time.from_sec(base + float(r["t"]))
                if r["cmd_left"] != "" and with_commands:
                    bag.write("/sbot_0/cmd_speed", TrackSpeed(left=int(float(r["cmd_left"])),
                                                               right=int(float(r["cmd_right"]))), t)
                if r["x"] != "":
                    m = PoseStamped()
                    m.header.stamp = rospy.Time.from_sec(base + float(r["t"]) - tracker_lead)
                    m.pose.position.x, m.pose.position.y = float(r["x"]), float(r["y"])
                    if nan_pose_at is not None and abs(float(r["t"]) - nan_pose_at) < 1e-6:
                        m.pose.position.x = float("nan")
                    yaw = float(r["yaw"])
                    m.pose.orientation.z, m.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
                    bag.write("/tracker/sbot_0", m, t)
                if r["speed_left"] != "":
                    m = TrackState()
                    m.header.stamp = t
                    m.measured_left, m.measured_right = int(float(r["speed_left"])), int(float(r["speed_right"]))
                    m.torque_left, m.torque_right = int(float(r["torque_left"])), int(float(r["torque_right"]))
                    bag.write("/sbot_0/track_state", m, t)
                if r["pitch"] != "":
                    m = Slope()
                    m.header.stamp = t
                    m.pitch, m.roll = int(round(math.degrees(float(r["pitch"])))), int(round(math.degrees(float(r["roll"]))))
                    bag.write("/sbot_0/slope", m, t)
        return rows

    def test_round_trip(self):
        bags = []
        originals = {}
        for run in ("straight_40", "spin_cw_30"):
            path = os.path.join(self.tmp, run + ".bag")
            originals[run] = self.write_bag(run, path)
            bags.append(path)
        out = os.path.join(self.tmp, "imported")
        self.assertEqual(bag_to_dataset.main([out] + bags + ["--tracker-topic", "/tracker/sbot_0", "--level", "simple"]), 0)
        for run, rows in originals.items():
            imported = read_csv(os.path.join(out, run + ".csv"))
            orig_pose = [(float(r["t"]), float(r["x"]), float(r["yaw"])) for r in rows if r["x"] != ""]
            imp_pose = [(float(r["t"]), float(r["x"]), float(r["yaw"])) for r in imported if r["x"] != ""]
            self.assertEqual(len(orig_pose), len(imp_pose), run)
            for (ta, xa, ya), (tb, xb, yb) in zip(orig_pose, imp_pose):
                self.assertAlmostEqual(ta, tb, places=5)  # both relative to the first message (a command at 0)
                self.assertAlmostEqual(xa, xb, places=7)
                self.assertAlmostEqual(math.remainder(ya - yb, 2 * math.pi), 0.0, places=7)
            cmds_a = [(r["cmd_left"], r["cmd_right"]) for r in rows if r["cmd_left"] != ""]
            cmds_b = [(r["cmd_left"], r["cmd_right"]) for r in imported if r["cmd_left"] != ""]
            self.assertEqual([tuple(float(v) for v in c) for c in cmds_a], [tuple(float(v) for v in c) for c in cmds_b])
            self.assertIn("torque_left", imported[0])
        # The C++ tool loads and replays the imported dataset.
        res = subprocess.run([self.tool, "compare", out, "--no-plots", "--out", os.path.join(self.tmp, "report"),
                              "--jobs", "1"], capture_output=True, text=True)
        self.assertEqual(res.returncode, 0, res.stderr)
        self.assertIn("nominal", res.stdout)

    def test_times_start_at_the_earliest_stamp(self):
        # A tracker on another clock stamps its poses 0.5 s ahead of the commands, which are read first:
        # times relative to the first message read were negative and crashed the replay.
        path = os.path.join(self.tmp, "lead.bag")
        original = self.write_bag("straight_20", path, tracker_lead=0.5)
        first_pose_t = next(float(r["t"]) for r in original if r["x"] != "")
        out = os.path.join(self.tmp, "lead")
        self.assertEqual(bag_to_dataset.main([out, path, "--tracker-topic", "/tracker/sbot_0", "--level", "simple"]), 0)
        rows = read_csv(os.path.join(out, "lead.csv"))
        self.assertAlmostEqual(float(rows[0]["t"]), 0.0, places=6)
        self.assertNotEqual(rows[0]["x"], "", "the earliest row is the tracker's")
        first_cmd = next(float(r["t"]) for r in rows if r["cmd_left"] != "")
        self.assertAlmostEqual(first_cmd, 0.5 - first_pose_t, places=5)
        res = subprocess.run([self.tool, "compare", out, "--no-plots", "--out", os.path.join(self.tmp, "lead_report"),
                              "--jobs", "1"], capture_output=True, text=True)
        self.assertEqual(res.returncode, 0, res.stderr)

    def test_bag_without_commands_is_refused(self):
        path = os.path.join(self.tmp, "nocmd.bag")
        self.write_bag("straight_20", path, with_commands=False)
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([os.path.join(self.tmp, "bad"), path, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("command", str(e.exception))

    def test_a_failed_append_leaves_the_dataset_as_it_was(self):
        # An append that fails half-way (a full disk) must not leave dataset.yaml truncated, losing
        # the index of the runs already there, nor a CSV without its entry.
        first = os.path.join(self.tmp, "first.bag")
        self.write_bag("straight_20", first)
        out = os.path.join(self.tmp, "appended")
        self.assertEqual(bag_to_dataset.main([out, first, "--tracker-topic", "/tracker/sbot_0"]), 0)
        with open(os.path.join(out, "dataset.yaml")) as f:
            before = f.read()
        second = os.path.join(self.tmp, "second.bag")
        self.write_bag("straight_20", second)
        nocmd = os.path.join(self.tmp, "third_nocmd.bag")
        self.write_bag("straight_20", nocmd, with_commands=False)
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, second, nocmd, "--append", "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("third_nocmd.csv: no command messages", str(e.exception))
        with open(os.path.join(out, "dataset.yaml")) as f:
            self.assertEqual(f.read(), before)
        self.assertEqual(sorted(os.listdir(out)), ["dataset.yaml", "first.csv"], "a file of the failed append is left")

    def test_a_pose_that_is_not_finite_is_refused(self):
        path = os.path.join(self.tmp, "nan.bag")
        rows = read_csv(os.path.join(self.tmp, "src", "straight_20.csv"))
        self.write_bag("straight_20", path, nan_pose_at=float(next(r["t"] for r in rows[3:] if r["x"] != "")))
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([os.path.join(self.tmp, "nan_out"), path, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("tracker topic /tracker/sbot_0: message at t = ", str(e.exception))
        self.assertIn("not finite (nan", str(e.exception))
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "nan_out")))

    def test_a_topic_of_the_wrong_type_is_named(self):
        path = os.path.join(self.tmp, "wrongtype.bag")
        self.write_bag("straight_20", path)
        with self.assertRaises(SystemExit) as e:  # the tracker's PoseStamped given as the command topic
            bag_to_dataset.main([os.path.join(self.tmp, "wt_out"), path, "--commands-topic", "/tracker/sbot_0"])
        self.assertIn("topic /tracker/sbot_0 has type geometry_msgs/PoseStamped, expected sbot_msgs/TrackSpeed",
                      str(e.exception))

    def test_an_append_onto_runs_that_are_not_runs_is_refused(self):
        out = os.path.join(self.tmp, "notruns")
        os.makedirs(out)
        with open(os.path.join(out, "dataset.yaml"), "w") as f:
            f.write("format: sbot-dataset/1\nruns: [1, 2]\n")
        path = os.path.join(self.tmp, "for_notruns.bag")
        self.write_bag("straight_20", path)
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, path, "--append", "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("runs[0] is not a run", str(e.exception))

    def test_unreadable_bag_is_named_and_nothing_is_written(self):
        good = os.path.join(self.tmp, "good.bag")
        self.write_bag("straight_20", good)
        corrupt = os.path.join(self.tmp, "corrupt.bag")
        with open(corrupt, "wb") as f:
            f.write(b"#ROSBAG V2.0\n" + bytes(range(256)) * 8)
        out = os.path.join(self.tmp, "partial")
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, good, corrupt, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("cannot read %s" % corrupt, str(e.exception))
        self.assertFalse(os.path.exists(out), "the good bag's CSV was written without a dataset.yaml")

    def test_an_output_place_that_cannot_be_made_is_named(self):
        good = os.path.join(self.tmp, "good_for_out.bag")
        self.write_bag("straight_20", good)
        plain = os.path.join(self.tmp, "plain_file")
        open(plain, "w").close()
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([os.path.join(plain, "dataset"), good, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("cannot create the dataset directory %s" % os.path.join(plain, "dataset"), str(e.exception))
        self.assertIn("Not a directory", str(e.exception))

    def test_a_world_file_that_cannot_be_read_is_named(self):
        good = os.path.join(self.tmp, "good_for_world.bag")
        self.write_bag("straight_20", good)
        out = os.path.join(self.tmp, "no_world")
        missing = os.path.join(self.tmp, "no_such_world.yaml")
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, good, "--world", missing, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("--world: cannot read %s: No such file or directory" % missing, str(e.exception))
        listed = os.path.join(self.tmp, "list_world.yaml")
        with open(listed, "w") as f:
            f.write("- plane\n")
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, good, "--world", listed, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("--world %s: expected the dataset's world mapping" % listed, str(e.exception))
        self.assertFalse(os.path.exists(out))

    def test_append_adds_runs_of_the_same_robot_and_world_only(self):
        # --append must not ignore --level, nor let --world replace the world of the runs already there.
        first = os.path.join(self.tmp, "append_first.bag")
        self.write_bag("straight_20", first)
        out = os.path.join(self.tmp, "appended")
        self.assertEqual(bag_to_dataset.main([out, first, "--tracker-topic", "/tracker/sbot_0", "--level", "simple"]), 0)
        second = os.path.join(self.tmp, "append_second.bag")
        self.write_bag("spin_cw_30", second)
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, second, "--append", "--level", "detailed", "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("is a dataset of level 'simple', not --level detailed", str(e.exception))
        world = os.path.join(self.tmp, "other_world.yaml")
        with open(world, "w") as f:
            f.write("terrain: {type: plane}\nlamps: [{position: [1, 0, 0.2]}]\n")
        with self.assertRaises(SystemExit) as e:
            bag_to_dataset.main([out, second, "--append", "--world", world, "--tracker-topic", "/tracker/sbot_0"])
        self.assertIn("--world %s differs from the world of" % world, str(e.exception))
        self.assertFalse(os.path.exists(os.path.join(out, "append_second.csv")), "a refused append wrote a run")
        # Without --level (or with the dataset's own), the run joins the dataset at its level.
        self.assertEqual(bag_to_dataset.main([out, second, "--append", "--tracker-topic", "/tracker/sbot_0"]), 0)
        with open(os.path.join(out, "dataset.yaml")) as f:
            ds = yaml.safe_load(f)
        self.assertEqual(ds["robot"], "simple")
        self.assertEqual([r["name"] for r in ds["runs"]], ["append_first", "append_second"])

    def test_an_unknown_level_is_refused(self):
        good = os.path.join(self.tmp, "good_for_level.bag")
        self.write_bag("straight_20", good)
        out = os.path.join(self.tmp, "bogus_level")
        err = io.StringIO()
        with self.assertRaises(SystemExit) as e, contextlib.redirect_stderr(err):
            bag_to_dataset.main([out, good, "--level", "bogus", "--tracker-topic", "/tracker/sbot_0"])
        self.assertNotEqual(e.exception.code, 0)
        self.assertIn("invalid choice: 'bogus'", err.getvalue())
        self.assertIn("medium", err.getvalue(), "lists the levels")
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
