#!/usr/bin/python3
"""rostest (description_rviz.test): each level's URDF, as robot_state_publisher publishes it.

The test reads each level's robot_description (the prefixed URDF the launch file loaded), publishes
zero positions for its movable joints on /<level>/joint_states, and asks tf2 for every shared link
in <level>/base_link: a URDF robot_state_publisher could not parse, or a shared link missing or
hanging off another root, fails here by name."""
import unittest
import xml.etree.ElementTree as ET

import rospy
import rostest
import tf2_ros
from sensor_msgs.msg import JointState

LEVELS = ['fast', 'simple', 'basic', 'medium', 'detailed']
SHARED_LINKS = (['base_link', 'turret', 'gripper', 'camera'] + ['ir_%d' % i for i in range(15)]
                + ['ground_%d' % i for i in range(4)] + ['light_%d' % i for i in range(8)]
                + ['mic_%d' % i for i in range(3)])


class DescriptionRviz(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_description_rviz')
        cls.joints = {}
        for level in LEVELS:
            urdf = ET.fromstring(rospy.get_param('/%s/robot_description' % level))
            cls.joints[level] = [j.get('name') for j in urdf.iter('joint') if j.get('type') != 'fixed']
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.publishers = {lv: rospy.Publisher('/%s/joint_states' % lv, JointState, queue_size=1) for lv in LEVELS}
        cls.timer = rospy.Timer(rospy.Duration(0.1), cls.publish_zero)

    @classmethod
    def publish_zero(cls, _event):
        for level, names in cls.joints.items():
            # Stamped now: robot_state_publisher publishes the moving joints' transforms at the
            # message's stamp, and only when it has advanced.
            state = JointState(name=names, position=[0.0] * len(names))
            state.header.stamp = rospy.Time.now()
            cls.publishers[level].publish(state)

    def test_every_shared_link_resolves_to_base_link_at_every_level(self):
        deadline = rospy.Time.now() + rospy.Duration(30.0)
        missing = {}
        while not rospy.is_shutdown():
            missing = {}
            for level in LEVELS:
                gone = [link for link in SHARED_LINKS
                        if not self.buffer.can_transform('%s/base_link' % level, '%s/%s' % (level, link), rospy.Time(0))]
                if gone:
                    missing[level] = gone
            if not missing or rospy.Time.now() > deadline:
                break
            rospy.sleep(0.2)
        self.assertEqual(missing, {}, 'shared links without a transform to <level>/base_link: %s' % missing)

    def test_every_level_has_movable_joints(self):
        # The turret at least: robot_state_publisher then needs the joint states the simulator sends.
        for level in LEVELS:
            self.assertIn('turret_joint', self.joints[level], '%s joints: %s' % (level, self.joints[level]))


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'test_description_rviz', DescriptionRviz)
