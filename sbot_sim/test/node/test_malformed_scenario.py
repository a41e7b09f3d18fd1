#!/usr/bin/env python3
"""rostest (node_malformed_scenario.test): the simulator refuses bad input at start-up. It is run as a
subprocess against the rostest master; it must exit non-zero, quickly, with a message on stderr that
names the offending file and field."""
import os
import shutil
import subprocess
import tempfile
import unittest

import rospkg
import rospy
import rostest
from roslib.packages import find_node

FIXTURES = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'fixtures')


def simulator_binary():
    paths = find_node('sbot_sim', 'simulator_node', rospack=rospkg.RosPack())
    if not paths:
        raise AssertionError('simulator_node not found (is sbot_sim built?)')
    return paths[0]


class TestMalformedScenario(unittest.TestCase):
    counter = 0

    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_malformed_scenario')
        cls.binary = simulator_binary()

    def run_node(self, *params, env=None):
        TestMalformedScenario.counter += 1
        name = 'bad_simulator_%d' % TestMalformedScenario.counter
        cmd = [self.binary, '__name:=' + name] + list(params)
        try:
            proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=30,
                                  universal_newlines=True, env=env)
        except subprocess.TimeoutExpired:
            self.fail('%s did not exit within 30 s' % ' '.join(cmd))
        return proc

    def assertRefused(self, proc, *needles):
        self.assertNotEqual(proc.returncode, 0, 'the simulator accepted it; stderr:\n' + proc.stderr)
        self.assertGreater(proc.returncode, 0, 'the simulator crashed (signal %d); stderr:\n%s'
                           % (-proc.returncode, proc.stderr))
        # Bad input refused before any step: exit status 2 (sbot_sim/tools/cli_args.h).
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn('FATAL', proc.stderr)
        for needle in needles:
            self.assertIn(needle, proc.stderr, 'stderr does not name %r:\n%s' % (needle, proc.stderr))

    def fixture(self, name):
        return os.path.join(FIXTURES, name)

    def test_negative_step(self):
        path = self.fixture('malformed_step.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'world.step')

    def test_unknown_level(self):
        path = self.fixture('malformed_level.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'robots[1].level', 'hyperdetailed')

    def test_non_numeric_pose(self):
        path = self.fixture('malformed_pose.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'robots[0].pose.x')

    def test_missing_file(self):
        path = self.fixture('no_such_scenario.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path)

    def test_missing_scenario_parameter(self):
        self.assertRefused(self.run_node(), '~scenario')

    def test_invalid_publish_rate(self):
        path = self.fixture('three_robots.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path, '_publish_rate:=-5.0'), '~publish_rate')

    def test_unknown_level_override(self):
        path = self.fixture('three_robots.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path, '_level:=huge'), '~level', "'huge'")

    def test_invalid_robot_name(self):
        path = self.fixture('bad_robot_name.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'robots[0].name', "'sbot-0'")

    def test_effects_file_out_of_bounds(self):
        scenario = self.fixture('three_robots.yaml')
        effects = self.fixture('malformed.effects.yaml')
        self.assertRefused(self.run_node('_scenario:=' + scenario, '_effects:=' + effects), effects,
                           'effects[0].params.delay')

    # Each of these would crash the node (a stack overflow, an abort from inside the sensor
    # set-up) or pass without a word if it were not refused.
    def scenario_with(self, world_lines):
        """three_robots.yaml with `world_lines` added under world:, as a temporary file."""
        with open(self.fixture('three_robots.yaml')) as f:
            text = f.read().replace('world:\n', 'world:\n' + world_lines, 1)
        handle, path = tempfile.mkstemp(suffix='.yaml')
        with os.fdopen(handle, 'w') as f:
            f.write(text)
        self.addCleanup(os.remove, path)
        return path

    def test_robots_spawned_inside_each_other(self):
        path = self.scenario_with('')
        with open(path) as f:
            text = f.read().replace('pose: {x: 0.0, y: 0.8,', 'pose: {x: 0.05, y: 0.0,')
        with open(path, 'w') as f:
            f.write(text)
        self.assertRefused(self.run_node('_scenario:=' + path), path, "'robots'", "robot 'sbot_0' and robot 'sbot_1' overlap")

    def test_infinite_ambient_light(self):
        path = self.scenario_with('  ambient_light: .inf\n')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'world.ambient_light', 'must be finite')

    def test_out_of_range_and_null_values(self):
        for world, field, words in (
                ('  ambient_light: 1e308\n', 'world.ambient_light', 'must be in [0, 1e+09] mcd/cm^2'),
                ('  lamps: [{position: [0, 0, 1], intensity: 1e308}]\n', 'world.lamps[0].intensity', 'must be in [0, 1e+09] mcd'),
                ('  gravity: ~\n', 'world.gravity', 'is null (~)')):
            path = self.scenario_with(world)
            self.assertRefused(self.run_node('_scenario:=' + path), path, field, words)
        path = self.scenario_with('')
        with open(path) as f:
            text = f.read().replace('terrain: {type: plane}', 'terrain: {type: composite, boxes: '
                                    '[{center: [3, 3, 0.05], size: [1e-20, 0.6, 0.1]}]}')
        with open(path, 'w') as f:
            f.write(text)
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'world.terrain.boxes[0].size',
                           'every edge must be in [0.0001, 200000] m')

    def test_special_files_are_refused(self):
        fifo = os.path.join(tempfile.mkdtemp(), 'scenario.fifo')
        os.mkfifo(fifo)
        for path in ('/dev/zero', fifo):
            self.assertRefused(self.run_node('_scenario:=' + path), path, 'is not a regular file')

    def test_lamp_without_a_position(self):
        path = self.scenario_with('  lamps: [{position: [0, 0, 1], intensity: 10}, {intensity: 5}]\n')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'world.lamps[1].position')

    def test_recursive_yaml(self):
        path = self.scenario_with('  solver: &loop [*loop]\n')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'recursive YAML is refused')

    def test_parameters_of_the_wrong_type(self):
        path = self.fixture('three_robots.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path, '_robots:=abc'), '~robots must be a whole number', "'abc'")
        self.assertRefused(self.run_node('_scenario:=' + path, '_paused:=maybe'), '~paused must be true or false')
        self.assertRefused(self.run_node('_scenario:=' + path, '_rates/nosuch:=5'), '~rates/nosuch: unknown channel')
        self.assertRefused(self.run_node('_scenario:=' + path, '_per_sensor_topics:=2'),
                           '~per_sensor_topics must be true or false')

    def test_sidecar_value_the_sensors_cannot_use(self):
        description = rospkg.RosPack().get_path('sbot_description')
        copy = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, copy)
        for sub in ('urdf', 'config'):
            shutil.copytree(os.path.join(description, sub), os.path.join(copy, sub))
        sidecar = os.path.join(copy, 'urdf', 'simple.sbot.yaml')
        with open(sidecar) as f:
            text = f.read()
        with open(sidecar, 'w') as f:
            f.write(text.replace('ir_model: lut', 'ir_model: psychic', 1))
        env = dict(os.environ, SBOT_DESCRIPTION_DIR=copy)
        proc = self.run_node('_scenario:=' + self.fixture('three_robots.yaml'), env=env)
        self.assertRefused(proc, sidecar, 'extra.ir_model', "'psychic'")

    def test_good_scenario_is_accepted(self):
        # Control: the same invocation with a valid scenario runs until its duration and exits 0.
        path = self.fixture('three_robots.yaml')
        proc = self.run_node('_scenario:=' + path, '_duration:=0.2', '_real_time_factor:=0.0')
        self.assertEqual(proc.returncode, 0, 'stderr:\n' + proc.stderr)
        self.assertIn('duration reached', proc.stdout)


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_malformed_scenario', TestMalformedScenario)
