#!/usr/bin/env python3
"""rostest (node_effects.test): the node loads the effects file named by ~effects (speed_scale 1.3,
fixtures/speed_scale_1_3.effects.yaml). cmd_speed 50,50 then drives at 1.3 x 0.14 m/s, while the
encoders (track_state) still read the command: node_cmd_speed.test is the same drive without it."""
import os
import sys
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sbot_msgs.msg import TrackSpeed, TrackState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import SPEED_UNIT, STEP, Recorder, Sim, planar_distance, publish_and_settle  # noqa: E402

SCALE = 1.3  # the fixture's speed_scale


class TestEffects(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_effects')
        cls.sim = Sim()
        cls.odom = Recorder('/sbot_0/ground_truth', Odometry).wait_connected()
        cls.track = Recorder('/sbot_0/track_state', TrackState).wait_connected()
        cls.cmd = rospy.Publisher('/sbot_0/cmd_speed', TrackSpeed, queue_size=10)

    def test_speed_scale_from_the_effects_file_acts(self):
        t0 = self.sim.step_ok(self, 20)  # settle on the ground
        publish_and_settle(self.cmd, TrackSpeed(left=50, right=50))
        # The steady speed over the second second (the first holds the run-up to speed, which is
        # longer at a higher target speed).
        t1 = self.sim.step_ok(self, int(round(1.0 / STEP)))
        t2 = self.sim.step_ok(self, int(round(1.0 / STEP)))
        self.assertGreater(t1, t0)
        p1 = self.odom.wait_stamp(t1).pose.pose.position
        p2 = self.odom.wait_stamp(t2).pose.pose.position
        v = planar_distance(p1, p2) / (t2 - t1)
        nominal = 50 * SPEED_UNIT  # 0.14 m/s without the effect (node_cmd_speed.test)
        self.assertLessEqual(abs(v - SCALE * nominal), 0.03 * SCALE * nominal,
                             'steady speed %.4f m/s; with speed_scale %.1f expected %.4f m/s (nominal %.4f m/s)'
                             % (v, SCALE, SCALE * nominal, nominal))
        state = self.track.wait_stamp(t2)
        self.assertLessEqual(abs(state.measured_left - 50), 3,
                             'speed_scale leaves the encoders reading the command, got %d' % state.measured_left)

if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_effects', TestEffects)
