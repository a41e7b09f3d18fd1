#!/usr/bin/python3
"""Convert recorded rosbags into a measurement dataset (format sbot-dataset/1, docs/calibration.md).

    rosrun swarmbot3d bag_to_dataset.py OUT_DIR BAG [BAG ...] [options]

Each bag becomes one `drive` run (named after the bag file, or --run-name for a single bag). Read,
per robot namespace ROBOT (--robot, default sbot_0), with every topic overridable:

  commands   /ROBOT/cmd_speed    sbot_msgs/TrackSpeed (left, right) -> cmd_left, cmd_right
  tracker    /ROBOT/ground_truth nav_msgs/Odometry, or geometry_msgs/PoseStamped | Pose2D |
                                 PoseWithCovarianceStamped (e.g. an overhead camera) -> x, y, yaw
  tracks     /ROBOT/track_state  sbot_msgs/TrackState -> speed_left/right, torque_left/right
  slope      /ROBOT/slope        sbot_msgs/Slope (deg) -> pitch, roll (rad)
  proximity  /ROBOT/proximity    sbot_msgs/ProximityArray -> ir0..ir14
  ground     /ROBOT/ground       sbot_msgs/GroundArray -> ground0..ground3
  light      /ROBOT/light        sbot_msgs/LightArray -> light0..light7

Time stamps come from message headers when present (bag time otherwise) and are relative to the
earliest stamp of the run (not the first message read: a tracker whose header stamps lead the
commands would otherwise get negative times). Topics that are absent are simply not measured. The start pose is the
first tracker pose. The world (obstacles, lamps) is copied from --world (a YAML file with the
dataset's `world:` mapping) and the model level from --level. With --append, runs are added to an
existing dataset: of its level and world (a --level or --world that differs is refused). Message classes are taken from the bag itself, so the workspace need not be sourced.
"""
import argparse
import math
import os
import sys

import rosbag
import yaml


def quat_yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def stamp_of(msg, bag_time):
    h = getattr(msg, "header", None)
    if h is not None and (h.stamp.secs or h.stamp.nsecs):
        return h.stamp.to_sec()
    return bag_time.to_sec()


def tracker_pose(msg):
    """(x, y, yaw) from the supported tracker message types, None if unsupported."""
    t = msg._type
    if t == "nav_msgs/Odometry":
        p = msg.pose.pose
    elif t == "geometry_msgs/PoseWithCovarianceStamped":
        p = msg.pose.pose
    elif t == "geometry_msgs/PoseStamped":
        p = msg.pose
    elif t == "geometry_msgs/Pose":
        p = msg
    elif t == "geometry_msgs/Pose2D":
        return msg.x, msg.y, msg.theta
    else:
        return None
    return p.position.x, p.position.y, quat_yaw(p.orientation)


# The message type each topic must have (the tracker: any type tracker_pose reads).
TOPIC_TYPES = {"commands": "sbot_msgs/TrackSpeed", "tracks": "sbot_msgs/TrackState", "slope": "sbot_msgs/Slope",
               "proximity": "sbot_msgs/ProximityArray", "ground": "sbot_msgs/GroundArray",
               "light": "sbot_msgs/LightArray"}


def read_run(bag_path, topics):
    """Rows {t: {column: value}} of one bag, t from the run's earliest stamp."""
    stamped = {}  # absolute stamp -> {column: value}
    first_pose = None  # (stamp, pose) of the earliest tracker message
    wanted = [t for t in topics.values() if t]
    with rosbag.Bag(bag_path) as bag:
        info = bag.get_type_and_topic_info().topics
        present = set(info.keys())
        missing = [k for k, t in topics.items() if t and t not in present]
        for key, expected in TOPIC_TYPES.items():
            topic = topics.get(key)
            if topic in info and info[topic].msg_type != expected:
                raise SystemExit("%s: topic %s has type %s, expected %s (or name another with --%s-topic)"
                                 % (bag_path, topic, info[topic].msg_type, expected, key))
        for topic, msg, bt in bag.read_messages(topics=wanted):
            t = stamp_of(msg, bt)
            row = stamped.setdefault(t, {})
            if topic == topics["commands"]:
                row["cmd_left"], row["cmd_right"] = msg.left, msg.right
            elif topic == topics["tracker"]:
                pose = tracker_pose(msg)
                if pose is None:
                    raise SystemExit("%s: tracker topic %s has unsupported type %s" % (bag_path, topic, msg._type))
                if not all(math.isfinite(v) for v in pose):
                    raise SystemExit("%s: tracker topic %s: message at t = %.6f s has a pose that is not finite (%s)"
                                     % (bag_path, topic, t, ", ".join("%g" % v for v in pose)))
                row["x"], row["y"], row["yaw"] = pose
                if first_pose is None or t < first_pose[0]:
                    first_pose = (t, pose)
            elif topic == topics["tracks"]:
                row["speed_left"], row["speed_right"] = msg.measured_left, msg.measured_right
                row["torque_left"], row["torque_right"] = msg.torque_left, msg.torque_right
            elif topic == topics["slope"]:
                row["pitch"], row["roll"] = math.radians(msg.pitch), math.radians(msg.roll)
            elif topic == topics["proximity"]:
                for k, v in enumerate(msg.readings):
                    row["ir%d" % k] = v
            elif topic == topics["ground"]:
                for k, v in enumerate(msg.readings):
                    row["ground%d" % k] = v
            elif topic == topics["light"]:
                for k, v in enumerate(msg.readings):
                    row["light%d" % k] = v
    rows = {}
    t0 = min(stamped) if stamped else 0.0
    for t in sorted(stamped):
        rows.setdefault(round(t - t0, 6), {}).update(stamped[t])
    return rows, (first_pose[1] if first_pose else None), missing


LEVELS = ["fast", "simple", "basic", "medium", "detailed"]  # the model levels (sbot::modelLevels)


def read_world(path):
    """The `world:` mapping of a --world file (or the file itself as that mapping); SystemExit naming
    the file when it cannot be read or holds something else."""
    try:
        with open(path) as f:
            w = yaml.safe_load(f)
    except OSError as error:
        raise SystemExit("bag_to_dataset: --world: cannot read %s: %s" % (path, error.strerror))
    except yaml.YAMLError as error:
        raise SystemExit("bag_to_dataset: --world %s: not valid YAML: %s" % (path, error))
    if isinstance(w, dict) and "world" in w:
        w = w["world"]
    if not isinstance(w, dict):
        raise SystemExit("bag_to_dataset: --world %s: expected the dataset's world mapping (terrain, obstacles, "
                         "lamps ...), found %s" % (path, "nothing" if w is None else type(w).__name__))
    return w


ORDER = ["cmd_left", "cmd_right", "x", "y", "yaw", "speed_left", "speed_right", "torque_left", "torque_right",
         "pitch", "roll"] + ["ir%d" % k for k in range(15)] + ["ground%d" % k for k in range(4)] + \
        ["light%d" % k for k in range(8)]


def write_csv(path, rows, final):
    """The run's CSV at `path` (to become `final`, which messages name); returns its columns.
    SystemExit when the rows hold no drive run."""
    cols = [c for c in ORDER if any(c in r for r in rows.values())]
    if "cmd_left" not in cols:
        raise SystemExit("%s: no command messages: a drive run needs the command topic" % final)
    measured = [c for c in cols if c not in ("cmd_left", "cmd_right")]
    if not measured:
        raise SystemExit("%s: nothing measured (no tracker, track state or sensor topic in the bag)" % final)
    with open(path, "w") as f:
        f.write("t," + ",".join(cols) + "\n")
        for t in sorted(rows):
            r = rows[t]
            cells = []
            for c in cols:
                v = r.get(c)
                cells.append("" if v is None else ("%.10g" % v))
            # commands are given as a pair or not at all
            f.write("%.6f," % t + ",".join(cells) + "\n")
    return cols


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", help="dataset directory (created)")
    p.add_argument("bags", nargs="+", help="bag files, one run each")
    p.add_argument("--robot", default="sbot_0", help="robot namespace (default sbot_0)")
    p.add_argument("--level", default=None, choices=LEVELS,
                   help="model level of the dataset (default medium; with --append, the dataset's)")
    p.add_argument("--name", default=None, help="dataset name (default: the directory name)")
    p.add_argument("--run-name", default=None, help="run name (single bag only)")
    p.add_argument("--world", default=None, help="YAML file with the dataset's world mapping")
    p.add_argument("--append", action="store_true", help="add the runs to an existing dataset")
    for key, default in (("commands", "cmd_speed"), ("tracker", "ground_truth"), ("tracks", "track_state"),
                         ("slope", "slope"), ("proximity", "proximity"), ("ground", "ground"), ("light", "light")):
        p.add_argument("--%s-topic" % key, default=None,
                       help="%s topic (default /ROBOT/%s; 'none' to ignore)" % (key, default))
    a = p.parse_args(argv)
    defaults = {"commands": "cmd_speed", "tracker": "ground_truth", "tracks": "track_state", "slope": "slope",
                "proximity": "proximity", "ground": "ground", "light": "light"}
    topics = {}
    for k, d in defaults.items():
        v = getattr(a, "%s_topic" % k)
        topics[k] = None if v == "none" else (v or "/%s/%s" % (a.robot, d))
    if a.run_name and len(a.bags) > 1:
        raise SystemExit("--run-name needs a single bag")

    yaml_path = os.path.join(a.out, "dataset.yaml")
    if a.append and os.path.exists(yaml_path):
        ds = read_existing(yaml_path)
        # One dataset is one robot in one world: runs of another level, or a world that would be
        # applied to the runs already there, are refused rather than mixed in.
        if a.level and a.level != ds.get("robot"):
            raise SystemExit("bag_to_dataset: --append: %s is a dataset of level '%s', not --level %s; import into "
                             "another directory" % (yaml_path, ds.get("robot"), a.level))
        if a.world and read_world(a.world) != ds.get("world"):
            raise SystemExit("bag_to_dataset: --append: --world %s differs from the world of %s, which its runs were "
                             "measured in; import into another directory" % (a.world, yaml_path))
    else:
        ds = {"format": "sbot-dataset/1", "name": a.name or os.path.basename(os.path.abspath(a.out)),
              "description": "imported from rosbag by bag_to_dataset.py", "robot": a.level or "medium",
              "world": {"terrain": {"type": "plane"}}, "runs": []}
        if a.world:
            ds["world"] = read_world(a.world)
    # Read every bag before writing anything: an unreadable bag stops the import with its name and
    # leaves the output directory as it was (no CSV without its dataset.yaml entry).
    imported = []
    for bag in a.bags:
        try:
            rows, pose, missing = read_run(bag, topics)
        except Exception as error:  # rosbag raises several unrelated types for unreadable files
            # What rosbag's own words leave out for the two commonest cases (a cut-off recording, not a bag).
            hint = {"ROSBagUnindexedException": " (a recording cut off: `rosbag reindex` repairs it)",
                    "UnicodeDecodeError": " (not a rosbag)"}.get(type(error).__name__, "")
            raise SystemExit("bag_to_dataset: cannot read %s: %s%s" % (bag, error, hint))
        if not rows:
            raise SystemExit("%s: none of the topics %s is in the bag" % (bag, sorted(t for t in topics.values() if t)))
        imported.append((bag, rows, pose, missing))
    try:
        os.makedirs(a.out, exist_ok=True)
    except OSError as error:  # e.g. a file in the way, or a read-only place: name it, no traceback
        raise SystemExit("bag_to_dataset: cannot create the dataset directory %s: %s" % (a.out, error.strerror))
    try:
        write_dataset(a, ds, imported, yaml_path)
    except OSError as error:
        raise SystemExit("bag_to_dataset: cannot write %s: %s" % (error.filename or a.out, error.strerror))
    return 0


def read_existing(yaml_path):
    """The dataset.yaml that --append adds to; SystemExit naming it when it is not one."""
    try:
        with open(yaml_path) as f:
            ds = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as error:
        raise SystemExit("bag_to_dataset: --append: cannot read %s: %s" % (yaml_path, error))
    if not isinstance(ds, dict) or not isinstance(ds.get("runs"), list):
        raise SystemExit("bag_to_dataset: --append: %s is not a dataset (a mapping with a 'runs' list)" % yaml_path)
    for k, run in enumerate(ds["runs"]):
        if not isinstance(run, dict) or not isinstance(run.get("name"), str):
            raise SystemExit("bag_to_dataset: --append: %s: runs[%d] is not a run (a mapping with a name, file, kind "
                             "and initial_pose)" % (yaml_path, k))
    return ds


def write_dataset(a, ds, imported, yaml_path):
    """The runs' CSVs and dataset.yaml (appending to `ds`); OSError when a file cannot be written.
    Every file is written under a temporary name and renamed only when all of them are complete:
    a full disk or a refused run leaves the dataset as it was (an append that failed half-way used
    to leave a truncated dataset.yaml, losing the index of the runs already there)."""
    pending = []  # (temporary, final) paths
    try:
        write_dataset_files(a, ds, imported, yaml_path, pending)
        for temporary, final in pending:
            os.replace(temporary, final)
    finally:
        for temporary, _ in pending:
            if os.path.exists(temporary):
                os.remove(temporary)
    sys.stdout.write("wrote %s (%d runs)\n" % (yaml_path, len(ds["runs"])))


def write_dataset_files(a, ds, imported, yaml_path, pending):
    names = {r["name"] for r in ds["runs"]}
    for bag, rows, pose, missing in imported:
        name = a.run_name or os.path.splitext(os.path.basename(bag))[0]
        base, k = name, 2
        while name in names:
            name = "%s_%d" % (base, k)
            k += 1
        final = os.path.join(a.out, name + ".csv")
        pending.append((final + ".part", final))
        cols = write_csv(final + ".part", rows, final)
        run = {"name": name, "file": name + ".csv", "kind": "drive",
               "initial_pose": {"x": pose[0], "y": pose[1], "yaw": pose[2]} if pose else {"x": 0.0, "y": 0.0, "yaw": 0.0}}
        ds["runs"].append(run)
        names.add(name)
        sys.stdout.write("%s -> %s.csv: %d rows, columns %s%s\n" % (
            bag, name, len(rows), ",".join(cols),
            ("; topics not in the bag: " + ", ".join(missing)) if missing else ""))
        if pose is None:
            sys.stdout.write("  warning: no tracker pose: initial_pose set to 0, 0, 0\n")
    pending.append((yaml_path + ".part", yaml_path))
    with open(yaml_path + ".part", "w") as f:
        f.write("# sbot-dataset/1 (see docs/calibration.md)\n")
        yaml.safe_dump(ds, f, default_flow_style=None, sort_keys=False)


if __name__ == "__main__":
    sys.exit(main())
