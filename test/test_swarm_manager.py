#!/usr/bin/env python3
"""rostest (swarm_manager.test): sbot_0 drives along x on the composite course at 60 units; the
swarm_manager keeps it Basic on the flat start, switches it to Medium before the 30 mm gap at
x = 1.5 m and back to Basic behind it. A manual override pins the level.

The test steers (proportional on heading and lateral offset, like the course experiment's route
follower): open loop, the quickstep solver's yaw drift (docs/model.md, "Yaw drift under quickstep") takes the robot to
the 0.5 m wide course's side edge, which the manager rightly reads as a drop."""
import math
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from geometry_msgs.msg import Point
from sbot_msgs.msg import ModelLevel, SwarmGraph, TrackSpeed
from sbot_msgs.srv import SetModelLevel


class TestSwarmManager(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_swarm_manager')

    def test_switches_at_the_gap_and_back(self):
        levels = []  # (x at the switch, level)
        x = [0.0]
        pose = [(0.0, 0.0, 0.0)]
        heading_error = [0.0]  # latest (x, y, yaw in degrees): a failure message says where it ended
        lock = threading.Lock()

        def on_odom(m):
            q = m.pose.pose.orientation
            yaw = math.degrees(math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))
            with lock:
                x[0] = m.pose.pose.position.x
                pose[0] = (round(x[0], 3), round(m.pose.pose.position.y, 3), round(yaw, 1))
                heading_error[0] = -math.radians(yaw) - 2.0 * m.pose.pose.position.y  # [rad]

        def on_level(m):
            with lock:
                levels.append((x[0], m.level))

        # queue_size=1: a slow test process reads the newest pose, not a backlog of old ones.
        rospy.Subscriber('/sbot_0/ground_truth', Odometry, on_odom, queue_size=1)
        rospy.Subscriber('/sbot_0/model_level', ModelLevel, on_level)
        pub = rospy.Publisher('/sbot_0/cmd_speed', TrackSpeed, queue_size=1, latch=True)
        rospy.wait_for_service('/swarm_manager/set_override', timeout=30.0)
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and not rospy.is_shutdown():
            with lock:
                if x[0] > 2.0:
                    break
                turn = int(round(max(-12.0, min(12.0, 60.0 * heading_error[0]))))
            pub.publish(TrackSpeed(left=60 - turn, right=60 + turn))
            time.sleep(0.1)
        pub.publish(TrackSpeed(left=0, right=0))
        with lock:
            seq = list(levels)
            final_x = x[0]
            final_pose = pose[0]
        self.assertGreater(final_x, 2.0, 'the robot did not cross the first gap: ended at (x, y, yaw) %s; '
                           'level switches (x, level) %s' % (final_pose, seq))
        names = [l for _, l in seq]
        self.assertIn('medium', names, seq)
        first_medium = next(px for px, l in seq if l == 'medium')
        self.assertGreater(first_medium, 1.1, seq)  # not before the look-ahead sees the gap
        self.assertLess(first_medium, 1.5, seq)     # switched before the gap
        self.assertEqual(names[-1], 'basic', seq)   # demoted behind it
        override = rospy.ServiceProxy('/swarm_manager/set_override', SetModelLevel)
        res = override('sbot_0', 'detailed')
        self.assertTrue(res.success, res.message)
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:
            with lock:
                if levels and levels[-1][1] == 'detailed':
                    break
            time.sleep(0.1)
        with lock:
            self.assertEqual(levels[-1][1], 'detailed')
        self.assertFalse(override('sbot_0', 'nonsense').success)

    def test_z_a_malformed_graph_is_ignored(self):
        # Its connection matrix was read past its end: the manager died with a segmentation fault.
        rospy.wait_for_service('/swarm_manager/set_override', timeout=30.0)
        pub = rospy.Publisher('/swarm/graph', SwarmGraph, queue_size=1, latch=True)
        bad = SwarmGraph(n=3, names=['a', 'b', 'c'], positions=[Point(0, 0, 0), Point(1, 0, 0), Point(2, 0, 0)],
                         headings=[0.0, 0.0, 0.0], connections=[])
        bad.header.stamp = rospy.Time(1e6)
        for _ in range(5):
            pub.publish(bad)
            time.sleep(0.2)
        override = rospy.ServiceProxy('/swarm_manager/set_override', SetModelLevel)
        res = override('sbot_0', '')  # the manager still answers
        self.assertTrue(res.success, res.message)


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'swarm_manager', TestSwarmManager)
