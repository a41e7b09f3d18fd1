#!/usr/bin/env python3
"""rostest (node_cmd_speed.test): driving through the node. The simulator starts paused and every test
steps it with /sim/step, so sim-time durations are exact: cmd_speed 50,50 for 2 s moves 0.28 m +-10%;
out-of-range speeds are limited to 70 units; cmd_vel maps to track speeds with the track separation;
a cmd_vel holding NaN is rejected."""
import math
import os
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sbot_msgs.msg import TrackSpeed, TrackState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import (ROBOTS, SPEED_UNIT, STEP, Recorder, Sim, planar_distance,  # noqa: E402
                              publish_and_settle, wrap, yaw_of)


class TestCmdSpeed(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_cmd_speed')
        cls.sim = Sim()
        cls.odom = {r: Recorder('/%s/ground_truth' % r, Odometry).wait_connected() for r in ROBOTS}
        cls.track = {r: Recorder('/%s/track_state' % r, TrackState).wait_connected() for r in ROBOTS}
        cls.cmd_speed = {r: rospy.Publisher('/%s/cmd_speed' % r, TrackSpeed, queue_size=10) for r in ROBOTS}
        cls.cmd_vel = {r: rospy.Publisher('/%s/cmd_vel' % r, Twist, queue_size=10) for r in ROBOTS}

    def setUp(self):
        # Every test starts from the scenario's initial state (the simulator stays paused).
        res = self.sim.reset()
        self.assertTrue(res.success, res.message)
        # Let the robots settle on the ground, then read where they are (publish_rate = step rate).
        self.t_start = self.sim.step_ok(self, 20)

    def pose(self, robot, t):
        return self.odom[robot].wait_stamp(t).pose.pose

    def run_for(self, seconds):
        return self.sim.step_ok(self, int(round(seconds / STEP)))

    def test_cmd_speed_50_for_2s_moves_28cm(self):
        p0 = self.pose('sbot_0', self.t_start)
        publish_and_settle(self.cmd_speed['sbot_0'], TrackSpeed(left=50, right=50))
        t = self.run_for(2.0)
        p1 = self.pose('sbot_0', t)
        d = planar_distance(p0.position, p1.position)
        expected = 50 * SPEED_UNIT * 2.0  # 0.28 m
        self.assertLessEqual(abs(d - expected), 0.1 * expected,
                             'cmd_speed 50,50 for 2 s moved %.3f m, expected %.3f m +-10%%' % (d, expected))
        # Forward is +x at yaw 0.
        self.assertGreater(p1.position.x - p0.position.x, 0.9 * d, 'did not drive forward')
        state = self.track['sbot_0'].wait_stamp(t)
        self.assertEqual((state.requested_left, state.requested_right), (50, 50))
        self.assertLessEqual(abs(state.measured_left - 50), 3, 'measured %d' % state.measured_left)
        # The other robots did not move.
        for other in ('sbot_1', 'sbot_2'):
            q0, q1 = self.pose(other, self.t_start), self.pose(other, t)
            self.assertLess(planar_distance(q0.position, q1.position), 0.005, '%s moved' % other)

    def test_ground_truth_twist_is_in_the_robot_frame(self):
        # sbot_1 faces +y: driving forward is +y in the world but +x in its base_link (REP 105).
        publish_and_settle(self.cmd_speed['sbot_1'], TrackSpeed(left=50, right=50))
        t = self.run_for(1.0)
        odom = self.odom['sbot_1'].wait_stamp(t)
        v = odom.twist.twist.linear
        self.assertAlmostEqual(v.x, 50 * SPEED_UNIT, delta=0.1 * 50 * SPEED_UNIT,
                               msg='forward speed in base_link: %r' % v)
        self.assertLess(abs(v.y), 0.01, 'sideways speed in base_link: %r' % v)
        # Not turning: the mean yaw rate over the last 0.5 s (50 messages). One message's rate is
        # quickstep's contact jitter (Simple driving straight: rms 0.03 rad/s, peaks 0.1-0.3 rad/s).
        rates = [self.odom['sbot_1'].wait_stamp(t - k * STEP).twist.twist.angular.z for k in range(50)]
        self.assertLess(abs(sum(rates) / len(rates)), 0.02, 'mean yaw rate over 0.5 s: %r' % rates)

    def test_out_of_range_speed_is_limited_to_70_units(self):
        publish_and_settle(self.cmd_speed['sbot_1'], TrackSpeed(left=127, right=-300))
        t = self.run_for(0.1)
        state = self.track['sbot_1'].wait_stamp(t)
        self.assertEqual((state.requested_left, state.requested_right), (70, -70))

    def test_cmd_vel_straight(self):
        p0 = self.pose('sbot_2', self.t_start)
        cmd = Twist()
        cmd.linear.x = 0.1
        publish_and_settle(self.cmd_vel['sbot_2'], cmd)
        t = self.run_for(2.0)
        p1 = self.pose('sbot_2', t)
        d = planar_distance(p0.position, p1.position)
        self.assertLessEqual(abs(d - 0.2), 0.02, 'cmd_vel 0.1 m/s for 2 s moved %.3f m' % d)
        # sbot_2 faces -x (yaw pi).
        self.assertLess(p1.position.x - p0.position.x, -0.9 * d, 'did not drive forward')
        state = self.track['sbot_2'].wait_stamp(t)
        self.assertEqual(state.requested_left, state.requested_right)
        self.assertEqual(state.requested_left, int(round(0.1 / SPEED_UNIT)))

    def test_cmd_vel_turns_counter_clockwise_for_positive_angular_z(self):
        p0 = self.pose('sbot_0', self.t_start)
        cmd = Twist()
        cmd.angular.z = 1.0
        publish_and_settle(self.cmd_vel['sbot_0'], cmd)
        t = self.run_for(1.0)
        state = self.track['sbot_0'].wait_stamp(t)
        # v_l = -w b / 2, v_r = +w b / 2 with b = 8.2 cm (the centre wheels, Table 2.2): 14.6 units,
        # rounded to 15, opposite signs.
        self.assertLess(state.requested_left, 0)
        self.assertGreater(state.requested_right, 0)
        self.assertEqual(state.requested_left, -state.requested_right)
        b = 2 * state.requested_right * SPEED_UNIT / 1.0
        self.assertTrue(0.078 < b < 0.086, 'implied track separation %.3f m' % b)
        # It turns at the commanded rate, less the acceleration phase (1.02 rad/s at 15 units).
        p1 = self.pose('sbot_0', t)
        turned = wrap(yaw_of(p1.orientation) - yaw_of(p0.orientation))
        self.assertGreater(turned, 0.8, 'angular.z 1 rad/s for 1 s turned %.2f rad' % turned)
        self.assertLess(turned, 1.1, 'angular.z 1 rad/s for 1 s turned %.2f rad' % turned)
        self.assertLess(planar_distance(p0.position, p1.position), 0.02, 'turning on the spot drifted')

    def test_cmd_vel_with_nan_is_rejected(self):
        cmd = Twist()
        cmd.linear.x = 0.05
        publish_and_settle(self.cmd_vel['sbot_1'], cmd)
        t = self.run_for(0.1)
        before = self.track['sbot_1'].wait_stamp(t)
        self.assertEqual(before.requested_left, int(round(0.05 / SPEED_UNIT)))
        bad = Twist()
        bad.linear.x = float('nan')
        bad.angular.z = 0.5
        publish_and_settle(self.cmd_vel['sbot_1'], bad)
        bad.linear.x = 0.0
        bad.angular.z = float('inf')
        publish_and_settle(self.cmd_vel['sbot_1'], bad)
        t = self.run_for(0.5)
        after = self.track['sbot_1'].wait_stamp(t)
        self.assertEqual((after.requested_left, after.requested_right),
                         (before.requested_left, before.requested_right),
                         'a non-finite cmd_vel must be ignored, keeping the previous command')
        p = self.pose('sbot_1', t).position
        self.assertTrue(all(math.isfinite(v) for v in (p.x, p.y, p.z)))


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_cmd_speed', TestCmdSpeed)
