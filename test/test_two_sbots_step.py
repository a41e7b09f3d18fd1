#!/usr/bin/python3
"""Seed 4.1.3 two-robot step passing, judged from ground truth while the sbot.h script
(sbot_controllers/src/step_climbing.c) runs: sbot_1 grips sbot_0 and the pair reverses up a ~step_height
step; sbot_2 tries it alone.

Pass, for the pair: sbot_1 gripped sbot_0 with its front gripper (/swarm/graph), and at the end both
are on the plateau (base_link beyond ~plateau_x and higher than the step) and upright (tilt < 20 deg).
For the single robot: it did NOT get onto the plateau and it tipped beyond ~topple_tilt (the seed's
single s-bot topples backwards at 32 mm).

The simulator starts paused; the test unpauses it once every controller has connected, so the run
is judged from t = 0.
"""
import math
import sys
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sbot_msgs.msg import SwarmGraph

from paused_sim import unpause_and_run, wait_for_controllers


def tilt_deg(q):
    """Angle between the body's z axis and the world's z axis [deg]."""
    up_z = 1.0 - 2.0 * (q.x * q.x + q.y * q.y)
    return math.degrees(math.acos(max(-1.0, min(1.0, up_z))))


class TwoSbotsStep(unittest.TestCase):
    def setUp(self):
        rospy.init_node('two_sbots_step_test', anonymous=True)
        self.holder = rospy.get_param('~holder', 'sbot_1')
        self.held = rospy.get_param('~held', 'sbot_0')
        self.single = rospy.get_param('~single', 'sbot_2')
        self.robots = [self.holder, self.held, self.single]
        self.duration = rospy.get_param('~sim_duration', 50.0)
        self.step_height = rospy.get_param('~step_height', 0.032)
        self.plateau_x = rospy.get_param('~plateau_x', -0.10)
        self.topple_tilt = rospy.get_param('~topple_tilt', 40.0)
        self.lock = threading.Lock()
        self.pose = {}
        self.max_tilt = {r: 0.0 for r in self.robots}
        self.gripped_at = None
        self.t0 = None
        self.t_last = 0.0
        self.subs = [rospy.Subscriber('/%s/ground_truth' % r, Odometry, self.on_pose, r, queue_size=100)
                     for r in self.robots]
        self.subs.append(rospy.Subscriber('/swarm/graph', SwarmGraph, self.on_graph, queue_size=10))

    def on_pose(self, msg, robot):
        t = msg.header.stamp.to_sec()
        p = msg.pose.pose.position
        with self.lock:
            if self.t0 is None:
                self.t0 = t
            self.pose[robot] = (p.x, p.y, p.z, tilt_deg(msg.pose.pose.orientation))
            self.max_tilt[robot] = max(self.max_tilt[robot], self.pose[robot][3])
            self.t_last = max(self.t_last, t)

    def on_graph(self, msg):
        if self.holder not in msg.names or self.held not in msg.names:
            return
        i, j = msg.names.index(self.holder), msg.names.index(self.held)
        if msg.connections[i * msg.n + j] == SwarmGraph.FRONT_GRIPPER:
            with self.lock:
                if self.gripped_at is None:
                    self.gripped_at = msg.header.stamp.to_sec() - (self.t0 or 0.0)

    def simulated(self):
        with self.lock:
            return self.t_last - self.t0 if self.t0 is not None else 0.0

    def on_plateau(self, robot):
        x, _, z, tilt = self.pose[robot]
        return x < self.plateau_x and z > self.step_height + 0.01 and tilt < 20.0

    def test_pair_passes_single_topples(self):
        rospy.wait_for_service('/sim/unpause', 60.0)
        if not wait_for_controllers('/two_sbots_step_test', self.robots, 'slope', publishers=False):
            self.fail('controllers did not subscribe to their slope topics within 60 s')
        wall = unpause_and_run(self.subs, self.simulated, self.duration, 400)
        with self.lock:
            sim = self.t_last - (self.t0 or 0.0)
            report = ', '.join('%s x %.3f z %.3f tilt %.0f deg (max %.0f)' % (
                r, self.pose[r][0], self.pose[r][2], self.pose[r][3], self.max_tilt[r])
                for r in self.robots if r in self.pose)
            print('two_sbots_step: %.1f s simulated in %.1f s wall; gripped at %s s; %s'
                  % (sim, wall, self.gripped_at, report), file=sys.stderr)
            self.assertGreaterEqual(sim, self.duration - 0.1, 'the simulation did not get far enough: ' + report)
            self.assertIsNotNone(self.gripped_at, '%s never gripped %s (no FRONT_GRIPPER link on /swarm/graph)'
                                 % (self.holder, self.held))
            for r in (self.holder, self.held):
                self.assertTrue(self.on_plateau(r), 'the pair did not pass the step: ' + report)
            self.assertFalse(self.on_plateau(self.single), 'the single robot passed the step: ' + report)
            self.assertGreater(self.max_tilt[self.single], self.topple_tilt,
                               'the single robot did not tip over: ' + report)


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'two_sbots_step', TwoSbotsStep)
