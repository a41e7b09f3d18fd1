#!/usr/bin/env python3
"""rostest (node_sim_services.test): the /sim/* control services. Calls naming an unknown robot, or
holding non-finite values, fail cleanly with a clear message and the node keeps running; /sim/step
works only while paused; /sim/set_pose teleports; sbot_<i>/set_turret clamps to the API range."""
import os
import sys
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sbot_msgs.msg import TurretState
from sbot_msgs.srv import SetTurret, SetTurretRequest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import STEP, Recorder, Sim, wrap, yaw_of  # noqa: E402


class TestSimServices(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_sim_services')
        cls.sim = Sim()
        cls.clock = Recorder('/clock', Clock).wait_connected()
        cls.odom = Recorder('/sbot_2/ground_truth', Odometry).wait_connected()
        cls.turret = Recorder('/sbot_0/turret/state', TurretState).wait_connected()
        rospy.wait_for_service('/sbot_0/set_turret', timeout=30.0)
        cls.set_turret = rospy.ServiceProxy('/sbot_0/set_turret', SetTurret)

    def setUp(self):
        self.assertTrue(self.sim.pause().success)

    def assertAlive(self):
        """The node still serves requests and still steps."""
        res = self.sim.step(3)
        self.assertTrue(res.success, res.message)
        self.clock.wait_for(lambda m: abs(m.clock.to_sec() - res.time) < 1e-6, timeout=5.0)

    def test_set_pose_unknown_robot_fails_with_message(self):
        res = self.sim.set_pose('sbot_99', 0.0, 0.0, 0.05, 0.0)
        self.assertFalse(res.success)
        self.assertEqual(res.message, "unknown robot 'sbot_99' (robots: sbot_0..sbot_2)")
        res = self.sim.set_pose('', 0.0, 0.0, 0.05, 0.0)
        self.assertFalse(res.success)
        self.assertIn('unknown robot', res.message)
        self.assertAlive()

    def test_set_pose_non_finite_fails_with_message(self):
        res = self.sim.set_pose('sbot_1', float('nan'), 0.0, 0.05, 0.0)
        self.assertFalse(res.success)
        self.assertIn('x', res.message)
        res = self.sim.set_pose('sbot_1', 0.0, 0.0, 0.05, float('inf'))
        self.assertFalse(res.success)
        self.assertIn('yaw', res.message)
        # Finite but outside the stated range (sbot_sim/core/input_limits.h): one turn either way.
        for yaw in (1e308, -1e308, 6.3):
            res = self.sim.set_pose('sbot_1', 0.0, 0.0, 0.05, yaw)
            self.assertFalse(res.success, yaw)
            self.assertIn('field yaw must be in [-6.28319, 6.28319] rad', res.message)
        self.assertAlive()

    def test_set_pose_teleports(self):
        t = self.sim.step_ok(self, 5)
        z = self.odom.wait_stamp(t).pose.pose.position.z
        res = self.sim.set_pose('sbot_2', 0.5, -0.4, z, 0.3)
        self.assertTrue(res.success, res.message)
        t = self.sim.step_ok(self, 10)
        p = self.odom.wait_stamp(t).pose.pose
        self.assertAlmostEqual(p.position.x, 0.5, delta=0.005)
        self.assertAlmostEqual(p.position.y, -0.4, delta=0.005)
        self.assertAlmostEqual(wrap(yaw_of(p.orientation) - 0.3), 0.0, delta=0.02)

    def test_set_pose_into_the_ground_or_a_robot_fails_and_leaves_it(self):
        # Accepted, a robot 5 m under the floor would rise through it at 0.5 m/s.
        t = self.sim.step_ok(self, 5)
        before = self.odom.wait_stamp(t).pose.pose.position
        res = self.sim.set_pose('sbot_2', 0.3, 0.3, -5.0, 0.0)
        self.assertFalse(res.success)
        self.assertIn("robot 'sbot_2' there would sit", res.message)
        self.assertIn('inside the ground', res.message)
        res = self.sim.set_pose('sbot_2', 0.0, 0.0, before.z, 0.0)  # onto sbot_0
        self.assertFalse(res.success)
        self.assertIn("inside robot 'sbot_0'", res.message)
        t = self.sim.step_ok(self, 5)
        after = self.odom.wait_stamp(t).pose.pose.position
        self.assertAlmostEqual(after.x, before.x, delta=0.002)
        self.assertAlmostEqual(after.y, before.y, delta=0.002)
        self.assertAlive()

    def test_step_refuses_counts_that_would_hold_the_node(self):
        # 2^32 steps held the node, /sim/pause included, for days.
        res = self.sim.step(4294967295)
        self.assertFalse(res.success)
        self.assertIn('steps 4294967295 exceeds 100000 per call', res.message)
        self.sim.step_ok(self, 1)  # and it still steps
        self.assertAlive()

    def test_step_only_while_paused(self):
        t0 = self.sim.step_ok(self, 1)
        t1 = self.sim.step_ok(self, 10)
        self.assertAlmostEqual(t1 - t0, 10 * STEP, places=6)
        res = self.sim.unpause()
        self.assertTrue(res.success, res.message)
        try:
            res = self.sim.step(5)
            self.assertFalse(res.success, '/sim/step must fail while the simulation runs')
            self.assertIn('pause', res.message)
            # Running: the clock advances on its own.
            t = self.clock.last().clock.to_sec()
            self.clock.wait_for(lambda m: m.clock.to_sec() > t + 0.1, timeout=10.0)
        finally:
            self.assertTrue(self.sim.pause().success)
        # Paused: it does not.
        time.sleep(0.2)
        t = self.clock.last().clock.to_sec()
        time.sleep(0.5)
        self.assertEqual(self.clock.last().clock.to_sec(), t, 'the clock advanced while paused')

    def test_set_turret_clamps_to_api_range(self):
        res = self.set_turret(SetTurretRequest(position=150))
        self.assertTrue(res.success, res.message)
        self.assertTrue(res.clamped)
        self.assertEqual(res.applied, 100)
        res = self.set_turret(SetTurretRequest(position=-101))
        self.assertTrue(res.clamped)
        self.assertEqual(res.applied, -100)
        res = self.set_turret(SetTurretRequest(position=15))  # 30 degrees
        self.assertTrue(res.success, res.message)
        self.assertFalse(res.clamped)
        self.assertEqual(res.applied, 15)
        t = self.sim.step_ok(self, 300)  # 0.52 rad at 0.5 rad/s: ~1 s, plus margin
        state = self.turret.wait_stamp(t)
        self.assertLessEqual(abs(state.rotation - 15), 1, 'turret at %d units, expected 15' % state.rotation)
        self.assertAlmostEqual(state.angle, 15 * 0.034906585, delta=0.04)


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_sim_services', TestSimServices)
