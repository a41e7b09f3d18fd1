#!/usr/bin/env python3
"""Benchmark the simulator node with its topics (the ROS counterpart of sbot_bench).

    rosrun swarmbot3d node_bench.py [--robots 1,10,100] [--seconds 10]

For each robot count it starts its own ROS master on a free port, runs simulator_node on
config/scenarios/bench_flat.yaml for `seconds` of simulated time while `rosbag record` subscribes
to every topic but the raw camera images (so every sensor is computed and every message serialised
and sent), and prints the real-time multiplier
(simulated s / wall s), wall time per step and the node's peak resident memory.
"""
import argparse
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time

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


def run(robots, seconds, scenario):
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI='http://127.0.0.1:%d' % port)
    devnull = subprocess.DEVNULL
    master = subprocess.Popen(['rosmaster', '--core', '-p', str(port)], env=env, stdout=devnull, stderr=devnull)
    tmp = tempfile.mkdtemp(prefix='node_bench_')
    try:
        time.sleep(1.0)
        subprocess.check_call(['rosparam', 'set', '/use_sim_time', 'true'], env=env)
        # Every topic but the raw camera images by default: those are ray-cast in software for every
        # subscribed robot (~12 ms per frame each). NODE_BENCH_EXCLUDE sets another exclusion regex.
        exclude = os.environ.get('NODE_BENCH_EXCLUDE', '.*/camera/image_raw.*')
        recorder = subprocess.Popen(['rosbag', 'record', '-a', '-x', exclude, '-q',
                                     '-O', os.path.join(tmp, 'b.bag')],
                                    env=env, stdout=devnull, stderr=devnull, start_new_session=True)
        time.sleep(1.0)
        log_path = os.path.join(tmp, 'node.log')
        with open(log_path, 'w') as log:
            node = subprocess.Popen(['rosrun', 'sbot_sim', 'simulator_node', '_scenario:=' + scenario,
                                     '_robots:=%d' % robots, '_duration:=%g' % seconds, '_real_time_factor:=0'],
                                    env=env, stdout=log, stderr=subprocess.STDOUT)
            peak = 0.0
            while node.poll() is None:
                peak = max(peak, peak_rss_mib(node.pid))
                time.sleep(0.05)
        # `rosbag record` runs the recorder as a child process: interrupt the whole group (SIGINT
        # closes the bag), or the child outlives the benchmark and loads the next rows.
        os.killpg(recorder.pid, signal.SIGINT)
        recorder.wait()
        # The node's own summary times the stepping loop (start-up and spawning excluded).
        with open(log_path) as log:
            match = re.search(r'wall time ([0-9.]+) s \(([0-9.]+) s paused\)', log.read())
        wall = float(match.group(1)) - float(match.group(2)) if match else float('nan')
        return node.returncode, wall, peak
    finally:
        master.terminate()
        master.wait()
        subprocess.call(['rm', '-rf', tmp])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--robots', default='1,10,100')
    parser.add_argument('--seconds', type=float, default=20.0)
    args = parser.parse_args()
    scenario = os.path.join(rospkg.RosPack().get_path('swarmbot3d'), 'config', 'scenarios', 'bench_flat.yaml')
    print('node_bench: simulator_node + rosbag record -a (raw camera images excluded), flat arena, idle robots')
    print('%-8s %7s %10s %12s %14s %12s' % ('level', 'robots', 'sim_s', 'RTM', 'wall_ms/step', 'peak_MiB'))
    failures = 0
    for n in [int(x) for x in args.robots.split(',')]:
        code, wall, peak = run(n, args.seconds, scenario)
        if code != 0:
            failures += 1
            print('%-8s %7d  simulator_node exited with %d' % ('simple', n, code))
            continue
        print('%-8s %7d %10.1f %12.1f %14.3f %12.1f' % ('simple', n, args.seconds, args.seconds / wall,
                                                       1000.0 * wall / (args.seconds / 0.01), peak))
        sys.stdout.flush()
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
