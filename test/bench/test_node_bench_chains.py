#!/usr/bin/python3
"""node_bench.py --chains: the simulator node runs robots linked in chains by static front-gripper
links, the driver moves them, and /swarm/graph reports the chains as swarm-bots at 10 Hz of simulated
time. node_bench.py (recording): the node is timed only once `rosbag record -a` has subscribed to
every topic. Checks what the benchmark line says, not how fast it was (no timing bar in a test)."""
import os
import re
import subprocess
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
TOOL = os.path.join(ROOT, "src", "node_bench.py")


def bench(*args):
    return subprocess.run(["/usr/bin/python3", TOOL] + list(args), capture_output=True, text=True, timeout=240)


class NodeBenchChains(unittest.TestCase):
    def test_ten_robots_in_chains_of_five_are_two_moving_swarm_bots(self):
        r = bench("--chains", "5", "--robots", "10", "--seconds", "3")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        line = [l for l in r.stdout.splitlines() if l.startswith("simple")]
        self.assertEqual(len(line), 1, r.stdout)
        m = re.search(r"simple\s+10\s+3\.0\s+([0-9.]+) .*/swarm/graph: (\d+) messages, ([0-9.]+) Hz of sim time, "
                      r"(\d+) swarm-bots, robots moved ([0-9.]+) m", line[0])
        self.assertIsNotNone(m, line[0])
        rtm, messages, hz, components, moved = float(m.group(1)), int(m.group(2)), float(m.group(3)), int(m.group(4)), float(m.group(5))
        self.assertGreater(rtm, 0)
        self.assertGreaterEqual(messages, 25)      # 10 Hz over 3 s of simulated time
        self.assertAlmostEqual(hz, 10.0, delta=0.5)
        self.assertEqual(components, 2)            # two chains of five, each one swarm-bot
        self.assertGreater(moved, 0.01)            # the driver's commands reached the robots

    def test_recording_is_timed_once_the_recorder_has_every_topic(self):
        r = bench("--robots", "2", "--seconds", "2")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        line = [l for l in r.stdout.splitlines() if l.startswith("simple")]
        self.assertEqual(len(line), 1, r.stdout)
        m = re.search(r"simple\s+2\s+2\.0\s+([0-9.]+) .*recorder subscribed to (\d+) topics in ([0-9.]+) s", line[0])
        self.assertIsNotNone(m, line[0])
        self.assertGreater(float(m.group(1)), 0)
        # Two robots' sensor, state and TF topics (about 24 each, per-IR Range topics included), /clock,
        # /tf and the swarm's: fewer means the gate counted before the node had advertised.
        self.assertGreater(int(m.group(2)), 2 * 20)

    def test_bad_options_are_refused_by_name(self):
        for option, bad in (("--chains", "0"), ("--chains", "x"), ("--seconds", "-1"), ("--seconds", "nan"),
                            ("--robots", "10,a")):
            r = bench(option, bad)
            self.assertEqual(r.returncode, 2, (option, bad))
            self.assertIn(option, r.stderr)
            self.assertIn(repr(bad), r.stderr)


if __name__ == "__main__":
    unittest.main()
