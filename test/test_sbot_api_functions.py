#!/usr/bin/python3
"""Runs sbot_controllers/sbot_api_smoke (every sbot.h function) in the namespace of sbot_0."""
import os
import subprocess
import unittest

import rospy
import rostest


class SbotApiFunctions(unittest.TestCase):
    def test_every_function(self):
        rospy.init_node('sbot_api_functions_test', anonymous=True)
        rospy.wait_for_service('/sbot_0/set_gripper', 30)
        exe = subprocess.check_output(['catkin_find', '--first-only', '--libexec', 'sbot_controllers',
                                       'sbot_api_smoke']).decode().strip()
        env = dict(os.environ, SBOT_NAMESPACE='/sbot_0')
        p = subprocess.run([exe], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=70)
        out, err = p.stdout.decode(), p.stderr.decode()
        print(out)
        print(err)
        self.assertEqual(p.returncode, 0, out + err)
        self.assertIn('SBOT_API_OK', out)


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'sbot_api_functions', SbotApiFunctions)
