#!/usr/bin/python3
"""docs/ros_api.md against the running simulator_node (rostest test/ros_api_doc.test).

The doc's simulator_node section has three tables of names (Published topics, Subscribed topics,
Services) whose first column is the name in backticks and whose column "Advertised" says when it
exists: `always`, or comma-separated conditions. A condition written `~p` (a boolean parameter is
true) or `~p > 0` (a number is positive) is evaluated against the node's parameters (the parameter
server, else the default in the doc's Parameters table); any other condition (a sentence) cannot be
evaluated here, and its name is then not required. In names, `<robot>` stands for a robot's name
and `<k>` for a sensor index.

Fails when
* the node advertises (or subscribes, or serves) a name no row of the matching table covers;
* a row whose condition holds matches nothing the node advertises, for any robot of the scenario;
* a published topic's type on the master differs from the row's type;
* the node's sources (sbot_sim/src/node) read a private parameter the Parameters table lacks.
"""
import os
import re
import sys
import time
import unittest

import rosgraph
import rospkg
import rospy

DOC = os.path.join(rospkg.RosPack().get_path('swarmbot3d'), 'docs', 'ros_api.md')
NODE_SOURCES = os.path.join(rospkg.RosPack().get_path('sbot_sim'), 'src', 'node')
TABLES = {'pub': 'Published topics', 'sub': 'Subscribed topics', 'srv': 'Services'}
ROBOT = '[A-Za-z][A-Za-z0-9_]*'


def section(text, heading, level):
    """The text under a markdown heading of `level` #'s, up to the next heading of that level or above."""
    m = re.search(r'^%s %s\s*$' % ('#' * level, re.escape(heading)), text, re.M)
    if not m:
        raise AssertionError('%s: no heading "%s %s"' % (DOC, '#' * level, heading))
    rest = text[m.end():]
    end = re.search(r'^#{1,%d} ' % level, rest, re.M)
    return rest[:end.start()] if end else rest


def table(text):
    """Rows of the first markdown table in text, as dicts keyed by the header's cells."""
    rows = [l.strip() for l in text.splitlines() if l.strip().startswith('|')]
    if len(rows) < 2:
        raise AssertionError('%s: a table is missing' % DOC)
    split = lambda l: [c.strip() for c in l.strip('|').split('|')]
    header = split(rows[0])
    return [dict(zip(header, split(r))) for r in rows[2:]]


def backticked(cell):
    return re.findall(r'`([^`]+)`', cell)


def parse_doc(text):
    sim = section(text, 'simulator_node', 2)
    names = {}
    for kind, heading in TABLES.items():
        rows = []
        for row in table(section(sim, heading, 3)):
            name = backticked(row['Name'])
            if len(name) != 1:
                raise AssertionError('%s, %s: a row must name exactly one `name`: %s' % (DOC, heading, row['Name']))
            rows.append({'name': name[0], 'type': row.get('Type', ''), 'when': row['Advertised']})
        names[kind] = rows
    params = {}
    for row in table(section(sim, 'Parameters', 3)):
        for p in backticked(row['Parameter']):
            default = backticked(row['Default'])
            params[p.lstrip('~')] = default[0] if default else None
    return names, params


def pattern(name, robot=None):
    """A doc name as a regex; `robot` fixes <robot>."""
    parts = re.split(r'(<robot>|<k>)', name)
    out = ''
    for p in parts:
        if p == '<robot>':
            out += re.escape(robot) if robot else ROBOT
        elif p == '<k>':
            out += r'\d+'
        else:
            out += re.escape(p)
    return re.compile('^' + out + '$')


def literal(value):
    if value is None:
        return None
    v = value.strip('"')
    if v in ('true', 'false'):
        return v == 'true'
    try:
        return float(v)
    except ValueError:
        return v


def condition_holds(when, value_of):
    """True / False when every part can be evaluated; None when a part is prose."""
    if when.strip() == 'always':
        return True
    result = True
    for part in [p.strip() for p in when.split(',')]:
        flag = re.match(r'^`~([\w/]+)`$', part)
        positive = re.match(r'^`~([\w/]+) > 0`$', part)
        if flag:
            result = result and value_of(flag.group(1)) is True
        elif positive:
            v = value_of(positive.group(1))
            result = result and not isinstance(v, bool) and isinstance(v, (int, float)) and v > 0
        else:
            return None
    return result


def source_params():
    """Private parameters read in the node's sources (string literals given to the private handle)."""
    found = set()
    call = re.compile(r'(?:readTypedParam\(\s*pnh_?\s*,\s*|pnh_?\.(?:param|getParam|hasParam)\(\s*)"([^"]+)"')
    for f in sorted(os.listdir(NODE_SOURCES)):
        if f.endswith(('.cpp', '.h')):
            with open(os.path.join(NODE_SOURCES, f)) as fh:
                found.update(call.findall(fh.read()))
    return found


class RosApiDoc(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_ros_api_doc')
        cls.node = rospy.get_param('~node', '/simulator')
        cls.robots = rospy.get_param('~robots')
        with open(DOC) as f:
            cls.doc, cls.params = parse_doc(f.read())
        cls.master = rosgraph.Master('/test_ros_api_doc')
        # The node is complete when its last service is up and its registrations stop changing.
        deadline = time.monotonic() + 60
        last, stable_since = None, time.monotonic()
        while time.monotonic() < deadline:
            now = cls.advertised()
            if now != last:
                last, stable_since = now, time.monotonic()
            elif '/sim/set_ambient_light' in now['srv'] and time.monotonic() - stable_since > 2.0:
                break
            time.sleep(0.2)
        cls.seen = last
        if not last or '/sim/set_ambient_light' not in last['srv']:
            raise AssertionError('%s did not advertise its services within 60 s: %s' % (cls.node, last))
        cls.types = dict(cls.master.getTopicTypes())

    @classmethod
    def advertised(cls):
        pubs, subs, srvs = cls.master.getSystemState()
        mine = lambda entries: {name for name, nodes in entries if cls.node in nodes}
        return {'pub': mine(pubs), 'sub': mine(subs), 'srv': mine(srvs)}

    def value_of(self, param):
        full = self.node + '/' + param
        if rospy.has_param(full):
            return rospy.get_param(full)
        return literal(self.params.get(param))

    def test_every_advertised_name_is_documented(self):
        for kind, heading in TABLES.items():
            pats = [pattern(r['name']) for r in self.doc[kind]]
            missing = sorted(n for n in self.seen[kind] if not any(p.match(n) for p in pats))
            self.assertEqual(missing, [], '%s advertises these %s, which %s does not list under "%s"'
                             % (self.node, kind, DOC, heading))

    def test_every_documented_name_is_advertised_when_its_condition_holds(self):
        self.assertTrue(self.robots, 'the test needs ~robots')
        for kind, heading in TABLES.items():
            for row in self.doc[kind]:
                holds = condition_holds(row['when'], self.value_of)
                if not holds:
                    continue
                for robot in (self.robots if '<robot>' in row['name'] else [None]):
                    p = pattern(row['name'], robot)
                    self.assertTrue(any(p.match(n) for n in self.seen[kind]),
                                    '%s, "%s": %s (advertised: %s) is not among %s\'s %s%s'
                                    % (DOC, heading, row['name'], row['when'], self.node, kind,
                                       ' for robot %s' % robot if robot else ''))

    def test_published_types_are_the_documented_ones(self):
        for row in self.doc['pub']:
            p = pattern(row['name'])
            for name in sorted(n for n in self.seen['pub'] if p.match(n)):
                self.assertEqual(self.types.get(name), row['type'],
                                 '%s: %s has type %s on the master, the doc says %s'
                                 % (DOC, name, self.types.get(name), row['type']))

    def test_every_parameter_the_node_reads_is_documented(self):
        documented = set(self.params)
        prefixes = {p.split('<')[0] for p in documented if '<' in p}
        missing = sorted(p for p in source_params()
                         if p not in documented and not any(p == x.rstrip('/') or p.startswith(x) for x in prefixes))
        self.assertEqual(missing, [], '%s reads these private parameters, which %s does not list: %s'
                         % (NODE_SOURCES, DOC, missing))
        self.assertGreater(len(source_params()), 15, 'the source scan found too few parameters')


if __name__ == '__main__':
    import rostest
    rostest.rosrun('swarmbot3d', 'ros_api_doc', RosApiDoc, sys.argv)
