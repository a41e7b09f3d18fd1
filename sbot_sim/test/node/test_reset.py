#!/usr/bin/env python3
"""rostest (node_reset.test): /sim/reset rebuilds the world from the scenario. Robots that were driven
or teleported are back at their initial poses, commands are forgotten, the same seed gives the same
trajectory again, and ROS time keeps increasing across the reset."""
import os
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import Point
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sbot_msgs.msg import TrackSpeed

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import (ROBOTS, Recorder, Sim, planar_distance, publish_and_settle,  # noqa: E402
                              wrap, yaw_of)

SETTLE_STEPS = 20


class TestReset(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_reset')
        cls.sim = Sim()
        cls.clock = Recorder('/clock', Clock).wait_connected()
        cls.odom = {r: Recorder('/%s/ground_truth' % r, Odometry).wait_connected() for r in ROBOTS}
        cls.cmd_speed = rospy.Publisher('/sbot_0/cmd_speed', TrackSpeed, queue_size=10)

    def poses(self, t):
        return {r: self.odom[r].wait_stamp(t).pose.pose for r in ROBOTS}

    def assertSamePoses(self, expected, actual, tol, what):
        for r in ROBOTS:
            d = planar_distance(expected[r].position, actual[r].position)
            dz = abs(expected[r].position.z - actual[r].position.z)
            dyaw = abs(wrap(yaw_of(expected[r].orientation) - yaw_of(actual[r].orientation)))
            self.assertTrue(d <= tol and dz <= tol and dyaw <= 10 * tol,
                            '%s: %s is off by %.2g m in the plane, %.2g m in z, %.2g rad in yaw'
                            % (what, r, d, dz, dyaw))

    def test_reset_restores_initial_state(self):
        # Trajectory A: from the start (the node was launched paused).
        t = self.sim.step_ok(self, SETTLE_STEPS)
        initial = self.poses(t)

        # Disturb: drive sbot_0, teleport sbot_1.
        publish_and_settle(self.cmd_speed, TrackSpeed(left=60, right=60))
        z1 = initial['sbot_1'].position.z
        res = self.sim.set_pose('sbot_1', 1.0, -1.0, z1, 0.5)
        self.assertTrue(res.success, res.message)
        t = self.sim.step_ok(self, 100)
        moved = self.poses(t)
        self.assertGreater(planar_distance(initial['sbot_0'].position, moved['sbot_0'].position), 0.1,
                           'sbot_0 did not drive, the test cannot check the reset')
        self.assertLess(planar_distance(moved['sbot_1'].position, Point(1.0, -1.0, z1)),
                        0.01, 'set_pose did not teleport sbot_1')
        t_before_reset = self.clock.last().clock.to_sec()

        res = self.sim.reset()
        self.assertTrue(res.success, res.message)

        # Trajectory B: the same number of steps from the rebuilt world gives the same poses.
        t = self.sim.step_ok(self, SETTLE_STEPS)
        self.assertGreater(t, t_before_reset, 'ROS time must keep increasing across a reset')
        again = self.poses(t)
        self.assertSamePoses(initial, again, 1e-6, 'after /sim/reset')

        # The command given before the reset is forgotten: sbot_0 stays put.
        t = self.sim.step_ok(self, 100)
        later = self.poses(t)
        self.assertLess(planar_distance(again['sbot_0'].position, later['sbot_0'].position), 0.002,
                        'sbot_0 still drives after the reset')

    def test_reset_while_running(self):
        res = self.sim.unpause()
        self.assertTrue(res.success, res.message)
        try:
            res = self.sim.reset()
            self.assertTrue(res.success, res.message)
            t = self.clock.last().clock.to_sec()
            self.clock.wait_for(lambda m: m.clock.to_sec() > t + 0.1, timeout=10.0,
                                what='after the reset (the simulation should keep running)')
        finally:
            self.sim.pause()


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_reset', TestReset)
