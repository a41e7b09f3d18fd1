#!/usr/bin/env python3
"""Benchmark the simulator node with its topics (the ROS counterpart of sbot_bench).

    rosrun swarmbot3d node_bench.py [--robots 1,10,100] [--seconds 10] [--compact]
    rosrun swarmbot3d node_bench.py --chains 5 [--robots 100] [--seconds 20]

For each robot count it starts its own ROS master on a free port, runs simulator_node on
config/scenarios/bench_flat.yaml for `seconds` of simulated time while `rosbag record` subscribes
to every topic but the raw camera images (so every sensor is computed and every message serialised
and sent), and prints the real-time multiplier
(simulated s / wall s), wall time per step and the node's peak resident memory. The node starts
paused and runs once the recorder has subscribed to every topic it publishes (with 100 robots that
takes seconds, a one-off cost a long recording does not pay again): the row times recording in its
steady state, and its last column says how long the subscribing took. --compact runs the node
with ~per_sensor_topics false (the sensor arrays without the 23 per-sensor topics of each robot).

--chains K (issue "Scale", seed 2.3): the robots stand in chains of K linked by static front-gripper
links (scenario `links:`), headless and unrecorded; a driver node sends every chain one random
command per simulated second on the robots' cmd_speed topics (all members the same, as sbot_bench
--chains does) and counts the /swarm/graph messages (published at the node's default 10 Hz) and the
swarm-bots (connected components) they report.
"""
import argparse
import json
import math
import os
import random
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time

import rosgraph
import rospkg


def free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def peak_rss_mib(pid):
    try:
        with open('/proc/%d/status' % pid) as f:
            for line in f:
                if line.startswith('VmHWM:'):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float('nan')


CHAIN_PITCH = 0.147  # [m] centre distance of two s-bots linked by the front gripper (docs/swarm.md)


def chain_scenario(robots, k, path):
    """A walled flat arena with `robots` Simple s-bots in chains of `k` (sbot_<i+1> holds sbot_<i>),
    the chains on a grid of cells as sbot_bench --chains lays them out."""
    chains = (robots + k - 1) // k
    side = max(1, math.ceil(math.sqrt(chains)))
    dx, dy = CHAIN_PITCH * k + 0.3, 0.35
    arena = max(side * dx, side * dy) + 1.0
    lines = ['name: node_bench_chains', 'seed: 1', 'duration: 0', 'world:', '  step: 0.01', '  terrain:',
             '    type: plane', '    arena: {size: %.3f, height: 0.1, surface: wall}' % arena, 'robots:']
    links = []
    for i in range(robots):
        c, j = divmod(i, k)  # chain c, member j (j = 0 leads, at the front)
        cx = (c % side - (side - 1) / 2.0) * dx + CHAIN_PITCH * (k - 1) / 2.0
        cy = (c // side - (side - 1) / 2.0) * dy
        lines.append('  - {name: sbot_%d, level: simple, pose: {x: %.4f, y: %.4f, yaw: 0.0}}' % (i, cx - CHAIN_PITCH * j, cy))
        if j > 0:
            links.append('  - {holder: sbot_%d, held: sbot_%d, kind: front_gripper}' % (i, i - 1))
    with open(path, 'w') as f:
        f.write('\n'.join(lines + (['links:'] + links if links else [])) + '\n')


def drive_chains(robots, k, stats_path):
    """The driver node (a child process): one random command per chain and simulated second; counts
    /swarm/graph messages. Writes its counts to `stats_path` when interrupted."""
    import rospy
    from sbot_msgs.msg import SwarmGraph, TrackSpeed
    from sbot_msgs.srv import Step
    from std_srvs.srv import Trigger
    rospy.init_node('node_bench_driver', disable_signals=True)
    pubs = [rospy.Publisher('/sbot_%d/cmd_speed' % i, TrackSpeed, queue_size=1) for i in range(robots)]
    stats = {'graphs': 0, 'first': None, 'last': None, 'components': None, 'moved': 0.0}
    positions = {}  # 'first' and 'last' graph: robot name -> (x, y)

    def on_graph(msg):
        t = msg.header.stamp.to_sec()
        stats['graphs'] += 1
        stats['first'] = t if stats['first'] is None else stats['first']
        stats['last'] = t
        stats['components'] = len(set(msg.component))
        xy = {name: (p.x, p.y) for name, p in zip(msg.names, msg.positions)}
        positions.setdefault('first', xy)
        positions['last'] = xy

    graph = rospy.Subscriber('/swarm/graph', SwarmGraph, on_graph, queue_size=100)
    rng = random.Random(1)

    def command(_event):
        for c in range(0, robots, k):
            cmd = TrackSpeed(left=rng.randint(-70, 70), right=rng.randint(-70, 70))
            for i in range(c, min(c + k, robots)):
                pubs[i].publish(cmd)

    # The node starts paused (node_bench passes ~paused): unpause once every command topic and the
    # graph are connected, or a fast run would be over before the first command arrives.
    rospy.wait_for_service('/sim/step')
    rospy.ServiceProxy('/sim/step', Step)(1)  # t = one step: rospy's sim-time timers need a non-zero clock
    deadline = time.time() + 60
    while time.time() < deadline and (any(p.get_num_connections() < 1 for p in pubs) or graph.get_num_connections() < 1):
        time.sleep(0.05)
    rospy.Timer(rospy.Duration(1.0), command)
    command(None)  # the first command at t = 0
    rospy.wait_for_service('/sim/unpause')
    rospy.ServiceProxy('/sim/unpause', Trigger)()
    try:
        while not rospy.is_shutdown():
            time.sleep(0.1)
    except KeyboardInterrupt:
        pass
    if positions:
        first, last = positions['first'], positions['last']
        moved = [math.dist(first[n], last[n]) for n in last if n in first]
        stats['moved'] = sum(moved) / len(moved) if moved else 0.0
    with open(stats_path, 'w') as f:
        json.dump(stats, f)


def gate_on_recorder(exclude, stats_path):
    """The recorder's gate (a child process): the node starts paused; step it until the recorder
    starts (`rosbag record` waits for a sim clock message before it subscribes), wait until it has
    registered a subscription to every topic the simulator publishes but the excluded ones and the
    node reports a live link to it on each, then unpause. Writes the topic count and the seconds
    the subscribing took to `stats_path`."""
    import rospy
    from sbot_msgs.srv import Step
    from std_srvs.srv import Trigger
    rospy.init_node('node_bench_gate', anonymous=True, disable_signals=True)
    rospy.wait_for_service('/sim/step')
    start = time.time()
    deadline = start + 120
    ours, missing = [], []
    try:
        readiness, master = start_when_ready(), rosgraph.Master(rospy.get_name())
        ours, missing = wait_recorder_subscribed(readiness, master, exclude, Step, deadline)
        # Registration precedes the TCP connection: wait until the node reports a live link to the
        # recorder on every topic, with the check swarm.launch's start_when_ready uses.
        needed = {t: 1 for t in ours}
        while time.time() < deadline and readiness.not_ready(master, needed):
            time.sleep(0.2)
    finally:  # whatever happened, the paused node must run (and end), or the benchmark hangs
        connected = time.time() - start
        rospy.ServiceProxy('/sim/unpause', Trigger)()
    with open(stats_path, 'w') as f:
        json.dump({'topics': len(ours), 'missing': len(missing), 'connect_s': connected}, f)


def start_when_ready():
    """The start_when_ready.py beside this file, as a module (its readiness checks)."""
    import importlib.util
    path = os.path.join(os.path.dirname(os.path.realpath(__file__)), 'start_when_ready.py')
    spec = importlib.util.spec_from_file_location('start_when_ready', path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def wait_recorder_subscribed(readiness, master, exclude, step_srv, deadline):
    """Steps the paused node until the recorder starts, and polls the master (start_when_ready's
    `registrations`) until the recorder subscribes to every topic the simulator publishes but the
    excluded ones (or the deadline). Returns those topics and the ones still missing."""
    import rospy
    step = rospy.ServiceProxy('/sim/step', step_srv)
    excluded = re.compile(exclude)
    ours, missing = [], []
    while time.time() < deadline:
        publishers, subscribed = readiness.registrations(master)
        ours = [t for t, nodes in publishers.items() if '/simulator' in nodes and not excluded.fullmatch(t)]
        missing = [t for t in ours if not any(n.startswith('/record') for n in subscribed.get(t, []))]
        if ours and not missing:
            break
        if set(ours) - set(missing) <= {'/clock'}:
            # The recorder has not started: it waits for a clock message, which it may have missed
            # (one per step, and it connects when it connects). A step per poll until it starts.
            step(1)
        time.sleep(0.2)
    return ours, missing


def run(robots, seconds, scenario, chains=0, per_sensor_topics=True):
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI='http://127.0.0.1:%d' % port)
    devnull = subprocess.DEVNULL
    master = subprocess.Popen(['rosmaster', '--core', '-p', str(port)], env=env, stdout=devnull, stderr=devnull)
    tmp = tempfile.mkdtemp(prefix='node_bench_')
    stats = None
    try:
        time.sleep(1.0)
        subprocess.check_call(['rosparam', 'set', '/use_sim_time', 'true'], env=env)
        if chains:
            scenario = os.path.join(tmp, 'chains.yaml')
            chain_scenario(robots, chains, scenario)
            stats_path = os.path.join(tmp, 'driver.json')
            listener = subprocess.Popen([sys.executable, os.path.realpath(__file__), '--_driver', stats_path,
                                         '--robots', str(robots), '--chains', str(chains)],
                                        env=env, stdout=devnull, stderr=devnull, start_new_session=True)
        else:
            # Every topic but the raw camera images by default: those are ray-cast in software for
            # every subscribed robot (~12 ms per frame each). NODE_BENCH_EXCLUDE sets another regex.
            exclude = os.environ.get('NODE_BENCH_EXCLUDE', '.*/camera/image_raw.*')
            listener = subprocess.Popen(['rosbag', 'record', '-a', '-x', exclude, '-q',
                                         '-O', os.path.join(tmp, 'b.bag')],
                                        env=env, stdout=devnull, stderr=devnull, start_new_session=True)
            stats_path = os.path.join(tmp, 'gate.json')
            gate = subprocess.Popen([sys.executable, os.path.realpath(__file__), '--_gate', stats_path,
                                     '--_exclude', exclude], env=env, stdout=devnull, stderr=devnull)
        time.sleep(1.0)
        log_path = os.path.join(tmp, 'node.log')
        with open(log_path, 'w') as log:
            node = subprocess.Popen(['rosrun', 'sbot_sim', 'simulator_node', '_scenario:=' + scenario,
                                     '_robots:=%d' % robots, '_duration:=%g' % seconds, '_real_time_factor:=0',
                                     '_paused:=true',  # the driver or the recorder's gate unpauses
                                     '_per_sensor_topics:=%s' % ('true' if per_sensor_topics else 'false')],
                                    env=env, stdout=log, stderr=subprocess.STDOUT)
            peak = 0.0
            while node.poll() is None:
                peak = max(peak, peak_rss_mib(node.pid))
                if not chains and gate.poll() not in (None, 0):  # no gate, no unpause: stop the paused node
                    node.terminate()
                time.sleep(0.05)
        # The listener (`rosbag record`, whose recorder is a child process, or the chain driver):
        # interrupt the whole group (SIGINT closes the bag; the driver writes its counts), or a child
        # outlives the benchmark and loads the next rows.
        os.killpg(listener.pid, signal.SIGINT)
        listener.wait()
        if not chains and gate.poll() is None:  # the node ended before the gate unpaused it
            gate.kill()
            gate.wait()
        if os.path.exists(stats_path):
            with open(stats_path) as f:
                stats = json.load(f)
        # The node's own summary times the stepping loop (start-up and spawning excluded).
        with open(log_path) as log:
            match = re.search(r'wall time ([0-9.]+) s \(([0-9.]+) s paused\)', log.read())
        wall = float(match.group(1)) - float(match.group(2)) if match else float('nan')
        return node.returncode, wall, peak, stats
    finally:
        master.terminate()
        master.wait()
        subprocess.call(['rm', '-rf', tmp])


def positive_int(text):
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError('expected a whole number >= 1, found %r' % text)
    return value


def positive_seconds(text):
    try:
        value = float(text)
    except ValueError:
        value = float('nan')
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError('expected simulated seconds > 0, found %r' % text)
    return value


def robot_counts(text):
    try:
        counts = [positive_int(x) for x in text.split(',')]
    except ValueError:
        raise argparse.ArgumentTypeError('expected robot counts like 1,10,100, found %r' % text)
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--robots', type=robot_counts, default=None, help='robot counts (default 1,10,100; 100 with --chains)')
    parser.add_argument('--seconds', type=positive_seconds, default=20.0)
    parser.add_argument('--chains', type=positive_int, default=0, help='robots per chain (static front-gripper links)')
    parser.add_argument('--compact', action='store_true',
                        help='~per_sensor_topics false: no proximity/ir_<k> or light/sensor_<k> topics')
    parser.add_argument('--_driver', help=argparse.SUPPRESS)
    parser.add_argument('--_gate', help=argparse.SUPPRESS)
    parser.add_argument('--_exclude', help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args._driver:
        drive_chains(args.robots[0], args.chains, args._driver)
        return 0
    if args._gate:
        gate_on_recorder(args._exclude, args._gate)
        return 0
    counts = args.robots or ([100] if args.chains else [1, 10, 100])
    scenario = os.path.join(rospkg.RosPack().get_path('swarmbot3d'), 'config', 'scenarios', 'bench_flat.yaml')
    if args.chains:
        print('node_bench: simulator_node, chains of %d (static front-gripper links), one random command per chain '
              'and second, /swarm/graph at 10 Hz, nothing recorded' % args.chains)
    else:
        print('node_bench: simulator_node%s + rosbag record -a (raw camera images excluded), flat arena, idle robots; '
              'timed from the recorder subscribed to every topic' % (' (~per_sensor_topics false)' if args.compact else ''))
    print('%-8s %7s %10s %12s %14s %12s' % ('level', 'robots', 'sim_s', 'RTM', 'wall_ms/step', 'peak_MiB'))
    failures = 0
    for n in counts:
        code, wall, peak, stats = run(n, args.seconds, scenario, args.chains, not args.compact)
        if code != 0:
            failures += 1
            print('%-8s %7d  simulator_node exited with %d' % ('simple', n, code))
            continue
        line = '%-8s %7d %10.1f %12.1f %14.3f %12.1f' % ('simple', n, args.seconds, args.seconds / wall,
                                                         1000.0 * wall / (args.seconds / 0.01), peak)
        if args.chains:
            if stats and stats['graphs'] > 1:
                span = stats['last'] - stats['first']
                line += '   /swarm/graph: %d messages, %.1f Hz of sim time, %d swarm-bots, robots moved %.2f m on average' % (
                    stats['graphs'], (stats['graphs'] - 1) / span if span > 0 else float('nan'), stats['components'],
                    stats['moved'])
            else:
                failures += 1
                line += '   /swarm/graph: no messages received'
        elif stats and stats['missing'] == 0:
            line += '   recorder subscribed to %d topics in %.1f s' % (stats['topics'], stats['connect_s'])
        else:
            failures += 1
            line += '   the recorder missed %s of the topics' % (stats['missing'] if stats else 'all')
        print(line)
        sys.stdout.flush()
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
