#!/usr/bin/env python3
"""Print a level's URDF with every link name prefixed, e.g. `prefixed_urdf.py simple sbot_3/`.

robot_state_publisher 1.15 (Debian 12) has no tf_prefix, so each robot of a swarm gets its own copy
of the URDF whose frames are `sbot_<i>/base_link`, `sbot_<i>/turret`, ...
"""
import os
import sys
import xml.etree.ElementTree as ET


def prefixed(urdf_path, prefix):
    tree = ET.parse(urdf_path)
    root = tree.getroot()
    for link in root.iter('link'):
        link.set('name', prefix + link.get('name'))
    for joint in root.iter('joint'):
        for tag in ('parent', 'child'):
            element = joint.find(tag)
            element.set('link', prefix + element.get('link'))
    return ET.tostring(root, encoding='unicode')


def main(argv):
    if len(argv) != 3:
        sys.stderr.write('usage: prefixed_urdf.py LEVEL PREFIX\n')
        return 2
    level, prefix = argv[1], argv[2]
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'urdf', level + '.urdf')
    if not os.path.exists(path):
        sys.stderr.write('prefixed_urdf.py: no URDF for level %r (%s)\n' % (level, path))
        return 1
    sys.stdout.write(prefixed(path, prefix))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
