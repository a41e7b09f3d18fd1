#!/usr/bin/python3
"""Runs sbot_controllers/sbot_api_smoke (every sbot.h function) in the namespace of sbot_0 (Detailed),
and `sbot_api_smoke missing` in that of sbot_1 (Simple: getters of modules it lacks report once and
return at once)."""
import os
import subprocess
import unittest

import rospy
import rostest


def smoke(namespace, *args):
    """Runs sbot_api_smoke in `namespace`; returns (exit status, stdout + stderr)."""
    rospy.wait_for_service(namespace + '/set_gripper', 30)
    exe = subprocess.check_output(['catkin_find', '--first-only', '--libexec', 'sbot_controllers',
                                   'sbot_api_smoke']).decode().strip()
    env = dict(os.environ, SBOT_NAMESPACE=namespace)
    p = subprocess.run([exe] + list(args), env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=70)
    out = p.stdout.decode() + p.stderr.decode()
    print(out)
    return p.returncode, out


class SbotApiFunctions(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('sbot_api_functions_test', anonymous=True)

    def test_every_function(self):
        code, out = smoke('/sbot_0')
        self.assertEqual(code, 0, out)
        self.assertIn('SBOT_API_OK', out)
        # Named with the caller's values (the service's uint8 fields made them 255 and "hz 0").
        self.assertIn('setLightColor: light group 300 outside [0, 7]', out)
        self.assertIn('setProximitySamplingRate(0): not a SAMPLING_RATE code', out)

    def test_missing_modules_are_reported_once_and_not_waited_for(self):
        code, out = smoke('/sbot_1', 'missing')
        self.assertEqual(code, 0, out)
        self.assertIn('SBOT_API_MISSING_OK', out)
        self.assertIn('sbot_1 is a simple s-bot, which has no light', out)


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'sbot_api_functions', SbotApiFunctions)
