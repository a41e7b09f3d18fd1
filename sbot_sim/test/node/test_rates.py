#!/usr/bin/env python3
"""rostest (node_rates.test): the simulator advertises its topics at the expected rates, measured
with sim-time stamps: /clock every step, per-robot state and tf at ~publish_rate (25 Hz here) +-10%,
frame ids without leading slash, latched model levels, and the real-time factor (1 here)."""
import os
import sys
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sbot_msgs.msg import ModelLevel, TrackState, TurretState
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import ROBOTS, STEP, Recorder, yaw_of  # noqa: E402

PUBLISH_RATE = 25.0   # node_rates.test sets ~publish_rate
WINDOW = 2.0          # [s sim] counting window
RECORD_WALL = 3.5     # [s wall] at real_time_factor 1


def count_in_window(stamps, t0, t1):
    return sum(1 for t in stamps if t0 - 1e-6 <= t < t1 - 1e-6)


class TestRates(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_rates')
        cls.clock = Recorder('/clock', Clock)
        cls.tf = Recorder('/tf', TFMessage)
        cls.topics = {}
        for r in ROBOTS:
            cls.topics[(r, 'ground_truth')] = Recorder('/%s/ground_truth' % r, Odometry)
            cls.topics[(r, 'joint_states')] = Recorder('/%s/joint_states' % r, JointState)
            cls.topics[(r, 'track_state')] = Recorder('/%s/track_state' % r, TrackState)
            cls.topics[(r, 'turret/state')] = Recorder('/%s/turret/state' % r, TurretState)
        for rec in [cls.clock, cls.tf] + list(cls.topics.values()):
            rec.wait_connected(timeout=30.0)
        cls.clock.unbounded_queue()
        # Count from a moment when every subscription is connected.
        now = cls.clock.wait_for(lambda m: True, timeout=30.0, what='(simulator not running?)')
        cls.t0 = now.clock.to_sec() + 0.2
        cls.t1 = cls.t0 + WINDOW
        time.sleep(RECORD_WALL)

    def assertRate(self, stamps, what):
        clock_msgs, _ = self.clock.snapshot()
        self.assertGreaterEqual(clock_msgs[-1].clock.to_sec(), self.t1,
                                'the simulation did not cover the counting window')
        n = count_in_window(stamps, self.t0, self.t1)
        expected = WINDOW * PUBLISH_RATE
        self.assertLessEqual(abs(n - expected), 0.1 * expected,
                             '%s: %d messages in %.1f s of sim time, expected %.0f +-10%% (%.0f Hz)'
                             % (what, n, WINDOW, expected, PUBLISH_RATE))

    def test_clock_every_step(self):
        msgs, _ = self.clock.snapshot()
        # From t0 on (every subscription connected, no start-up back-pressure).
        times = [m.clock.to_sec() for m in msgs if m.clock.to_sec() >= self.t0 - 1e-6]
        self.assertGreater(len(times), 100, 'too few /clock messages: %d' % len(times))
        bad = [(a, b - a) for a, b in zip(times, times[1:]) if abs(b - a - STEP) > 1e-6]
        self.assertEqual(bad, [], '/clock must advance by exactly one step (%g s) per message; '
                         'found (time, gap) %s' % (STEP, [(round(t, 3), round(g, 6)) for t, g in bad[:5]]))

    def test_state_topics_at_publish_rate(self):
        for (robot, topic), rec in sorted(self.topics.items()):
            msgs, _ = rec.snapshot()
            self.assertRate([m.header.stamp.to_sec() for m in msgs], '/%s/%s' % (robot, topic))

    def test_tf_at_publish_rate_without_leading_slash(self):
        msgs, _ = self.tf.snapshot()
        for robot in ROBOTS:
            child = '%s/base_link' % robot
            stamps = [t.header.stamp.to_sec() for m in msgs for t in m.transforms
                      if t.child_frame_id == child and t.header.frame_id == 'world']
            self.assertRate(stamps, 'tf world -> %s' % child)
        for m in msgs:
            for t in m.transforms:
                self.assertFalse(t.header.frame_id.startswith('/') or t.child_frame_id.startswith('/'),
                                 'frame ids must not start with a slash: %s -> %s'
                                 % (t.header.frame_id, t.child_frame_id))

    def test_tf_matches_ground_truth(self):
        tf_msgs, _ = self.tf.snapshot()
        odom_msgs, _ = self.topics[('sbot_1', 'ground_truth')].snapshot()
        by_stamp = {m.header.stamp: m.pose.pose for m in odom_msgs}
        matched = 0
        for m in tf_msgs:
            for t in m.transforms:
                if t.child_frame_id != 'sbot_1/base_link' or t.header.stamp not in by_stamp:
                    continue
                p = by_stamp[t.header.stamp]
                self.assertAlmostEqual(t.transform.translation.x, p.position.x, places=9)
                self.assertAlmostEqual(t.transform.translation.y, p.position.y, places=9)
                self.assertAlmostEqual(t.transform.translation.z, p.position.z, places=9)
                self.assertAlmostEqual(abs(t.transform.rotation.x * p.orientation.x +
                                           t.transform.rotation.y * p.orientation.y +
                                           t.transform.rotation.z * p.orientation.z +
                                           t.transform.rotation.w * p.orientation.w), 1.0, places=9)
                matched += 1
        self.assertGreater(matched, 10, 'tf and ground truth share too few stamps')
        # sbot_1 starts at (0, 0.8) facing +y (fixtures/three_robots.yaml).
        p = odom_msgs[-1].pose.pose
        self.assertAlmostEqual(p.position.x, 0.0, delta=0.01)
        self.assertAlmostEqual(p.position.y, 0.8, delta=0.01)
        self.assertAlmostEqual(yaw_of(p.orientation), 1.5707963, delta=0.02)

    def test_ground_truth_frames_and_stamps(self):
        for robot in ROBOTS:
            msgs, _ = self.topics[(robot, 'ground_truth')].snapshot()
            self.assertTrue(msgs, 'no ground truth for %s' % robot)
            for m in msgs:
                self.assertEqual(m.header.frame_id, 'world')
                self.assertEqual(m.child_frame_id, '%s/base_link' % robot)
            stamps = [m.header.stamp.to_sec() for m in msgs]
            self.assertEqual(stamps, sorted(stamps), 'ground truth stamps must increase')
            # Stamps are sim time: multiples of the step.
            for t in stamps:
                self.assertAlmostEqual(t / STEP, round(t / STEP), places=3)

    def test_joint_states_name_the_turret(self):
        msgs, _ = self.topics[('sbot_0', 'joint_states')].snapshot()
        self.assertTrue(msgs)
        m = msgs[-1]
        self.assertEqual(len(m.name), len(m.position))
        self.assertEqual(len(m.name), len(m.velocity))
        self.assertTrue(any('turret' in n for n in m.name), 'joint names: %s' % (m.name,))

    def test_model_level_latched(self):
        for robot in ROBOTS:
            rec = Recorder('/%s/model_level' % robot, ModelLevel)  # subscribed late: latched
            m = rec.wait_for(lambda m: True, timeout=10.0)
            self.assertEqual(m.robot, robot)
            self.assertEqual(m.level, 'simple')

    def test_real_time_factor(self):
        msgs, wall = self.clock.snapshot()
        # Skip the first half second (connection set-up), measure over the rest.
        i0 = next(i for i, w in enumerate(wall) if w >= wall[0] + 0.5)
        sim = msgs[-1].clock.to_sec() - msgs[i0].clock.to_sec()
        dwall = wall[-1] - wall[i0]
        self.assertGreater(dwall, 1.5)
        rtf = sim / dwall
        self.assertTrue(0.8 <= rtf <= 1.2, 'real_time_factor 1 requested, measured %.2f' % rtf)


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_rates', TestRates)
