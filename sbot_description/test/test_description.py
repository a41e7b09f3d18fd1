#!/usr/bin/python3
"""Tests of sbot_description: run as `/usr/bin/python3 test/test_description.py` (exit != 0 on failure).

(a) the committed urdf/ files are exactly what the parameter table generates;
(b) every URDF passes check_urdf;
(c) every level has the shared link/joint names;
(d) values in each URDF and sidecar match the parameter table (checked from the parsed XML, with a
    mutation test proving that a wrong number is caught);
(e) dynamical body counts (rigid groups with mass joined by non-fixed joints) are as documented;
plus frame conventions (sensor axes, wheel axes, ground plane), Fast = Simple scaled, equal ground
speed at equal command, and closure of the side-arm loop joints.
"""
import copy
import filecmp
import math
import os
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

import yaml

PKG = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(PKG, "scripts"))
import generate_urdf as gen  # noqa: E402

URDF_DIR = os.path.join(PKG, "urdf")
TABLE = gen.load_table()
LEVELS = TABLE["levels_order"]
CHECK_URDF = "/usr/bin/check_urdf"

SHARED_LINKS = (["base_link", "turret", "gripper", "camera"]
                + ["ir_%d" % i for i in range(15)] + ["ground_%d" % i for i in range(4)]
                + ["light_%d" % i for i in range(8)] + ["mic_%d" % i for i in range(3)])


# ------------------------------------------------------------------------------------------------
# Independent URDF reading helpers (do not reuse the generator's in-memory model)
# ------------------------------------------------------------------------------------------------

def floats(s):
    return [float(v) for v in s.split()]


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr]]


def mv(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def mm(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


class Urdf:
    def __init__(self, path):
        self.path = path
        self.root = ET.parse(path).getroot()
        self.links = {l.get("name"): l for l in self.root.findall("link")}
        self.joints = {j.get("name"): j for j in self.root.findall("joint")}
        self.child_joint = {j.find("child").get("link"): j for j in self.joints.values()}

    def mass(self, link):
        m = self.links[link].find("inertial/mass")
        return 0.0 if m is None else float(m.get("value"))

    def jtype(self, name):
        return self.joints[name].get("type")

    def origin(self, joint):
        o = self.joints[joint].find("origin")
        return floats(o.get("xyz")), floats(o.get("rpy"))

    def axis(self, joint):
        a = self.joints[joint].find("axis")
        return [1.0, 0.0, 0.0] if a is None else floats(a.get("xyz"))

    def limit(self, joint):
        lim = self.joints[joint].find("limit")
        return {} if lim is None else {k: float(v) for k, v in lim.attrib.items()}

    def collisions(self, link):
        out = []
        for c in self.links[link].findall("collision"):
            g = c.find("geometry")[0]
            o = c.find("origin")
            out.append((g.tag, {k: (floats(v) if " " in v else float(v)) for k, v in g.attrib.items()},
                        floats(o.get("xyz")), floats(o.get("rpy"))))
        return out

    def pose(self, link):
        """Pose (R, p) of a link in base_link at the zero configuration."""
        if link not in self.child_joint:
            return [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 0.0, 0.0]
        j = self.child_joint[link]
        R0, p0 = self.pose(j.find("parent").get("link"))
        xyz, rpy = self.origin(j.get("name"))
        return mm(R0, rpy_matrix(*rpy)), [p0[i] + mv(R0, xyz)[i] for i in range(3)]

    def dynamical_bodies(self):
        """Rigid groups (links joined by fixed joints) that carry mass."""
        parent = {l: l for l in self.links}

        def find(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        for j in self.joints.values():
            if j.get("type") == "fixed":
                a, b = find(j.find("parent").get("link")), find(j.find("child").get("link"))
                parent[b] = a
        groups = {}
        for l in self.links:
            groups[find(l)] = groups.get(find(l), 0.0) + self.mass(l)
        return sum(1 for m in groups.values() if m > 0.0)


def load_sidecar(path):
    with open(path, "r", encoding="utf-8") as fh:
        return yaml.safe_load(fh)


def close(a, b, rel=1e-6, abs_=1e-12):
    return abs(a - b) <= max(abs_, rel * max(abs(a), abs(b)))


# ------------------------------------------------------------------------------------------------
# Value checks: URDF + sidecar against the resolved parameter table. Returns a list of errors.
# ------------------------------------------------------------------------------------------------

def wheel_joints(p):
    names = ["left_wheel", "right_wheel"]
    if p["wheels"].get("front_rear"):
        names += ["left_wheel_front", "left_wheel_rear", "right_wheel_front", "right_wheel_rear"]
    return names


def value_errors(u, sc, p, level):
    err = []

    def chk(what, got, want, rel=1e-6):
        if not close(got, want, rel):
            err.append("%s %s: urdf/sidecar %r != table %r" % (level, what, got, want))

    # masses
    chk("base_link mass", u.mass("base_link"), p["chassis"]["mass_kg"])
    chk("turret mass", u.mass("turret"), p["turret"]["mass_kg"])
    if p.get("casters"):
        for c in ("caster_front", "caster_rear"):
            chk(c + " mass", u.mass(c), p["casters"]["mass_kg"])
            chk(c + " radius", u.collisions(c)[0][1]["radius"], p["casters"]["radius_m"])
            chk(c + " x", abs(u.origin(c + "_joint")[0][0]), p["casters"]["x_m"])
    g = p["gripper"]
    chk("gripper mass", u.mass("gripper"), g.get("mass_kg", 0.0))
    if g["type"] == "jaws":
        for j in ("gripper_jaw_upper", "gripper_jaw_lower"):
            chk(j + " mass", u.mass(j), g["jaws"]["mass_kg"])
    # com offsets (Basic/Medium/Detailed shift, Simple/Fast none)
    com = floats(u.links["turret"].find("inertial/origin").get("xyz"))
    for i in range(3):
        chk("turret com[%d]" % i, com[i], p["turret"]["com_m"][i])
    com = floats(u.links["base_link"].find("inertial/origin").get("xyz"))
    for i in range(3):
        chk("chassis com[%d]" % i, com[i], p["chassis"]["com_m"][i])
    inert = u.links["turret"].find("inertial/inertia")
    for k, i in (("ixx", 0), ("iyy", 1), ("izz", 2)):
        chk("turret " + k, float(inert.get(k)), p["turret"]["inertia_kgm2"][i])
    # wheels: radius, separation, effort, velocity
    tr = p["treels"]
    names = wheel_joints(p)
    per_track = len(names) // 2
    for n in names:
        w = p["wheels"]["center"] if n in ("left_wheel", "right_wheel") else p["wheels"]["front_rear"]
        chk(n + " radius", outer_radius(u.collisions(n)), w["radius_m"])
        xyz, _ = u.origin(n + "_joint")
        chk(n + " lateral offset", abs(xyz[1]), w["y_m"])
        chk(n + " x", abs(xyz[0]), w["x_m"])
        lim = u.limit(n + "_joint")
        chk(n + " effort", lim["effort"], tr["max_torque_Nm"] / per_track)
        chk(n + " velocity", lim["velocity"], tr["max_speed_mps"] / w["radius_m"])
        chk(n + " sidecar radius", sc["treels"]["wheel_radii"].get(n + "_joint", sc["treels"]["wheel_radius"]),
            w["radius_m"])
    chk("wheel separation", u.origin("left_wheel_joint")[0][1] - u.origin("right_wheel_joint")[0][1],
        2 * p["wheels"]["center"]["y_m"])
    # turret joint
    api = p["turret"]["api"]
    lim = u.limit("turret_joint")
    chk("turret lower", lim["lower"], -api["limit_rad"])
    chk("turret upper", lim["upper"], api["limit_rad"])
    chk("turret effort", lim["effort"], api["max_torque_Nm"])
    chk("turret velocity", lim["velocity"], api["speed_rads"])
    chk("turret height", u.origin("turret_joint")[0][2], p["turret"]["joint_z_m"])
    # gripper joints
    if g["type"] != "none":
        lim = u.limit("gripper_elevation_joint")
        el = g["elevation"]
        chk("gripper lower", lim["lower"], el["lower_rad"])
        chk("gripper upper", lim["upper"], el["upper_rad"])
        chk("gripper effort", lim["effort"], el["torque_Nm"])
        chk("gripper velocity", lim["velocity"], el["speed_rads"])
        chk("sidecar gripper elevation_torque", sc["gripper"]["elevation_torque"], el["torque_Nm"])
    if g["type"] == "jaws":
        jw = g["jaws"]
        for j in ("gripper_jaw_upper_joint", "gripper_jaw_lower_joint"):
            lim = u.limit(j)
            chk(j + " upper", lim["upper"], jw["upper_rad"])
            chk(j + " lower", lim["lower"], jw["lower_rad"])
            chk(j + " effort", lim["effort"], min(jw["force_N"] * jw["lever_m"], jw.get("servo_torque_max_Nm", float("inf"))))
            chk(j + " velocity", lim["velocity"], jw["speed_rads"])
    # side arm servos
    sa = p.get("side_arm")
    if sa:
        chk("side arm elevation effort", u.limit("side_arm_elevation_joint")["effort"], sa["elevation_torque_Nm"])
        for j in ("side_arm_rotation_left_joint", "side_arm_rotation_right_joint"):
            chk(j + " effort", u.limit(j)["effort"], sa["horizontal_torque_Nm"])
        for j in ("side_arm_jaw_a_joint", "side_arm_jaw_b_joint"):
            chk(j + " effort", u.limit(j)["effort"], sa["jaw_force_N"] * sa["jaw_lever_m"])
        m = sum(u.mass(l) for l in u.links if l.startswith("side_arm_"))
        want = (sa["base_mass_kg"] + 2 * sa["root_mass_kg"] + 4 * sa["cross_mass_kg"]
                + 2 * sa["tip_mass_kg"] + sa["head_mass_kg"] + 2 * sa["jaw_mass_kg"])
        chk("side arm mass", m, want)
    # sidecar semantics
    chk("sidecar wheel_radius", sc["treels"]["wheel_radius"], p["wheels"]["center"]["radius_m"])
    chk("sidecar max_torque", sc["treels"]["max_torque"], tr["max_torque_Nm"])
    chk("sidecar torque_unit", sc["treels"]["torque_unit"], tr["torque_unit_Nm"])
    chk("sidecar speed_unit", sc["treels"]["speed_unit"], tr["speed_unit_mps"])
    chk("sidecar speed_limit_units", sc["treels"]["speed_limit_units"], tr["speed_limit_units"])
    chk("sidecar torque_window", sc["treels"]["torque_window"], tr["torque_window_s"])
    chk("sidecar turret max_torque", sc["turret"]["max_torque"], api["max_torque_Nm"])
    chk("sidecar turret torque_unit", sc["turret"]["torque_unit"], api["torque_unit_Nm"])
    chk("sidecar turret unit", sc["turret"]["unit"], api["unit_rad"])
    chk("sidecar gravity", sc["gravity"], p["gravity_mps2"])
    chk("sidecar step", sc["recommended_step"], p["recommended_step_s"])
    if sc["level"] != level:
        err.append("%s sidecar level %r" % (level, sc["level"]))
    return err


def outer_radius(cols):
    """A wheel's radius from its collision shapes: the furthest any shape reaches from the axle (a
    sphere's radius; a teethed wheel's core cylinder, box teeth or round teeth)."""
    reach = {"sphere": lambda c: c[1]["radius"], "cylinder": lambda c: math.hypot(c[2][0], c[2][2]) + c[1]["radius"],
             "box": lambda c: math.hypot(c[2][0], c[2][2]) + c[1]["size"][0] / 2.0}
    return max(reach[c[0]](c) for c in cols)


def teeth_of(cols):
    """A teethed wheel's teeth: every shape but the core cylinder on the axle."""
    return [c for c in cols if math.hypot(c[2][0], c[2][2]) > 1e-9]


def write_changed_table(tmp, level, path, value):
    """The parameter table with levels.<level>.<path> set to value, written into tmp; its path."""
    table = copy.deepcopy(TABLE)
    node = table["levels"][level]
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    tpath = os.path.join(tmp, "table.yaml")
    with open(tpath, "w") as fh:
        yaml.safe_dump(table, fh)
    return tpath


def generate_to(tmp, table_path=None):
    args = ["--out", tmp, "--quiet"]
    if table_path:
        args += ["--params", table_path]
    gen.main(args)


# ------------------------------------------------------------------------------------------------

class TestDescription(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.urdf = {lv: Urdf(os.path.join(URDF_DIR, lv + ".urdf")) for lv in LEVELS}
        cls.side = {lv: load_sidecar(os.path.join(URDF_DIR, lv + ".sbot.yaml")) for lv in LEVELS}
        cls.par = {lv: gen.resolve_level(TABLE, lv) for lv in LEVELS}

    # (a) -----------------------------------------------------------------------------------------
    def test_a_regeneration_is_byte_identical(self):
        with tempfile.TemporaryDirectory() as tmp:
            generate_to(tmp)
            names = sorted(os.listdir(tmp))
            self.assertEqual(len(names), 2 * len(LEVELS))
            for n in names:
                self.assertTrue(os.path.exists(os.path.join(URDF_DIR, n)), "missing committed " + n)
                self.assertTrue(filecmp.cmp(os.path.join(tmp, n), os.path.join(URDF_DIR, n), shallow=False),
                                "%s differs from the table: run scripts/generate_urdf.py --out urdf" % n)
            # and twice in a row gives the same bytes (determinism)
            with tempfile.TemporaryDirectory() as tmp2:
                generate_to(tmp2)
                for n in names:
                    self.assertTrue(filecmp.cmp(os.path.join(tmp, n), os.path.join(tmp2, n), shallow=False))

    # (b) -----------------------------------------------------------------------------------------
    def test_b_check_urdf(self):
        self.assertTrue(os.path.exists(CHECK_URDF), "check_urdf not installed")
        for lv in LEVELS:
            r = subprocess.run([CHECK_URDF, os.path.join(URDF_DIR, lv + ".urdf")],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
            self.assertEqual(r.returncode, 0, "%s: %s" % (lv, r.stdout[-2000:]))
            self.assertIn("Successfully Parsed XML", r.stdout)

    # (c) -----------------------------------------------------------------------------------------
    def test_c_shared_names(self):
        for lv in LEVELS:
            u = self.urdf[lv]
            for name in SHARED_LINKS + ["fake_camera", "gripper_tip", "left_wheel", "right_wheel"]:
                self.assertIn(name, u.links, "%s lacks link %s" % (lv, name))
            for j in ("turret_joint", "left_wheel_joint", "right_wheel_joint"):
                self.assertIn(j, u.joints, "%s lacks joint %s" % (lv, j))
            self.assertEqual(u.jtype("turret_joint"), "revolute")
            self.assertEqual(u.child_joint["turret"].find("parent").get("link"), "base_link")
            self.assertNotIn("base_link", u.child_joint, "base_link must be the root")
            for j in u.joints.values():
                self.assertIn(j.get("type"), ("fixed", "revolute", "continuous"))
            for l in u.links:
                for c in u.collisions(l):
                    self.assertIn(c[0], ("sphere", "cylinder", "box"))
                nvis, ncol = len(u.links[l].findall("visual")), len(u.links[l].findall("collision"))
                self.assertEqual(nvis, ncol, "%s %s: visual/collision mismatch" % (lv, l))
                if u.mass(l) > 0:
                    inert = u.links[l].find("inertial/inertia")
                    for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                        self.assertIsNotNone(inert.get(k))
                    self.assertGreater(float(inert.get("ixx")), 0)
            if self.par[lv]["wheels"].get("front_rear"):
                for n in ("left_wheel_front", "left_wheel_rear", "right_wheel_front", "right_wheel_rear"):
                    self.assertIn(n + "_joint", u.joints)
            if self.par[lv]["gripper"]["type"] != "none":
                self.assertEqual(u.jtype("gripper_elevation_joint"), "revolute")
            if self.par[lv]["gripper"]["type"] == "jaws":
                for n in ("gripper_jaw_upper_joint", "gripper_jaw_lower_joint"):
                    self.assertEqual(u.jtype(n), "revolute")

    # (d) -----------------------------------------------------------------------------------------
    def test_d_values_match_table(self):
        for lv in LEVELS:
            errs = value_errors(self.urdf[lv], self.side[lv], self.par[lv], lv)
            self.assertEqual(errs, [], "\n".join(errs))

    def test_d_mutation_is_detected(self):
        """A table that differs in one number must produce files that fail the value check."""
        mutations = [("simple", ["chassis", "mass_kg"], 0.3),
                     ("medium", ["wheels", "front_rear", "y_m"], 0.03),
                     ("simple", ["treels", "max_torque_Nm"], 0.3)]
        for level, path, value in mutations:
            with tempfile.TemporaryDirectory() as tmp:
                tpath = write_changed_table(tmp, level, path, value)
                out = os.path.join(tmp, "out")
                generate_to(out, tpath)
                u = Urdf(os.path.join(out, level + ".urdf"))
                sc = load_sidecar(os.path.join(out, level + ".sbot.yaml"))
                errs = value_errors(u, sc, self.par[level], level)
                self.assertTrue(errs, "mutation %s=%r not detected" % (".".join(path), value))

    def test_a_table_that_cannot_describe_a_body_is_refused_by_name(self):
        """A mass, radius or size that is not > 0, or a NaN anywhere, stops the generator with the
        field's path (as resolved: Detailed inherits Medium's wheels)."""
        cases = [("medium", ["turret", "mass_kg"], -1.0, "levels.medium.turret.mass_kg: expected a number > 0"),
                 ("medium", ["wheels", "center", "radius_m"], 0.0,
                  "levels.medium.wheels.center.radius_m: expected a number > 0"),
                 ("simple", ["chassis", "com_m"], [0.0, float("nan"), 0.0],
                  "levels.simple.chassis.com_m[1]: expected a finite number"),
                 ("detailed", ["wheels", "front_rear", "tooth_shape"], "hexagon",
                  "levels.detailed.wheels.front_rear.tooth_shape: expected one of box, cylinder, found 'hexagon'")]
        for level, path, value, message in cases:
            with tempfile.TemporaryDirectory() as tmp:
                tpath = write_changed_table(tmp, level, path, value)
                r = subprocess.run(["/usr/bin/python3", os.path.join(PKG, "scripts", "generate_urdf.py"), "--out",
                                    os.path.join(tmp, "out"), "--quiet", "--params", tpath],
                                   capture_output=True, text=True)
                self.assertNotEqual(r.returncode, 0, ".".join(path))
                self.assertIn(message, r.stderr)
                self.assertIn(tpath, r.stderr)

    def test_both_tooth_shapes_reach_the_wheels_radius(self):
        """tooth_shape: cylinder (the table's) gives every tooth as a cylinder along the axle, box as
        a box across the rim; either way as many as `teeth`, their outsides on the wheel's radius,
        and the values and the URDF check hold."""
        for tooth_shape in ("cylinder", "box"):
            with tempfile.TemporaryDirectory() as tmp:
                table = copy.deepcopy(TABLE)
                for key in ("center", "front_rear"):
                    table["levels"]["detailed"]["wheels"][key]["tooth_shape"] = tooth_shape
                tpath = os.path.join(tmp, "table.yaml")
                with open(tpath, "w") as fh:
                    yaml.safe_dump(table, fh)
                out = os.path.join(tmp, "out")
                generate_to(out, tpath)
                u = Urdf(os.path.join(out, "detailed.urdf"))
                sc = load_sidecar(os.path.join(out, "detailed.sbot.yaml"))
                p = gen.resolve_level(table, "detailed")
                self.assertEqual(value_errors(u, sc, p, "detailed"), [], tooth_shape)
                for name, key in (("left_wheel", "center"), ("right_wheel_front", "front_rear")):
                    w = p["wheels"][key]
                    teeth = teeth_of(u.collisions(name))
                    self.assertEqual(len(teeth), int(w["teeth"]), name)
                    for shape, attrs, xyz, rpy in teeth:
                        self.assertEqual(shape, tooth_shape, name)
                        if shape == "cylinder":
                            self.assertAlmostEqual(attrs["radius"], w["tooth_width_m"] / 2.0, places=9)
                            self.assertAlmostEqual(rpy[0], math.pi / 2, places=6)  # axis along the axle (y)
                        self.assertAlmostEqual(outer_radius([(shape, attrs, xyz, rpy)]), w["radius_m"], places=7, msg=name)
                r = subprocess.run([CHECK_URDF, os.path.join(out, "detailed.urdf")], capture_output=True, text=True)
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_d_total_mass_and_fast_scaling(self):
        for lv in LEVELS:
            total = sum(self.urdf[lv].mass(l) for l in self.urdf[lv].links)
            self.assertAlmostEqual(total, 0.033 if lv == "fast" else 0.660, places=9, msg=lv)
        fast, simple = self.urdf["fast"], self.urdf["simple"]
        self.assertEqual(sorted(fast.links), sorted(simple.links))
        fast_override = TABLE["levels"]["fast"].get("override", {})
        # Parts whose mass or size Fast's override sets itself are not Simple's scaled (their values
        # are checked against the table by test_d_values_match_table); every other link is.
        sized = ("mass_kg", "radius_m")
        own = set()
        if any(k in fast_override.get("casters", {}) for k in sized):
            own |= {"caster_front", "caster_rear"}
        if any(k in fast_override.get("wheels", {}).get("center", {}) for k in sized):
            own |= {"left_wheel", "right_wheel"}
        if any(k in fast_override.get("turret", {}) for k in sized):
            own.add("turret")
        for l in simple.links:
            if l in own:
                continue
            self.assertTrue(close(fast.mass(l), 0.05 * simple.mass(l)), l)
            if simple.mass(l) > 0:
                fi, si = fast.links[l].find("inertial/inertia"), simple.links[l].find("inertial/inertia")
                self.assertTrue(close(float(fi.get("izz")), 0.05 * 0.25 * float(si.get("izz"))), l)
        for j in simple.joints:
            if j.startswith("caster_") and "casters" in fast_override:
                continue  # placed by Fast's own override (test_d_values_match_table checks them)
            fx, sx = fast.origin(j)[0], simple.origin(j)[0]
            for a, b in zip(fx, sx):
                self.assertTrue(close(a, 0.5 * b, abs_=1e-9), "%s origin %r vs %r" % (j, fx, sx))
        self.assertTrue(close(self.side["fast"]["gravity"], 9.81 / 50))
        self.assertTrue(close(self.side["fast"]["recommended_step"], 0.1))
        self.assertTrue(close(self.side["fast"]["treels"]["max_torque"], 0.21971 * 0.05 * 0.02 * 0.5))

    # (e) -----------------------------------------------------------------------------------------
    def test_e_dynamical_bodies(self):
        documented = {"fast": 4, "simple": 4, "basic": 5, "medium": 9, "detailed": 22}  # README
        for lv in LEVELS:
            n = self.urdf[lv].dynamical_bodies()
            self.assertEqual(n, documented[lv], lv)
            self.assertEqual(n, self.par[lv]["expected_dynamical_bodies"], lv)
            self.assertEqual(n, self.side[lv]["extra"]["dynamical_bodies"], lv)
        u = self.urdf["detailed"]
        side_arm_bodies = [l for l in u.links if l.startswith("side_arm_") and u.mass(l) > 0]
        self.assertEqual(len(side_arm_bodies), 11)  # Table 2.5
        self.assertEqual(len(self.side["detailed"]["side_arm"]["servos"]), 5)  # Table 2.5

    # frames and conventions ----------------------------------------------------------------------
    def test_sensor_frames(self):
        for lv in LEVELS:
            u = self.urdf[lv]
            for l in SHARED_LINKS[3:] + ["fake_camera", "gripper_tip"]:
                self.assertEqual(u.mass(l), 0.0, "%s %s must be massless" % (lv, l))
                self.assertIsNone(u.links[l].find("inertial"))
                self.assertEqual(u.jtype(l + "_joint"), "fixed")
            for i in range(15):
                R, p = u.pose("ir_%d" % i)
                want = math.radians(40 + 20 * i)
                got = math.atan2(R[1][0], R[0][0])
                self.assertAlmostEqual(math.cos(got - want), 1.0, places=9)
                self.assertAlmostEqual(math.atan2(p[1], p[0]) % (2 * math.pi), want % (2 * math.pi), places=6)
                self.assertEqual(u.child_joint["ir_%d" % i].find("parent").get("link"), "turret")
            for i in range(8):
                R, _ = u.pose("light_%d" % i)
                self.assertAlmostEqual(math.cos(math.atan2(R[1][0], R[0][0]) - math.radians(45 * i)), 1.0, places=9)
            for i in range(3):
                R, _ = u.pose("mic_%d" % i)
                self.assertAlmostEqual(math.cos(math.atan2(R[1][0], R[0][0]) - math.radians(120 * i)), 1.0, places=9)
            for i, d in enumerate(((1, 0), (0, 1), (-1, 0), (0, -1))):
                R, p = u.pose("ground_%d" % i)
                self.assertAlmostEqual(R[2][0], -1.0, places=9)  # +x points down
                self.assertEqual(u.child_joint["ground_%d" % i].find("parent").get("link"), "base_link")
                self.assertGreater(p[0] * d[0] + p[1] * d[1], 0.0)
            R, p = u.pose("camera")
            self.assertAlmostEqual(R[2][0], -1.0, places=9)
            scale = 0.5 if lv == "fast" else 1.0
            self.assertAlmostEqual(p[2] - u.origin("turret_joint")[0][2], 0.1185 * scale, places=9)
            _, p = u.pose("fake_camera")
            self.assertAlmostEqual(p[2] - u.origin("turret_joint")[0][2], 0.05 * scale, places=9)
            _, p = u.pose("gripper")
            self.assertGreater(p[0], 0.0)

    def test_wheels_and_ground_plane(self):
        for lv in LEVELS:
            u, p, sc = self.urdf[lv], self.par[lv], self.side[lv]
            names = wheel_joints(p)
            self.assertEqual(sorted(sc["treels"]["left_joints"] + sc["treels"]["right_joints"]),
                             sorted(n + "_joint" for n in names))
            bottoms = []
            for n in names:
                self.assertEqual(u.jtype(n + "_joint"), "continuous")
                self.assertEqual(u.axis(n + "_joint"), [0.0, 1.0, 0.0])
                xyz, _ = u.origin(n + "_joint")
                r = sc["treels"]["wheel_radii"].get(n + "_joint", sc["treels"]["wheel_radius"])
                bottoms.append(xyz[2] - r)
                self.assertEqual(xyz[1] > 0, n.startswith("left"), n)
                self.assertIn(n + "_joint", sc["treels"]["left_joints" if n.startswith("left") else "right_joints"])
            if p.get("casters"):
                for c in ("caster_front", "caster_rear"):
                    caster_bottom = u.origin(c + "_joint")[0][2] - u.collisions(c)[0][1]["radius"]
                    # casters sit a small clearance above the wheels' plane (weight on the wheels)
                    self.assertAlmostEqual(caster_bottom - bottoms[0], p["casters"]["clearance_m"], places=9,
                                           msg="%s: %s clearance" % (lv, c))
                    self.assertGreater(p["casters"]["clearance_m"], 0.0)
                    self.assertEqual(sc["materials"][c], "caster")
                    self.assertEqual(u.jtype(c + "_joint"), "fixed")
            for b in bottoms:
                self.assertAlmostEqual(b, bottoms[0], places=9, msg="%s: wheels/casters not on one plane" % lv)
            # chassis clears the ground
            lowest = min(c[2][2] - (c[1]["radius"] if c[0] == "sphere" else c[1]["size"][2] / 2.0)
                         for c in u.collisions("base_link"))
            self.assertGreater(lowest, bottoms[0])

    def test_equal_ground_speed_at_equal_command(self):
        """Same API speed -> same ground speed at every level (within 3 %)."""
        units = 50
        for lv in LEVELS:
            u, sc = self.urdf[lv], self.side[lv]
            v_cmd = units * sc["treels"]["speed_unit"]
            self.assertTrue(close(v_cmd, units * 0.0028))
            for jn in sc["treels"]["left_joints"] + sc["treels"]["right_joints"]:
                omega = v_cmd / sc["treels"]["wheel_radii"].get(jn, sc["treels"]["wheel_radius"])
                cols = u.collisions(jn[:-len("_joint")])
                if cols[0][0] == "sphere":
                    r_roll = cols[0][1]["radius"]
                else:  # teethed: rolls on the polygon of its teeth's outsides
                    n = len(teeth_of(cols))
                    r_roll = outer_radius(cols) * math.sin(math.pi / n) / (math.pi / n)
                v = omega * r_roll
                self.assertLess(abs(v - v_cmd) / v_cmd, 0.03, "%s %s: %g vs %g" % (lv, jn, v, v_cmd))

    def test_side_arm_loops_close(self):
        u, sc = self.urdf["detailed"], self.side["detailed"]["side_arm"]
        self.assertEqual(len(sc["loop_joints"]), 3)
        for lj in sc["loop_joints"]:
            self.assertEqual(lj["type"], "revolute")
            Rp, pp = u.pose(lj["parent"])
            Rc, pc = u.pose(lj["child"])
            a = [pp[i] + mv(Rp, lj["anchor_in_parent"])[i] for i in range(3)]
            b = [pc[i] + mv(Rc, lj["anchor_in_child"])[i] for i in range(3)]
            for i in range(3):
                self.assertAlmostEqual(a[i], b[i], places=7, msg=lj["name"])
            ap, ac = mv(Rp, lj["axis"]), mv(Rc, lj["axis"])
            self.assertAlmostEqual(sum(x * y for x, y in zip(ap, ac)), 1.0, places=9)
        for role, j in sc["servos"].items():
            self.assertEqual(u.jtype(j), "revolute", role)
            self.assertGreater(u.limit(j)["effort"], 0, role)
        for j in sc["passive_joints"]:
            self.assertEqual(u.limit(j)["effort"], 0.0)
        # rest direction: 110 deg from the front gripper axis, depth 6 s cos(alpha0)
        Rb, pb = u.pose("side_arm_base")
        self.assertAlmostEqual(math.degrees(math.atan2(Rb[1][0], Rb[0][0])), 110.0, places=4)
        _, pt = u.pose("side_arm_tip_b")
        tip = [pt[i] + mv(u.pose("side_arm_tip_b")[0], [sc["link_length"], 0, 0])[i] for i in range(3)]
        _, proot = u.pose("side_arm_root_left")
        self.assertAlmostEqual(math.dist(tip, proot), sc["depth_rest"], places=7)


if __name__ == "__main__":
    unittest.main(verbosity=2)
