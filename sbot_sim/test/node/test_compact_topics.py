#!/usr/bin/env python3
"""rostest (node_compact_topics.test): with ~per_sensor_topics false the simulator still publishes
every robot's proximity and light arrays, but advertises none of the per-sensor topics
(proximity/ir_<k>, light/sensor_<k>) that it advertises by default."""
import re
import unittest

import rospy
import rostest
from sbot_msgs.msg import LightArray, ProximityArray

ROBOTS = ['sbot_0', 'sbot_1']  # fixtures/modules.yaml
PER_SENSOR = re.compile(r'^/sbot_\d+/(proximity/ir_\d+|light/sensor_\d+)$')


class TestCompactTopics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_compact_topics')
        # The arrays arrive: the robots' modules are up, so every topic they would advertise is.
        cls.proximity = {r: rospy.wait_for_message('/%s/proximity' % r, ProximityArray, 30) for r in ROBOTS}
        cls.light = rospy.wait_for_message('/sbot_0/light', LightArray, 30)  # the Medium has light sensors
        cls.topics = [name for name, _ in rospy.get_published_topics()]

    def test_arrays_are_published(self):
        for r in ROBOTS:
            self.assertEqual(len(self.proximity[r].readings), 15, r)
            self.assertIn('/%s/proximity' % r, self.topics)
        self.assertEqual(len(self.light.readings), 8)

    def test_no_per_sensor_topic_is_advertised(self):
        per_sensor = [t for t in self.topics if PER_SENSOR.match(t)]
        self.assertEqual(per_sensor, [], 'per-sensor topics advertised with ~per_sensor_topics false')
        # The other per-robot topics are still there (the pattern would not miss them by a typo).
        for t in ['/sbot_0/ground', '/sbot_0/light', '/sbot_0/camera/blobs', '/sbot_1/ground_truth']:
            self.assertIn(t, self.topics)


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_compact_topics', TestCompactTopics)
