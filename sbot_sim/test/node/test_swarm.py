#!/usr/bin/env python3
"""rostest (node_swarm.test): the swarm graph and the model-level / spawn / delete services.
The graph is published at ~graph_rate with the static link of the fixture; switching a linked robot
keeps the link, its pose and its topics (model_level republished, ground_truth continues); unknown
robots / levels, duplicates and Fast-to-full-size switches fail with a message; spawn and delete
change the graph."""
import os
import sys
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sbot_msgs.msg import ModelLevel, SwarmGraph
from sbot_msgs.srv import Delete, SetModelLevel, Spawn

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import Recorder, Sim, planar_distance  # noqa: E402


class TestSwarm(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_swarm')
        cls.sim = Sim()
        cls.clock = Recorder('/clock', Clock).wait_connected()
        cls.graph = Recorder('/swarm/graph', SwarmGraph).wait_connected()
        # visualization_msgs has no Python package on Debian 12: check the markers arrive, undecoded.
        cls.markers = Recorder('/swarm/graph_markers', rospy.AnyMsg).wait_connected()
        cls.odom = Recorder('/sbot_0/ground_truth', Odometry).wait_connected()
        cls.level0 = Recorder('/sbot_0/model_level', ModelLevel).wait_connected()
        for s in ('/sim/set_model_level', '/sim/spawn', '/sim/delete'):
            rospy.wait_for_service(s, timeout=30.0)
        cls.set_level = rospy.ServiceProxy('/sim/set_model_level', SetModelLevel)
        cls.spawn = rospy.ServiceProxy('/sim/spawn', Spawn)
        cls.delete = rospy.ServiceProxy('/sim/delete', Delete)

    def setUp(self):
        self.assertTrue(self.sim.pause().success)

    def step(self, n):
        res = self.sim.step(n)
        self.assertTrue(res.success, res.message)
        return res.time

    def latest_graph(self, after):
        return self.graph.wait_for(lambda m: m.header.stamp.to_sec() >= after - 1e-6, timeout=10.0)

    def test_1_graph_has_the_static_link(self):
        t = self.step(20)
        g = self.latest_graph(t - 0.1)
        self.assertEqual(g.n, 3)
        self.assertEqual(list(g.names), ['sbot_0', 'sbot_1', 'sbot_2'])
        i0, i1, i2 = 0, 1, 2
        self.assertEqual(g.connections[i1 * 3 + i0], SwarmGraph.FRONT_GRIPPER)
        self.assertEqual(g.connections[i0 * 3 + i1], SwarmGraph.NONE)
        self.assertEqual(g.component[i0], g.component[i1])
        self.assertNotEqual(g.component[i2], g.component[i0])
        self.assertAlmostEqual(planar_distance(g.positions[i0], g.positions[i1]), 0.147, delta=0.005)
        # Rate: 10 Hz of sim time (20 steps of 0.01 s: 2 or 3 graphs).
        stamps = [m.header.stamp.to_sec() for m in self.graph.snapshot()[0]]
        self.assertGreaterEqual(len(stamps), 2)
        m = self.markers.wait_for(lambda a: b'swarm_front_gripper' in a._buff, timeout=10.0)
        self.assertTrue(m)

    def test_2_switch_keeps_pose_link_and_topics(self):
        self.level0.wait_for(lambda m: m.level == 'simple', timeout=10.0)
        t = self.step(5)
        before = self.odom.wait_for(lambda m: m.header.stamp.to_sec() >= t - 0.025)
        for level in ('basic', 'medium', 'detailed'):
            res = self.set_level('sbot_0', level)
            self.assertTrue(res.success, res.message)
            self.assertIn('available', res.message)
            self.level0.wait_for(lambda m, lv=level: m.level == lv and m.robot == 'sbot_0', timeout=10.0)
        self.assertIn('side_arm', res.message)
        t = self.step(5)
        after = self.odom.wait_for(lambda m: m.header.stamp.to_sec() >= t - 0.025)
        self.assertLess(planar_distance(before.pose.pose.position, after.pose.pose.position), 0.01)
        g = self.latest_graph(t - 0.1)
        self.assertEqual(g.connections[1 * g.n + 0], SwarmGraph.FRONT_GRIPPER)
        self.assertTrue(self.set_level('sbot_0', 'simple').success)
        self.level0.wait_for(lambda m: m.level == 'simple', timeout=10.0)

    def test_3_bad_requests_fail_cleanly(self):
        res = self.set_level('sbot_99', 'basic')
        self.assertFalse(res.success)
        self.assertIn("unknown robot 'sbot_99'", res.message)
        res = self.set_level('sbot_0', 'ultra')
        self.assertFalse(res.success)
        self.assertIn("unknown model level 'ultra'", res.message)
        res = self.set_level('sbot_0', 'fast')
        self.assertFalse(res.success)
        self.assertIn('scale', res.message)
        res = self.spawn('sbot_1', 'simple', 1.0, 1.0, 0.0)
        self.assertFalse(res.success)
        self.assertIn('exists', res.message)
        res = self.spawn('sbot_9', 'huge', 1.0, 1.0, 0.0)
        self.assertFalse(res.success)
        res = self.spawn('sbot_9', 'simple', float('nan'), 1.0, 0.0)
        self.assertFalse(res.success)
        res = self.spawn('sbot_9', 'simple', 1e300, 1.0, 0.0)  # stopped the node with an ODE assertion
        self.assertFalse(res.success)
        self.assertIn('outside the simulated space', res.message)
        res = self.spawn('sbot_9', 'fast', 1.0, 1.0, 0.0)  # scaled for 1/50 g, this world has 9.81
        self.assertFalse(res.success)
        self.assertIn('scaled for a gravity of 0.1962', res.message)
        for name in ('', '9lives', 'sbot-9', 'sbot 9', 'a/b'):  # ROS could not advertise its topics
            res = self.spawn(name, 'simple', 1.0, 1.0, 0.0)
            self.assertFalse(res.success, name)
            self.assertIn("invalid robot name '%s'" % name, res.message)
        res = self.spawn('a' * 10000, 'simple', 1.0, 1.0, 0.0)
        self.assertFalse(res.success)
        self.assertIn('a ROS name of at most 64 characters', res.message)
        self.assertLess(len(res.message), 300)  # names the start of it, not all 10000 characters
        res = self.spawn('sbot_9', 'simple', 1.0, 1.0, 1e308)
        self.assertFalse(res.success)
        self.assertIn('field yaw must be in [-6.28319, 6.28319] rad', res.message)
        res = self.spawn('sbot_9', 'simple', -0.8, -0.78, 0.0)  # onto sbot_2
        self.assertFalse(res.success)
        self.assertIn("'sbot_9' there would overlap robot 'sbot_2'", res.message)
        res = self.delete('sbot_42')
        self.assertFalse(res.success)
        self.assertIn("unknown robot 'sbot_42'", res.message)
        self.step(3)  # still alive

    def test_4_spawn_and_delete(self):
        res = self.spawn('sbot_9', 'medium', 1.0, 1.0, 0.5)
        self.assertTrue(res.success, res.message)
        odom9 = Recorder('/sbot_9/ground_truth', Odometry).wait_connected()
        t = self.step(10)
        # The graph stamped at the spawn's own time may predate it (the spawn is served after that
        # step's publication), and the one at t may still be on its way: wait for the first graph
        # with sbot_9 and check it came from these 10 steps.
        g = self.graph.wait_for(lambda m: 'sbot_9' in m.names, timeout=10.0, what='listing sbot_9', first=True)
        self.assertLessEqual(g.header.stamp.to_sec(), t + 1e-6)
        m = odom9.wait_for(lambda m: m.header.stamp.to_sec() >= t - 0.05)
        self.assertAlmostEqual(m.pose.pose.position.x, 1.0, delta=0.01)
        res = self.delete('sbot_0')  # the held robot: its connection goes with it
        self.assertTrue(res.success, res.message)
        self.step(10)
        g = self.graph.wait_for(lambda m: 'sbot_0' not in m.names, timeout=10.0)
        self.assertEqual(g.n, 3)
        self.assertNotIn('sbot_0', g.names)
        self.assertEqual(sum(g.connections), 0)
        self.assertEqual(len(set(g.component)), 3)
        # Its topics go with it (kept, every name ever spawned held ~50 topics for good), and a spawn
        # of the same name brings them back.
        published = lambda: [name for name, _ in rospy.get_published_topics()]
        self.assertNotIn('/sbot_0/model_level', published())
        self.assertIn('/sbot_9/model_level', published())
        res = self.spawn('sbot_0', 'simple', 1.0, -1.0, 0.0)
        self.assertTrue(res.success, res.message)
        level = rospy.wait_for_message('/sbot_0/model_level', ModelLevel, timeout=10.0)
        self.assertEqual(level.level, 'simple')


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_swarm', TestSwarm)
