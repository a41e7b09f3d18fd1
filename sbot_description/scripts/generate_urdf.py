#!/usr/bin/python3
"""Generate the s-bot URDFs and simulation sidecars from config/sbot_parameters.yaml.

    generate_urdf.py --out DIR [--quiet] [--level L] [--params FILE]

Writes DIR/<level>.urdf and DIR/<level>.sbot.yaml for every level (or only L). Output is
deterministic: same table -> byte-identical files (fixed float formatting, fixed ordering).
Only the Python standard library and PyYAML are used (xacro is not available on Debian 12).
"""
import argparse
import copy
import math
import os
import sys

import yaml

PKG_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PARAMS = os.path.join(PKG_DIR, "config", "sbot_parameters.yaml")

# ------------------------------------------------------------------------------------------------
# Parameter table: loading, inheritance, Fast scaling
# ------------------------------------------------------------------------------------------------


def deep_merge(base, over):
    """Return base updated recursively with over (dicts merge, everything else replaces)."""
    if isinstance(base, dict) and isinstance(over, dict):
        out = copy.deepcopy(base)
        for k, v in over.items():
            out[k] = deep_merge(out[k], v) if k in out else copy.deepcopy(v)
        return out
    return copy.deepcopy(over)


def unit_suffix(key):
    return key.rsplit("_", 1)[-1] if "_" in key else ""


def scale_tree(node, factors, key=""):
    """Scale every numeric value according to the unit suffix of its key (see the table header)."""
    if isinstance(node, dict):
        return {k: scale_tree(v, factors, k) for k, v in node.items()}
    if isinstance(node, list):
        return [scale_tree(v, factors, key) for v in node]
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        return node
    f = factors.get(unit_suffix(key), 1.0)
    return node * f if f != 1.0 else node


def load_table(path=DEFAULT_PARAMS):
    with open(path, "r", encoding="utf-8") as fh:
        return yaml.safe_load(fh)


def resolve_level(table, level):
    """Fully resolved parameter dict of one level (inherit / derive applied)."""
    raw = table["levels"][level]
    if "derive" in raw:
        d = raw["derive"]
        base = resolve_level(table, d["from"])
        L, M, G = float(d["length"]), float(d["mass"]), float(d["gravity"])
        factors = {"m": L, "kg": M, "kgm2": M * L * L, "Nm": M * G * L, "N": M * G}
        out = scale_tree(base, factors)
        out = deep_merge(out, raw.get("override", {}))
        out["scale"] = {"length": L, "mass": M, "gravity": G}
        return out
    if "inherit" in raw:
        base = resolve_level(table, raw["inherit"])
        over = {k: v for k, v in raw.items() if k != "inherit"}
        out = deep_merge(base, over)
        out.pop("scale", None)
        return out
    return copy.deepcopy(raw)


# Physical quantities that must be positive wherever they appear in a level (key names of the table).
POSITIVE_KEYS = ("mass_kg", "radius_m", "height_m", "length_m", "width_m", "box_m", "inertia_kgm2")
TOOTH_SHAPES = ("box", "cylinder")


def check_level(source, node, path):
    """Refuse a level whose numbers cannot describe a body: NaN or infinite anywhere, and a mass,
    radius, size or inertia that is not > 0. The message names the file and the field's path in it
    (`path` starts as "levels.<level>"; inherited and derived values are checked as resolved)."""
    if isinstance(node, dict):
        for k, v in node.items():
            where = "%s.%s" % (path, k)
            check_level(source, v, where)
            if k == "tooth_shape" and v not in TOOTH_SHAPES:
                raise SystemExit("%s: %s: expected one of %s, found %r" % (source, where, ", ".join(TOOTH_SHAPES), v))
            if k in POSITIVE_KEYS or k.endswith("radius_m"):
                for i, x in enumerate(v if isinstance(v, list) else [v]):
                    if isinstance(x, (int, float)) and not isinstance(x, bool) and not x > 0:
                        index = "[%d]" % i if isinstance(v, list) else ""
                        raise SystemExit("%s: %s%s: expected a number > 0, found %r" % (source, where, index, x))
    elif isinstance(node, list):
        for i, x in enumerate(node):
            check_level(source, x, "%s[%d]" % (path, i))
    elif isinstance(node, float) and not math.isfinite(node):
        raise SystemExit("%s: %s: expected a finite number, found %r" % (source, path, node))


# ------------------------------------------------------------------------------------------------
# Small numeric helpers
# ------------------------------------------------------------------------------------------------


def fmt(x):
    """Fixed float formatting: 8 significant digits, no negative zero."""
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    s = "%.8g" % x
    return "0" if s == "-0" else s


def vec(v):
    return " ".join(fmt(float(c)) for c in v)


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def diag(d):
    return [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]]


def sphere_inertia(m, r):
    i = 0.4 * m * r * r
    return [i, i, i]


def box_inertia(m, size):
    a, b, c = size
    return [m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0]


def cylinder_y_inertia(m, r, length):
    """Solid cylinder whose axis is the link's y axis (wheels)."""
    across = m * (3.0 * r * r + length * length) / 12.0
    return [across, 0.5 * m * r * r, across]


def composite(parts):
    """parts: list of (mass, com[3], inertia 3x3 about own com in link axes). Returns m, com, I."""
    m = sum(p[0] for p in parts)
    com = [sum(p[0] * p[1][i] for p in parts) / m for i in range(3)]
    tot = [[0.0] * 3 for _ in range(3)]
    for pm, pc, pi in parts:
        d = [pc[i] - com[i] for i in range(3)]
        dd = sum(x * x for x in d)
        for i in range(3):
            for j in range(3):
                tot[i][j] += pi[i][j] + pm * ((dd if i == j else 0.0) - d[i] * d[j])
    return m, com, tot


# ------------------------------------------------------------------------------------------------
# Robot model in memory
# ------------------------------------------------------------------------------------------------

COLOURS = [
    ("chassis_grey", "0.35 0.35 0.38 1"),
    ("track_black", "0.08 0.08 0.08 1"),
    ("caster_white", "0.9 0.9 0.9 1"),
    ("turret_blue", "0.55 0.65 0.8 1"),
    ("ring_clear", "0.85 0.9 1 0.6"),
    ("pole_clear", "0.8 0.9 1 0.4"),
    ("gripper_red", "0.8 0.15 0.1 1"),
    ("arm_grey", "0.6 0.6 0.6 1"),
]


class Robot:
    def __init__(self, name):
        self.name = name
        self.links = []   # dicts: name, inertial, shapes
        self.joints = []  # dicts

    def link(self, name, mass=None, com=(0, 0, 0), inertia=None, shapes=None):
        """inertia: 3 principal moments or a full 3x3 matrix."""
        if inertia is not None and not isinstance(inertia[0], list):
            inertia = diag(inertia)
        self.links.append({"name": name, "mass": mass, "com": list(com), "inertia": inertia,
                           "shapes": shapes or []})

    def joint(self, name, jtype, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None,
              limit=None):
        self.joints.append({"name": name, "type": jtype, "parent": parent, "child": child,
                            "xyz": list(xyz), "rpy": list(rpy), "axis": axis, "limit": limit})

    def to_urdf(self, header):
        out = ['<?xml version="1.0"?>']
        out.extend("<!-- %s -->" % h for h in header)
        out.append('<robot name="%s">' % self.name)
        for cname, rgba in COLOURS:
            out.append('  <material name="%s"><color rgba="%s"/></material>' % (cname, rgba))
        for ln in self.links:
            if ln["mass"] is None and not ln["shapes"]:
                out.append('  <link name="%s"/>' % ln["name"])
                continue
            out.append('  <link name="%s">' % ln["name"])
            if ln["mass"] is not None:
                I = ln["inertia"]
                out.append("    <inertial>")
                out.append('      <origin xyz="%s" rpy="0 0 0"/>' % vec(ln["com"]))
                out.append('      <mass value="%s"/>' % fmt(ln["mass"]))
                out.append('      <inertia ixx="%s" ixy="%s" ixz="%s" iyy="%s" iyz="%s" izz="%s"/>'
                           % tuple(fmt(v) for v in (I[0][0], I[0][1], I[0][2], I[1][1], I[1][2],
                                                     I[2][2])))
                out.append("    </inertial>")
            for tag in ("visual", "collision"):
                for sh in ln["shapes"]:
                    out.append("    <%s>" % tag)
                    out.append('      <origin xyz="%s" rpy="%s"/>' % (vec(sh["xyz"]), vec(sh["rpy"])))
                    out.append("      <geometry>%s</geometry>" % geometry_xml(sh))
                    if tag == "visual":
                        out.append('      <material name="%s"/>' % sh["colour"])
                    out.append("    </%s>" % tag)
            out.append("  </link>")
        for j in self.joints:
            out.append('  <joint name="%s" type="%s">' % (j["name"], j["type"]))
            out.append('    <parent link="%s"/>' % j["parent"])
            out.append('    <child link="%s"/>' % j["child"])
            out.append('    <origin xyz="%s" rpy="%s"/>' % (vec(j["xyz"]), vec(j["rpy"])))
            if j["axis"] is not None:
                out.append('    <axis xyz="%s"/>' % vec(j["axis"]))
            if j["limit"] is not None:
                lim = j["limit"]
                attrs = []
                for k in ("lower", "upper", "effort", "velocity"):
                    if k in lim:
                        attrs.append('%s="%s"' % (k, fmt(lim[k])))
                out.append("    <limit %s/>" % " ".join(attrs))
            out.append("  </joint>")
        out.append("</robot>")
        return "\n".join(out) + "\n"


def geometry_xml(sh):
    if sh["type"] == "sphere":
        return '<sphere radius="%s"/>' % fmt(sh["radius"])
    if sh["type"] == "cylinder":
        return '<cylinder radius="%s" length="%s"/>' % (fmt(sh["radius"]), fmt(sh["length"]))
    if sh["type"] == "box":
        return '<box size="%s"/>' % vec(sh["size"])
    raise ValueError(sh["type"])


def sphere(r, xyz=(0, 0, 0), colour="chassis_grey"):
    return {"type": "sphere", "radius": r, "xyz": list(xyz), "rpy": [0, 0, 0], "colour": colour}


def cylinder(r, length, xyz=(0, 0, 0), rpy=(0, 0, 0), colour="turret_blue"):
    return {"type": "cylinder", "radius": r, "length": length, "xyz": list(xyz), "rpy": list(rpy),
            "colour": colour}


def box(size, xyz=(0, 0, 0), rpy=(0, 0, 0), colour="chassis_grey"):
    return {"type": "box", "size": list(size), "xyz": list(xyz), "rpy": list(rpy), "colour": colour}


# ------------------------------------------------------------------------------------------------
# Builders
# ------------------------------------------------------------------------------------------------

HALF_PI = math.pi / 2.0
EXTRA_FLAGS = ("ir_model", "ground_sensors", "camera", "sound_model", "light_ring", "gripper",
               "side_arm", "treels_model")


def turret_sensor_ring(rb, prefix, ring, radius):
    """Frames <prefix>_0.. of a ring of sensors on the turret (IR, light, microphones all sit this way):
    `ring` count, first_rad, step_rad, z_m; each at `radius`, +x pointing outwards."""
    for i in range(ring["count"]):
        a = ring["first_rad"] + i * ring["step_rad"]
        a = math.atan2(math.sin(a), math.cos(a))
        rb.link("%s_%d" % (prefix, i))
        rb.joint("%s_%d_joint" % (prefix, i), "fixed", "turret", "%s_%d" % (prefix, i),
                 (radius * math.cos(a), radius * math.sin(a), ring["z_m"]), (0, 0, a))


def build(level, p):
    """Return (Robot, sidecar dict) for one resolved level."""
    rb = Robot("sbot_" + level)
    materials = {}
    treels_left, treels_right, radii = [], [], {}

    # ---- chassis (base_link) -----------------------------------------------------------------
    ch = p["chassis"]
    if ch["shape"] == "sphere":
        shapes = [sphere(ch["radius_m"], colour="chassis_grey")]
    else:
        shapes = [box(ch["box_m"], colour="chassis_grey")]
    rb.link("base_link", ch["mass_kg"], ch["com_m"], ch["inertia_kgm2"], shapes)
    materials["base_link"] = ch["material"]

    # ---- casters (fixed, zero-friction spheres) ------------------------------------------------
    cs = p.get("casters")
    if cs:
        for name, sx in (("caster_front", 1.0), ("caster_rear", -1.0)):
            rb.link(name, cs["mass_kg"], (0, 0, 0), sphere_inertia(cs["mass_kg"], cs["radius_m"]),
                    [sphere(cs["radius_m"], colour="caster_white")])
            rb.joint(name + "_joint", "fixed", "base_link", name, (sx * cs["x_m"], 0, cs["z_m"]))
            materials[name] = cs["material"]

    # ---- wheels ---------------------------------------------------------------------------------
    tr = p["treels"]
    wheels = p["wheels"]
    per_track = 1 + (2 if wheels.get("front_rear") else 0)
    effort = tr["max_torque_Nm"] / per_track
    wheel_list = []
    for side, sy in (("left", 1.0), ("right", -1.0)):
        wheel_list.append(("%s_wheel" % side, side, wheels["center"], 0.0, sy))
    if wheels.get("front_rear"):
        for side, sy in (("left", 1.0), ("right", -1.0)):
            for pos, sx in (("front", 1.0), ("rear", -1.0)):
                wheel_list.append(("%s_wheel_%s" % (side, pos), side, wheels["front_rear"], sx, sy))
    for name, side, w, sx, sy in wheel_list:
        r, m = w["radius_m"], w["mass_kg"]
        if w["shape"] == "sphere":
            inertia = sphere_inertia(m, r)
            shapes = [sphere(r, colour="track_black")]
        elif w["shape"] == "teethed_cylinder":
            inertia = cylinder_y_inertia(m, r, w["width_m"])
            h, n = w["tooth_height_m"], int(w["teeth"])
            shapes = [cylinder(r - h, w["width_m"], rpy=(HALF_PI, 0, 0), colour="track_black")]
            rho = r - h / 2.0
            round_teeth = w.get("tooth_shape", "box") == "cylinder"
            for k in range(n):
                phi = 2.0 * math.pi * k / n
                if round_teeth:  # along the axle, its outside on the wheel's radius
                    a = w["tooth_width_m"] / 2.0
                    shapes.append(cylinder(a, w["width_m"], ((r - a) * math.cos(phi), 0, (r - a) * math.sin(phi)),
                                           (HALF_PI, 0, 0), colour="track_black"))
                else:
                    shapes.append(box([h, w["width_m"], w["tooth_width_m"]],
                                      (rho * math.cos(phi), 0, rho * math.sin(phi)), (0, -phi, 0),
                                      colour="track_black"))
        else:
            raise ValueError(w["shape"])
        rb.link(name, m, (0, 0, 0), inertia, shapes)
        jn = name + "_joint"
        rb.joint(jn, "continuous", "base_link", name, (sx * w["x_m"], sy * w["y_m"], w["z_m"]),
                 axis=(0, 1, 0), limit={"effort": effort, "velocity": tr["max_speed_mps"] / r})
        (treels_left if side == "left" else treels_right).append(jn)
        radii[jn] = r
        materials[name] = w["material"]
    # central wheels first in each list, then front, rear
    center_r = wheels["center"]["radius_m"]

    # ---- turret -----------------------------------------------------------------------------
    t = p["turret"]
    api = t["api"]
    if t["shape"] == "cylinder":
        shapes = [cylinder(t["radius_m"], t["height_m"], colour="turret_blue")]
    else:
        hh = t["height_m"] / 2.0
        pole_len = t["pole_top_m"] - hh
        shapes = [cylinder(t["main_radius_m"], t["height_m"], colour="turret_blue"),
                  cylinder(t["ring_radius_m"], t["ring_height_m"], (0, 0, t["ring_z_m"]),
                           colour="ring_clear"),
                  cylinder(t["pole_radius_m"], pole_len, (0, 0, hh + pole_len / 2.0),
                           colour="pole_clear")]
    rb.link("turret", t["mass_kg"], t["com_m"], t["inertia_kgm2"], shapes)
    rb.joint("turret_joint", "revolute", "base_link", "turret", (0, 0, t["joint_z_m"]),
             axis=(0, 0, 1), limit={"lower": -api["limit_rad"], "upper": api["limit_rad"],
                                    "effort": api["max_torque_Nm"], "velocity": api["speed_rads"]})
    materials["turret"] = t["material"]

    # ---- front gripper ----------------------------------------------------------------------
    g = p["gripper"]
    gside = {"type": g["type"], "link": "gripper", "tip_frame": "gripper_tip",
             "grip_point": g["grip_point_m"]}
    if g["type"] == "none":
        rb.link("gripper")
        rb.joint("gripper_joint", "fixed", "turret", "gripper", g["hinge_m"])
    else:
        bx = g["box_m"]
        colour = "gripper_red" if g["type"] == "sticky" else "arm_grey"
        rb.link("gripper", g["mass_kg"], (bx[0] / 2.0, 0, 0), box_inertia(g["mass_kg"], bx),
                [box(bx, (bx[0] / 2.0, 0, 0), colour=colour)])
        el = g["elevation"]
        rb.joint("gripper_elevation_joint", "revolute", "turret", "gripper", g["hinge_m"],
                 axis=(0, -1, 0), limit={"lower": el["lower_rad"], "upper": el["upper_rad"],
                                         "effort": el["torque_Nm"], "velocity": el["speed_rads"]})
        materials["gripper"] = g["material"]
        gside.update({"elevation_joint": "gripper_elevation_joint",
                      "elevation_lower": el["lower_rad"], "elevation_upper": el["upper_rad"],
                      "elevation_torque": el["torque_Nm"], "elevation_speed": el["speed_rads"],
                      "zero_set_point": el["zero_set_point_rad"],
                      "aperture_max": g["aperture_max_rad"]})
    rb.link("gripper_tip")
    rb.joint("gripper_tip_joint", "fixed", "gripper", "gripper_tip", (g["grip_point_m"], 0, 0))
    if g["type"] == "jaws":
        jw = g["jaws"]
        torque = min(jw["force_N"] * jw["lever_m"], jw.get("servo_torque_max_Nm", float("inf")))
        size = [jw["length_m"], jw["width_m"], jw["thickness_m"]]
        for name, sz, ax in (("gripper_jaw_upper", 1.0, (0, -1, 0)),
                             ("gripper_jaw_lower", -1.0, (0, 1, 0))):
            c = (jw["length_m"] / 2.0, 0, sz * jw["thickness_m"] / 2.0)
            rb.link(name, jw["mass_kg"], c, box_inertia(jw["mass_kg"], size),
                    [box(size, c, colour="gripper_red")])
            rb.joint(name + "_joint", "revolute", "gripper", name,
                     (g["box_m"][0], 0, sz * jw["pivot_z_m"]), axis=ax,
                     limit={"lower": jw["lower_rad"], "upper": jw["upper_rad"], "effort": torque,
                            "velocity": jw["speed_rads"]})
            materials[name] = jw["material"]
        gside.update({"jaw_joints": ["gripper_jaw_upper_joint", "gripper_jaw_lower_joint"],
                      "jaw_speed": jw["speed_rads"], "jaw_force": jw["force_N"],
                      "jaw_torque": torque, "jaw_length": jw["length_m"]})

    # ---- sensor frames (massless, fixed, +x = sensing direction) -----------------------------
    s = p["sensors"]
    turret_sensor_ring(rb, "ir", s["ir"], s["ir_radius_m"])
    gr = s["ground"]
    for i, (x, y) in enumerate(((gr["x_m"], 0), (0, gr["y_m"]), (-gr["x_m"], 0), (0, -gr["y_m"]))):
        rb.link("ground_%d" % i)
        rb.joint("ground_%d_joint" % i, "fixed", "base_link", "ground_%d" % i, (x, y, gr["z_m"]),
                 (0, HALF_PI, 0))
    turret_sensor_ring(rb, "light", s["light"], s["light_radius_m"])
    rb.link("camera")
    rb.joint("camera_joint", "fixed", "turret", "camera", (0, 0, s["camera_z_m"]), (0, HALF_PI, 0))
    rb.link("fake_camera")
    rb.joint("fake_camera_joint", "fixed", "turret", "fake_camera", (0, 0, s["fake_camera_z_m"]))
    turret_sensor_ring(rb, "mic", s["mic"], s["mic"]["radius_m"])

    # ---- side arm -----------------------------------------------------------------------------
    side_arm_side = None
    if p.get("side_arm"):
        side_arm_side = build_side_arm(rb, p["side_arm"], materials)

    # ---- sidecar ----------------------------------------------------------------------------
    sc = {}
    sc["level"] = level
    sc["recommended_step"] = p["recommended_step_s"]
    sc["gravity"] = p["gravity_mps2"]
    sc["treels"] = {
        "left_joints": treels_left,
        "right_joints": treels_right,
        "wheel_radius": center_r,
        "wheel_radii": radii if wheels.get("front_rear") else {},
        "max_torque": tr["max_torque_Nm"],
        "torque_unit": tr["torque_unit_Nm"],
        "speed_unit": tr["speed_unit_mps"],
        "speed_limit_units": tr["speed_limit_units"],
        "max_speed": tr["max_speed_mps"],
        "wheel_effort": effort,
        "gear_ratio": tr["gear_ratio"],
        "rotor_inertia": tr["rotor_inertia_kgm2"],
        "backdrive_force": tr["friction_force_N"],
        "torque_window": tr["torque_window_s"],
        "creep_stiffness": tr.get("creep_stiffness", 0.0),
        "friction_scale": tr.get("friction_scale", 1.0),
        "friction_law": tr.get("friction_law", "coulomb"),
        "friction_force_limit": tr["friction_force_N"],
        "drive": tr.get("drive", "wheels"),
    }
    sc["turret"] = {"joint": "turret_joint", "speed": api["speed_rads"], "unit": api["unit_rad"],
                    "range_units": api["range_units"], "max_torque": api["max_torque_Nm"],
                    "torque_unit": api["torque_unit_Nm"]}
    sc["materials"] = materials
    # model flags first (the keys the core switches on), then the sensor constants
    extra = {k: p["extra"][k] for k in EXTRA_FLAGS if k in p["extra"]}
    extra["dynamical_bodies"] = p["expected_dynamical_bodies"]
    extra.update({k: v for k, v in p["extra"].items() if k not in extra})
    sc["extra"] = extra
    sc["gripper"] = gside
    if side_arm_side:
        sc["side_arm"] = side_arm_side
    return rb, sc


def build_side_arm(rb, a, materials):
    """Scissor side arm (see sbot_description/README.md "Side arm"). Returns the sidecar `side_arm` block."""
    az, s, a0 = a["azimuth_rad"], a["link_length_m"], a["rest_half_angle_rad"]
    lw, lt, lo = a["link_width_m"], a["link_thickness_m"], a["layer_offset_m"]
    mat = a["material"]

    # base: elevation hinge on the turret, frame x = rest direction of the arm (radially outward)
    rb.link("side_arm_base", a["base_mass_kg"], (a["base_box_m"][0] / 2.0, 0, 0),
            box_inertia(a["base_mass_kg"], a["base_box_m"]),
            [box(a["base_box_m"], (a["base_box_m"][0] / 2.0, 0, 0), colour="arm_grey")])
    rb.joint("side_arm_elevation_joint", "revolute", "turret", "side_arm_base",
             (a["mount_radius_m"] * math.cos(az), a["mount_radius_m"] * math.sin(az), a["mount_z_m"]),
             (0, 0, az), axis=(0, -1, 0),
             limit={"lower": a["elevation_lower_rad"], "upper": a["elevation_upper_rad"],
                    "effort": a["elevation_torque_Nm"], "velocity": a["servo_speed_rads"]})
    materials["side_arm_base"] = mat

    def bar(name, length, mass, layer, extra_parts=None):
        size = [length, lw, lt]
        c = (length / 2.0, 0, layer * lo)
        parts = [(mass, list(c), diag(box_inertia(mass, size)))]
        shapes = [box(size, c, colour="arm_grey")]
        if extra_parts:
            for pm, pc, pi, sh in extra_parts:
                parts.append((pm, pc, pi))
                shapes.append(sh)
        m, com, inertia = composite(parts)
        rb.link(name, m, com, inertia, shapes)
        materials[name] = mat

    passive = {"lower": -math.pi, "upper": math.pi, "effort": 0.0, "velocity": 0.0}
    rot = a["rotation_range_rad"]
    lo_open, hi_open = a0 - a["half_angle_min_rad"], a["half_angle_max_rad"] - a0
    px = a["pivot_x_m"]
    # root links (servos): q_l = rotation + (alpha - alpha0), q_r = rotation - (alpha - alpha0)
    bar("side_arm_root_left", s, a["root_mass_kg"], +1)
    rb.joint("side_arm_rotation_left_joint", "revolute", "side_arm_base", "side_arm_root_left",
             (px, 0, 0), (0, 0, a0), axis=(0, 0, 1),
             limit={"lower": -rot - lo_open, "upper": rot + hi_open,
                    "effort": a["horizontal_torque_Nm"], "velocity": a["servo_speed_rads"]})
    bar("side_arm_root_right", s, a["root_mass_kg"], -1)
    rb.joint("side_arm_rotation_right_joint", "revolute", "side_arm_base", "side_arm_root_right",
             (px, 0, 0), (0, 0, -a0), axis=(0, 0, 1),
             limit={"lower": -rot - hi_open, "upper": rot + lo_open,
                    "effort": a["horizontal_torque_Nm"], "velocity": a["servo_speed_rads"]})
    # crossing links (length 2 s) and tip links (length s); (name, parent, parent_len, rel_yaw, layer)
    chain = [
        ("side_arm_cross_1a", "side_arm_root_left", s, -2 * a0, -1, 2 * s, a["cross_mass_kg"]),
        ("side_arm_cross_1b", "side_arm_root_right", s, +2 * a0, +1, 2 * s, a["cross_mass_kg"]),
        ("side_arm_cross_2a", "side_arm_cross_1b", 2 * s, -2 * a0, -1, 2 * s, a["cross_mass_kg"]),
        ("side_arm_cross_2b", "side_arm_cross_1a", 2 * s, +2 * a0, +1, 2 * s, a["cross_mass_kg"]),
        ("side_arm_tip_a", "side_arm_cross_2b", 2 * s, -2 * a0, -1, s, a["tip_mass_kg"]),
        ("side_arm_tip_b", "side_arm_cross_2a", 2 * s, +2 * a0, +1, s, a["tip_mass_kg"]),
    ]
    passive_names = []
    hb = a["head_box_m"]
    R = rot_z(a0)
    head_c = [s + (a["head_gap_m"] + hb[0] / 2.0) * math.cos(a0),
              (a["head_gap_m"] + hb[0] / 2.0) * math.sin(a0), 0.0]
    head_I = mat_mul(mat_mul(R, diag(box_inertia(a["head_mass_kg"], hb))), transpose(R))
    for name, parent, plen, yaw, layer, length, mass in chain:
        extra = None
        if name == "side_arm_tip_a":
            extra = [(a["head_mass_kg"], head_c, head_I,
                      box(hb, head_c, (0, 0, a0), colour="arm_grey"))]
        bar(name, length, mass, layer, extra)
        jn = name + "_joint"
        rb.joint(jn, "revolute", parent, name, (plen, 0, 0), (0, 0, yaw), axis=(0, 0, 1),
                 limit=passive)
        passive_names.append(jn)
    # jaws on the head (part of tip_a), frames aligned with the arm axis at rest
    hend = a["head_gap_m"] + hb[0]
    jsize = [a["jaw_length_m"], a["jaw_width_m"], a["jaw_height_m"]]
    jtorque = a["jaw_force_N"] * a["jaw_lever_m"]
    for name, sy, ax in (("side_arm_jaw_a", 1.0, (0, 0, 1)), ("side_arm_jaw_b", -1.0, (0, 0, -1))):
        off = (hend, sy * a["jaw_pivot_y_m"])
        xyz = (s + off[0] * math.cos(a0) - off[1] * math.sin(a0),
               off[0] * math.sin(a0) + off[1] * math.cos(a0), 0.0)
        c = (a["jaw_length_m"] / 2.0, 0, 0)
        rb.link(name, a["jaw_mass_kg"], c, box_inertia(a["jaw_mass_kg"], jsize),
                [box(jsize, c, colour="gripper_red")])
        rb.joint(name + "_joint", "revolute", "side_arm_tip_a", name, xyz, (0, 0, a0), axis=ax,
                 limit={"lower": a["jaw_lower_rad"], "upper": a["jaw_upper_rad"],
                        "effort": jtorque, "velocity": a["jaw_speed_rads"]})
        materials[name] = a["jaw_material"]
    loops = []
    for name, parent, child in (("side_arm_loop_r1_joint", "side_arm_cross_1a", "side_arm_cross_1b"),
                                ("side_arm_loop_r2_joint", "side_arm_cross_2a", "side_arm_cross_2b"),
                                ("side_arm_loop_tip_joint", "side_arm_tip_a", "side_arm_tip_b")):
        loops.append({"name": name, "type": "revolute", "parent": parent, "child": child,
                      "anchor_in_parent": [s, 0.0, 0.0], "anchor_in_child": [s, 0.0, 0.0],
                      "axis": [0.0, 0.0, 1.0]})
    return {
        "base_link": "side_arm_base",
        "tip_link": "side_arm_tip_a",
        "rest_azimuth": az,
        "servos": {"elevation": "side_arm_elevation_joint",
                   "rotation_left": "side_arm_rotation_left_joint",
                   "rotation_right": "side_arm_rotation_right_joint",
                   "jaw_a": "side_arm_jaw_a_joint", "jaw_b": "side_arm_jaw_b_joint"},
        "passive_joints": passive_names,
        "loop_joints": loops,
        "link_length": s,
        "rhombi": 3,
        "rest_half_angle": a0,
        "half_angle_min": a["half_angle_min_rad"],
        "half_angle_max": a["half_angle_max_rad"],
        "rotation_range": rot,
        "depth_rest": 6.0 * s * math.cos(a0),
        "kinematics": "rotation=(q_left+q_right)/2; half_angle=rest_half_angle+(q_left-q_right)/2; "
                      "depth=2*rhombi*link_length*cos(half_angle); elevation=q_elevation",
        "unit": a["unit_rad"],
        "elevation_torque": a["elevation_torque_Nm"],
        "horizontal_torque": a["horizontal_torque_Nm"],
        "servo_speed": a["servo_speed_rads"],
        "jaw_force": a["jaw_force_N"],
        "jaw_torque": jtorque,
        "jaw_speed": a["jaw_speed_rads"],
        "aperture_max": a["jaw_upper_rad"],
    }


# ------------------------------------------------------------------------------------------------
# Sidecar YAML emitter (hand-written for fixed formatting)
# ------------------------------------------------------------------------------------------------


def scalar(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "null"
    if isinstance(v, (int, float)):
        return fmt(v)
    s = str(v)
    if s == "" or any(ch in s for ch in ":#{}[],&*!|>'\"%@`") or s.lower() in (
            "true", "false", "null", "yes", "no", "on", "off", "~"):
        return "'" + s.replace("'", "''") + "'"
    try:
        float(s)
        return "'" + s + "'"
    except ValueError:
        return s


def flow(v):
    if isinstance(v, dict):
        return "{" + ", ".join("%s: %s" % (k, flow(x)) for k, x in v.items()) + "}"
    if isinstance(v, list):
        return "[" + ", ".join(flow(x) for x in v) + "]"
    return scalar(v)


def emit(node, indent=0):
    pad = "  " * indent
    lines = []
    for k, v in node.items():
        if isinstance(v, dict) and v and any(isinstance(x, (dict, list)) for x in v.values()):
            lines.append("%s%s:" % (pad, k))
            lines.extend(emit(v, indent + 1))
        elif isinstance(v, dict) and len(v) > 6:
            lines.append("%s%s:" % (pad, k))
            lines.extend(emit(v, indent + 1))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            lines.append("%s%s:" % (pad, k))
            for item in v:
                lines.append("%s  - %s" % (pad, flow(item)))
        else:
            lines.append("%s%s: %s" % (pad, k, flow(v)))
    return lines


def sidecar_text(level, sc):
    head = ["# %s.sbot.yaml: GENERATED by sbot_description/scripts/generate_urdf.py from" % level,
            "# config/sbot_parameters.yaml. Do not edit; edit the table and regenerate.",
            "# Simulation semantics of the %s level that URDF cannot express (see README.md)." % level,
            "# Units: SI (m, kg, s, rad, N m); *_units are API integer units."]
    return "\n".join(head + emit(sc)) + "\n"


# ------------------------------------------------------------------------------------------------


def generate(out_dir, levels=None, params=DEFAULT_PARAMS, quiet=False):
    table = load_table(params)
    order = table["levels_order"]
    todo = levels or order
    # The table as written first (the message names where a value is set), then each level as
    # resolved (inherit, derive, override) below.
    for key in ("shared", "levels"):
        check_level(params, table.get(key, {}), key)
    os.makedirs(out_dir, exist_ok=True)
    written = []
    for level in todo:
        if level not in table["levels"]:
            raise SystemExit("unknown level '%s' (known: %s)" % (level, ", ".join(order)))
        p = resolve_level(table, level)
        check_level(params, p, "levels.%s" % level)
        rb, sc = build(level, p)
        header = ["%s.urdf: GENERATED by sbot_description/scripts/generate_urdf.py from" % level,
                  "config/sbot_parameters.yaml. Do not edit; edit the table and regenerate.",
                  p["description"],
                  "Frames: REP-103 (x forward toward the gripper, y left, z up), SI units.",
                  "Simulation semantics (drive joints, units, materials, sensors): %s.sbot.yaml" % level]
        for name, text in (("%s.urdf" % level, rb.to_urdf(header)),
                           ("%s.sbot.yaml" % level, sidecar_text(level, sc))):
            path = os.path.join(out_dir, name)
            with open(path, "w", encoding="utf-8", newline="\n") as fh:
                fh.write(text)
            written.append(path)
            if not quiet:
                print("wrote %s" % path)
    return written


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--quiet", action="store_true", help="do not list the written files")
    ap.add_argument("--level", action="append", help="only this level (repeatable)")
    ap.add_argument("--params", default=DEFAULT_PARAMS, help="parameter table (default: %(default)s)")
    args = ap.parse_args(argv)
    generate(args.out, args.level, args.params, args.quiet)
    return 0


if __name__ == "__main__":
    sys.exit(main())
