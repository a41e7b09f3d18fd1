#!/usr/bin/env python3
"""Summarise a swarm rosbag: topics, message counts, simulated duration, per-robot distance.

    rosrun swarmbot3d bag_summary.py BAG [--require-topic T ...]

Exits 1 if the bag cannot be opened or lacks a required topic (default: /clock, /tf and every
robot's ground_truth), so it doubles as a check of a recording.
"""
import argparse
import math
import re
import sys

import rosbag


def summarise(path):
    bag = rosbag.Bag(path)
    info = bag.get_type_and_topic_info()
    topics = {name: (t.msg_type, t.message_count) for name, t in info.topics.items()}
    robots = sorted({m.group(1) for m in (re.match(r'^/(sbot_\d+)/', t) for t in topics) if m},
                    key=lambda r: int(r.split('_')[1]))
    travelled = {r: 0.0 for r in robots}
    last = {}
    first_stamp = last_stamp = None
    # read_messages() with no matching topic would return every message: ask only for present ones.
    wanted = [t for t in ('/%s/ground_truth' % r for r in robots) if t in topics]
    for topic, msg, _ in (bag.read_messages(topics=wanted) if wanted else []):
        robot = topic.split('/')[1]
        p = msg.pose.pose.position
        if robot in last:
            travelled[robot] += math.hypot(p.x - last[robot][0], p.y - last[robot][1])
        last[robot] = (p.x, p.y)
        stamp = msg.header.stamp.to_sec()
        first_stamp = stamp if first_stamp is None else min(first_stamp, stamp)
        last_stamp = stamp if last_stamp is None else max(last_stamp, stamp)
    bag.close()
    return topics, robots, travelled, last, (first_stamp, last_stamp)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('bag')
    parser.add_argument('--require-topic', action='append', default=None)
    args = parser.parse_args()
    try:
        topics, robots, travelled, final, (t0, t1) = summarise(args.bag)
    except Exception as error:  # rosbag raises several unrelated types for unreadable files
        # What rosbag's own words leave out for the two commonest cases (a cut-off recording, not a bag).
        hint = {'ROSBagUnindexedException': ' (a recording cut off: `rosbag reindex` repairs it)',
                'UnicodeDecodeError': ' (not a rosbag)'}.get(type(error).__name__, '')
        print('bag_summary: cannot read %s: %s%s' % (args.bag, error, hint), file=sys.stderr)
        return 1
    print('bag: %s' % args.bag)
    print('topics: %d' % len(topics))
    for name in sorted(topics):
        print('  %-40s %-28s %7d msgs' % (name, topics[name][0], topics[name][1]))
    if t0 is not None:
        print('simulated time covered: %.2f s (%.2f .. %.2f)' % (t1 - t0, t0, t1))
    print('robots: %d' % len(robots))
    if robots:
        dist = [travelled[r] for r in robots]
        print('distance travelled per robot [m]: mean %.2f, min %.2f, max %.2f'
              % (sum(dist) / len(dist), min(dist), max(dist)))
        for r in robots[:5]:
            if r in final:
                print('  %-8s travelled %.2f m, final position (%.2f, %.2f)' % (r, travelled[r], final[r][0], final[r][1]))
            else:
                print('  %-8s no ground_truth recorded' % r)
        if len(robots) > 5:
            print('  ... (%d more)' % (len(robots) - 5))
    required = args.require_topic or (['/clock', '/tf'] + ['/%s/ground_truth' % r for r in robots])
    missing = [t for t in required if t not in topics or topics[t][1] == 0]
    if not robots:
        missing.append('/sbot_<i>/ground_truth (no robot topics at all)')
    if missing:
        print('MISSING or empty topics: %s' % ', '.join(missing))
        return 1
    print('all expected topics present')
    return 0


if __name__ == '__main__':
    sys.exit(main())
