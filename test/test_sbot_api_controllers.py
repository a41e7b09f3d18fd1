#!/usr/bin/python3
"""Outcome of the sbot.h controllers (sbot_controllers/src/obstacle_avoidance.c, phototaxis.c) run
against the simulator over ~sim_duration simulated seconds, judged from ground truth.

Collision (ground truth): two robots' centres closer than 2 x turret radius - 5 mm, or a robot's
centre closer than turret radius - 5 mm to an arena wall's inner face (overlap). Checked on every
ground_truth message (50 Hz sim time) of every robot against the latest pose of the others.

~mode avoidance: no collision at all, and every robot travelled at least ~min_travel [m].
~mode phototaxis: the mean distance to the lamp fell by at least ~min_gain [m].

The simulator starts paused; the test unpauses it once every controller publishes cmd_speed, so
the run is judged from t = 0.
"""
import math
import sys
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sbot_msgs.msg import TurretState

from paused_sim import unpause_and_run, wait_for_controllers


class ControllerOutcome(unittest.TestCase):
    def setUp(self):
        rospy.init_node('sbot_api_controller_test', anonymous=True)
        self.robots = rospy.get_param('~robots')
        self.mode = rospy.get_param('~mode')
        self.duration = rospy.get_param('~sim_duration', 120.0)
        self.radius = rospy.get_param('~turret_radius', 0.057)
        self.arena = rospy.get_param('~arena_size', 0.0)
        self.lamp = rospy.get_param('~lamp', [0.0, 0.0])
        self.lock = threading.Lock()
        self.pose = {}
        self.heading = {}  # [rad] latest yaw per robot, for the failure report
        self.turret = {}  # [API units, 2 deg] latest measured turret rotation per robot
        self.start = {}
        self.travel = {r: 0.0 for r in self.robots}
        self.t0 = None
        self.t_last = 0.0
        self.collisions = []
        self.subs = [rospy.Subscriber('/%s/ground_truth' % r, Odometry, self.on_pose, r, queue_size=1000,
                                      tcp_nodelay=True) for r in self.robots]
        self.turret_subs = [rospy.Subscriber('/%s/turret/state' % r, TurretState, self.on_turret, r, queue_size=1)
                            for r in self.robots]

    def on_turret(self, msg, robot):
        with self.lock:
            self.turret[robot] = msg.rotation

    def on_pose(self, msg, robot):
        p = (msg.pose.pose.position.x, msg.pose.pose.position.y)
        t = msg.header.stamp.to_sec()
        with self.lock:
            if self.t0 is None:
                self.t0 = t
            if robot not in self.start:
                self.start[robot] = p
            if robot in self.pose:
                q = self.pose[robot]
                self.travel[robot] += math.hypot(p[0] - q[0], p[1] - q[1])
            self.pose[robot] = p
            o = msg.pose.pose.orientation
            self.heading[robot] = math.atan2(2 * (o.w * o.z + o.x * o.y), 1 - 2 * (o.y * o.y + o.z * o.z))
            self.t_last = max(self.t_last, t)
            limit = 2 * self.radius - 0.005
            for other, q in self.pose.items():
                if other != robot and math.hypot(p[0] - q[0], p[1] - q[1]) < limit:
                    self.collisions.append('t=%.2f %s-%s %.3f m' % (t - self.t0, robot, other,
                                                                   math.hypot(p[0] - q[0], p[1] - q[1])))
            if self.arena > 0:
                half = self.arena / 2 - (self.radius - 0.005)
                if abs(p[0]) > half or abs(p[1]) > half:
                    self.collisions.append('t=%.2f %s-wall at (%.3f, %.3f)' % (t - self.t0, robot, p[0], p[1]))

    def simulated(self):
        """[s] simulated so far; 0 until every robot has reported."""
        with self.lock:
            if self.t0 is None or len(self.pose) < len(self.robots):
                return 0.0
            return self.t_last - self.t0

    def test_outcome(self):
        rospy.wait_for_service('/sim/unpause', 60.0)
        if not wait_for_controllers('/sbot_api_controller_test', self.robots, 'cmd_speed', publishers=True):
            self.fail('controllers did not start within 60 s')
        wall = unpause_and_run(self.subs, self.simulated, self.duration, 600)
        with self.lock:
            sim = self.t_last - (self.t0 or 0)
            rospy.loginfo('%s: %.1f s simulated in %.1f s wall (RTM %.1f); travel %s', self.mode, sim, wall,
                          sim / max(wall, 1e-9), {r: round(d, 2) for r, d in self.travel.items()})
            print('%s: %.1f s simulated in %.1f s wall; travel %s' % (self.mode, sim, wall,
                  {r: round(d, 2) for r, d in self.travel.items()}), file=sys.stderr)
            self.assertGreaterEqual(sim, self.duration - 0.1, 'the simulation did not get far enough')
            kinds = {}
            for c in self.collisions:
                k = c.split()[1]
                kinds[k] = kinds.get(k, 0) + 1
            print('collision samples by pair: %s' % kinds, file=sys.stderr)
            if self.mode == 'avoidance':
                self.assertEqual(self.collisions, [], '%d collision samples, first: %s' %
                                 (len(self.collisions), self.collisions[:5]))
                for r in self.robots:
                    self.assertGreater(self.travel[r], rospy.get_param('~min_travel', 2.0),
                                       '%s hardly moved' % r)
            else:
                def mean_distance(poses):
                    return sum(math.hypot(p[0] - self.lamp[0], p[1] - self.lamp[1]) for p in poses.values()) / len(poses)
                d0, d1 = mean_distance(self.start), mean_distance(self.pose)
                print('phototaxis: mean distance to the lamp %.2f m -> %.2f m; robot-robot contacts: %d samples'
                      % (d0, d1, len(self.collisions)), file=sys.stderr)
                self.assertLess(d1, d0 - rospy.get_param('~min_gain', 1.0),
                                'mean distance to the lamp %.2f m -> %.2f m; at the end: %s' % (d0, d1, self.final_states()))

    def final_states(self):
        """Per robot at the end: position, distance and bearing to the lamp (0 = ahead, + = left) and
        the turret rotation, so that a failed run says whether a robot was lost, orbiting or turned away."""
        out = []
        for r in self.robots:
            x, y = self.pose.get(r, (float('nan'), float('nan')))
            yaw = self.heading.get(r, float('nan'))
            bearing = math.degrees(math.atan2(self.lamp[1] - y, self.lamp[0] - x) - yaw)
            bearing = (bearing + 180) % 360 - 180
            out.append('%s at (%.2f, %.2f) %.2f m from the lamp, lamp bearing %.0f deg, turret %s units' % (
                r, x, y, math.hypot(self.lamp[0] - x, self.lamp[1] - y), bearing, self.turret.get(r, 'unknown')))
        return '; '.join(out)


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'sbot_api_controllers', ControllerOutcome)
