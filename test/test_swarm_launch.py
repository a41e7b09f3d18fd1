#!/usr/bin/env python3
"""rostest (swarm_launch_1.test, swarm_launch_20.test): launch/swarm.launch brings up a working swarm.

For every robot sbot_<i> (i < ~robots):
  - /sbot_<i>/ground_truth publishes, and the robot moves (its random_walk controller drives it):
    its base travels at least ~min_travel (path length) or turns at least ~min_turn (a random walker
    turning on the spot at a wall is driven too), and /sbot_<i>/cmd_speed carries commands;
  - /tf carries world -> sbot_<i>/base_link (from the simulator) and sbot_<i>/base_link ->
    sbot_<i>/turret (from /sbot_<i>/robot_state_publisher, the turret joint being revolute);
  - the robot is simulated at ~level (/sbot_<i>/model_level), and its robot_state_publisher has that
    level's URDF: at a six-wheeled level it publishes base_link -> left_wheel_front, which only
    moves with the simulator's joint_states of that level.

Private parameters: ~robots (required), ~level (default simple), ~sim_window [s sim] to watch
(default 5), ~min_travel [m] (default 0.05), ~min_turn [rad] (default 0.5), ~timeout [s wall] for
everything to come up (default 40).
"""
import math
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sbot_msgs.msg import ModelLevel, TrackSpeed
from tf2_msgs.msg import TFMessage

PKG = 'swarmbot3d'


class SwarmLaunchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_swarm_launch')
        cls.robots = int(rospy.get_param('~robots'))
        cls.level = rospy.get_param('~level', 'simple')
        cls.sim_window = float(rospy.get_param('~sim_window', 5.0))
        cls.min_travel = float(rospy.get_param('~min_travel', 0.05))
        cls.timeout = float(rospy.get_param('~timeout', 40.0))
        cls.names = ['sbot_%d' % i for i in range(cls.robots)]
        cls.lock = threading.Lock()
        cls.min_turn = float(rospy.get_param('~min_turn', 0.5))
        cls.last = {}         # robot -> (x, y, yaw) latest ground truth
        cls.path = {r: 0.0 for r in cls.names}   # [m] base path length
        cls.turn = {r: 0.0 for r in cls.names}   # [rad] accumulated |yaw change|
        cls.gt_count = {r: 0 for r in cls.names}
        cls.cmd_count = {r: 0 for r in cls.names}
        cls.cmd_nonzero = {r: 0 for r in cls.names}
        cls.levels = {}       # robot -> level on its latched model_level topic
        cls.edges = {}        # (parent, child) -> set of publishing nodes
        cls.clock = None
        cls.subs = [rospy.Subscriber('/clock', Clock, cls.on_clock),
                    rospy.Subscriber('/tf', TFMessage, cls.on_tf, queue_size=1000)]
        for r in cls.names:
            cls.subs.append(rospy.Subscriber('/%s/ground_truth' % r, Odometry, cls.on_gt, r, queue_size=100))
            cls.subs.append(rospy.Subscriber('/%s/cmd_speed' % r, TrackSpeed, cls.on_cmd, r, queue_size=100))
            cls.subs.append(rospy.Subscriber('/%s/model_level' % r, ModelLevel, cls.on_level, r))

        # Wait (wall time) until every robot has reported once, then watch sim_window of sim time.
        deadline = time.time() + cls.timeout
        while time.time() < deadline and not rospy.is_shutdown():
            with cls.lock:
                if all(cls.gt_count[r] > 0 for r in cls.names) and cls.clock is not None:
                    break
            time.sleep(0.1)
        with cls.lock:
            cls.start_clock = cls.clock
        if cls.start_clock is None:
            return
        deadline = time.time() + cls.timeout
        while time.time() < deadline and not rospy.is_shutdown():
            with cls.lock:
                if cls.clock >= cls.start_clock + cls.sim_window:
                    break
            time.sleep(0.1)
        with cls.lock:
            cls.end_clock = cls.clock

    @classmethod
    def tearDownClass(cls):
        for s in cls.subs:
            s.unregister()

    @classmethod
    def on_clock(cls, msg):
        with cls.lock:
            cls.clock = msg.clock.to_sec()

    @classmethod
    def on_gt(cls, msg, robot):
        p = msg.pose.pose.position
        with cls.lock:
            cls.gt_count[robot] += 1
            q = msg.pose.pose.orientation
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            if robot in cls.last:
                x0, y0, yaw0 = cls.last[robot]
                cls.path[robot] += math.hypot(p.x - x0, p.y - y0)
                cls.turn[robot] += abs(math.remainder(yaw - yaw0, 2 * math.pi))
            cls.last[robot] = (p.x, p.y, yaw)

    @classmethod
    def on_cmd(cls, msg, robot):
        with cls.lock:
            cls.cmd_count[robot] += 1
            if msg.left != 0 or msg.right != 0:
                cls.cmd_nonzero[robot] += 1

    @classmethod
    def on_level(cls, msg, robot):
        with cls.lock:
            cls.levels[robot] = msg.level

    @classmethod
    def on_tf(cls, msg):
        node = getattr(msg, '_connection_header', {}).get('callerid', '?')
        with cls.lock:
            for t in msg.transforms:
                cls.edges.setdefault((t.header.frame_id.lstrip('/'), t.child_frame_id.lstrip('/')), set()).add(node)

    def test_0_clock_runs(self):
        self.assertIsNotNone(self.start_clock, 'no /clock or not every robot published ground_truth within %.0f s'
                             % self.timeout)
        self.assertGreaterEqual(self.end_clock, self.start_clock + self.sim_window - 1e-6,
                                'sim time advanced only %.2f s in %.0f s wall (wanted %.1f s)'
                                % (self.end_clock - self.start_clock, self.timeout, self.sim_window))

    def test_1_ground_truth(self):
        with self.lock:
            silent = [r for r in self.names if self.gt_count[r] == 0]
        self.assertEqual(silent, [], 'robots without ground_truth messages: %s' % silent)

    def test_2_robots_move(self):
        with self.lock:
            moved = {r: (round(self.path[r], 3), round(self.turn[r], 2)) for r in self.names}
            no_cmd = [r for r in self.names if self.cmd_nonzero[r] == 0]
        still = sorted(r for r in self.names if moved[r][0] < self.min_travel and moved[r][1] < self.min_turn)
        self.assertEqual(no_cmd, [], 'robots whose controller sent no non-zero cmd_speed: %s' % no_cmd)
        self.assertEqual(still, [], 'robots that neither travelled %.2f m nor turned %.1f rad (path [m], turn [rad]): %s'
                         % (self.min_travel, self.min_turn, {r: moved[r] for r in still}))

    def test_3_tf_tree(self):
        with self.lock:
            edges = dict(self.edges)
        missing = []
        for r in self.names:
            if ('world', '%s/base_link' % r) not in edges:
                missing.append('world -> %s/base_link' % r)
            turret = edges.get(('%s/base_link' % r, '%s/turret' % r))
            if not turret:
                missing.append('%s/base_link -> %s/turret' % (r, r))
            elif '/%s/robot_state_publisher' % r not in turret:
                missing.append('%s/base_link -> %s/turret from /%s/robot_state_publisher (published by %s)'
                               % (r, r, r, sorted(turret)))
        self.assertEqual(missing, [], 'missing transforms on /tf: %s' % missing)

    def test_4_level_in_simulator_and_robot_state_publisher(self):
        with self.lock:
            levels = dict(self.levels)
            edges = dict(self.edges)
        wrong = {r: levels.get(r) for r in self.names if levels.get(r) != self.level}
        self.assertEqual(wrong, {}, 'robots not simulated at level %s (model_level): %s' % (self.level, wrong))
        if self.level in ('medium', 'detailed'):
            missing = [r for r in self.names
                       if '/%s/robot_state_publisher' % r not in edges.get(('%s/base_link' % r, '%s/left_wheel_front' % r), ())]
            self.assertEqual(missing, [], 'robot_state_publisher without the %s URDF (no base_link -> left_wheel_front): %s'
                             % (self.level, missing))


if __name__ == '__main__':
    rostest.rosrun(PKG, 'test_swarm_launch', SwarmLaunchTest)
