#!/usr/bin/python3
"""Writes the seed's own published measurements as sbot-dataset/1 datasets (run once; the output is
committed). Sources: Swarmbot3d technical report, sections 2.2.6 / 2.2.7 and Appendix A (sbot.h), and
Table 2.2 / sections 2.4 and 4.1 (1.2 N friction, measured by pulling an s-bot with a force meter).

  seed_ir_response/      IR proximity sensor ir2 facing a white wall head-on at the API's points
                         150 mm -> 20, 50 mm -> 50, 10 mm -> 1000, 5 mm -> 3700 (kind: place)
  seed_ground_response/  the four ground sensors held above the floor at the API's points
                         6 mm -> 1, 2 mm -> 25, 1 mm -> 100 (kind: place, z column)
  seed_traction/         the s-bot with passive tracks pulled forward by a force ramped 0 -> 2 N; it
                         stays put below 1.2 N (kind: drive with the force_x and passive inputs)
Geometry is read from sbot_description/urdf/medium.urdf (ir_2 on the turret, the ground sensors
below base_link), so the datasets follow the model; re-run after changing the parameter table.
"""
import math
import os
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
URDF = os.path.join(HERE, "..", "sbot_description", "urdf", "medium.urdf")


def joint_origin(name):
    """(xyz, rpy) of a joint of the Medium URDF."""
    for j in ET.parse(URDF).getroot().iter("joint"):
        if j.get("name") == name:
            o = j.find("origin")
            return ([float(v) for v in o.get("xyz", "0 0 0").split()],
                    [float(v) for v in o.get("rpy", "0 0 0").split()])
    raise SystemExit("%s: no joint %s" % (URDF, name))


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def ir_response():
    d = os.path.join(HERE, "seed_ir_response")
    os.makedirs(d, exist_ok=True)
    wall_x = 1.0
    (sx0, sy0, _), (_, _, axis) = joint_origin("ir_2_joint")  # turret frame; turret axis at x = y = 0
    yaw = -axis  # sensor axis along +x, toward the wall
    c, s = math.cos(yaw), math.sin(yaw)
    sx, sy = c * sx0 - s * sy0, s * sx0 + c * sy0
    rows = ["x,y,yaw,ir2,_distance_mm"]
    for mm, reading in ((150, 20), (50, 50), (10, 1000), (5, 3700)):
        bx = wall_x - mm / 1000.0 - sx
        by = 0.0 - sy
        rows.append("%.6f,%.6f,%.6f,%d,%d" % (bx, by, yaw, reading, mm))
    write(os.path.join(d, "ir2_head_on.csv"), "\n".join(rows) + "\n")
    write(os.path.join(d, "dataset.yaml"), """# sbot-dataset/1 -- the seed's IR proximity response points (sbot.h, Appendix A; section 2.2.6):
# "20 is 15 cm, 50 is 5 cm, 1000 is 1 cm, 3700 is 0.5 cm". Sensor ir2 faces a white wall head-on at
# those distances (measured along its axis); the other sensors were not reported. Made by
# datasets/make_seed_datasets.py.
format: sbot-dataset/1
name: seed_ir_response
description: IR proximity response points published in the seed (Appendix A, 2.2.6)
robot: medium
world:
  terrain: {type: plane}
  obstacles:
    - {name: calibration_wall, center: [1.01, 0.0, 0.05], size: [0.02, 1.0, 0.1], yaw: 0, surface: white_paper}
noise:
  ir: {abs: 2, rel: 0.1}
runs:
  - {name: ir2_head_on, file: ir2_head_on.csv, kind: place}
""")


def ground_response():
    d = os.path.join(HERE, "seed_ground_response")
    os.makedirs(d, exist_ok=True)
    rows = ["x,y,yaw,z,ground0,ground1,ground2,ground3,_distance_mm"]
    depths = {-joint_origin("ground_%d_joint" % k)[0][2] for k in range(4)}
    if len(depths) != 1:
        raise SystemExit("the ground sensors are not at one height below base_link: %s" % sorted(depths))
    depth = depths.pop()
    for mm, reading in ((6, 1), (2, 25), (1, 100)):
        z = mm / 1000.0 + depth  # base_link height: the sensors sit `depth` below base_link
        rows.append("0,0,0,%.4f,%d,%d,%d,%d,%d" % (z, reading, reading, reading, reading, mm))
    write(os.path.join(d, "held_above_floor.csv"), "\n".join(rows) + "\n")
    write(os.path.join(d, "dataset.yaml"), """# sbot-dataset/1 -- the seed's ground sensor response points (sbot.h, Appendix A; section 2.2.7):
# "1 is 6mm, 25 is 2mm, 100 is 1mm". The robot is held (z column: height of base_link above the floor)
# so that all four ground sensors are at those distances from the floor. Made by
# datasets/make_seed_datasets.py.
format: sbot-dataset/1
name: seed_ground_response
description: ground IR sensor response points published in the seed (Appendix A, 2.2.7)
robot: medium
world:
  terrain: {type: plane}
noise:
  ground: {abs: 1, rel: 0.1}
runs:
  - {name: held_above_floor, file: held_above_floor.csv, kind: place}
""")


def traction():
    d = os.path.join(HERE, "seed_traction")
    os.makedirs(d, exist_ok=True)
    rows = ["t,cmd_left,cmd_right,passive,force_x,force_y,x,y,yaw"]
    # Force ramp 0 -> 2.0 N in 0.1 N steps every 0.5 s; the published fact is that the robot does not
    # move below 1.2 N, so the tracker samples (10 Hz) are at the start pose while F <= 1.1 N.
    t = 0.0
    while t < 10.0 + 1e-9:
        k = int(round(t * 10))
        cells = ["%.1f" % t, "", "", "", "", "", "", "", ""]
        if k == 0:
            cells[1:4] = ["0", "0", "1"]
        if k % 5 == 0:
            cells[4], cells[5] = "%.1f" % (0.1 * (k // 5)), "0"
        if 0.1 * (k // 5) <= 1.1 + 1e-9:
            cells[6:9] = ["0", "0", "0"]
        rows.append(",".join(cells))
        t += 0.1
    write(os.path.join(d, "pull_ramp.csv"), "\n".join(rows) + "\n")
    write(os.path.join(d, "dataset.yaml"), """# sbot-dataset/1 -- the seed's traction figure (Table 2.2 "friction 12e4 dyne", 2.4, 4.1.1: "the
# ground friction ... set to the same value measured in reality (1.2 N)", measured "by pulling one
# s-bot using a force meter"). The robot, tracks passive, is pulled forward with a force ramped from
# 0 to 2 N (0.1 N every 0.5 s); the measurement is that it does not move while the force is below
# 1.2 N (tracker samples at the start pose until then, none after: the speed was not reported).
# Made by datasets/make_seed_datasets.py.
format: sbot-dataset/1
name: seed_traction
description: the 1.2 N pull test of the seed (passive tracks, force meter)
robot: medium
world:
  terrain: {type: plane}
align_initial_pose: false
runs:
  - {name: pull_ramp, file: pull_ramp.csv, kind: drive, initial_pose: {x: 0, y: 0, yaw: 0}}
""")


if __name__ == "__main__":
    ir_response()
    ground_response()
    traction()
