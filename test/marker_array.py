"""Decodes a visualization_msgs/MarkerArray from its serialised bytes (rospy.AnyMsg's _buff).

Debian 12 packages visualization_msgs for C++ only, so Python tests cannot import its message
classes; the layout below is /usr/share/visualization_msgs/msg/Marker.msg's, field by field."""
import struct


class Marker(object):
    """The fields the tests read: ns, id, type, pose position, scale, points."""

    def __init__(self):
        self.ns, self.id, self.type, self.frame_id = '', 0, 0, ''
        self.position = (0.0, 0.0, 0.0)
        self.orientation = (0.0, 0.0, 0.0, 1.0)
        self.scale = (0.0, 0.0, 0.0)
        self.points = []


class _Reader(object):
    def __init__(self, buff):
        self.buff, self.at = buff, 0

    def take(self, fmt):
        values = struct.unpack_from('<' + fmt, self.buff, self.at)
        self.at += struct.calcsize('<' + fmt)
        return values

    def string(self):
        (n,) = self.take('I')
        text = self.buff[self.at:self.at + n].decode('utf-8')
        self.at += n
        return text


def decode(buff):
    """The markers of one serialised MarkerArray, in order."""
    r = _Reader(buff)
    (count,) = r.take('I')
    markers = []
    for _ in range(count):
        m = Marker()
        r.take('III')                      # header.seq, header.stamp
        m.frame_id = r.string()
        m.ns = r.string()
        m.id, m.type, _action = r.take('iii')
        m.position = r.take('ddd')
        m.orientation = r.take('dddd')
        m.scale = r.take('ddd')
        r.take('ffff')                     # color
        r.take('ii')                       # lifetime
        r.take('B')                        # frame_locked
        (n,) = r.take('I')
        flat = r.take('%dd' % (3 * n)) if n else ()
        m.points = [flat[3 * i:3 * i + 3] for i in range(n)]
        (n,) = r.take('I')
        r.take('%df' % (4 * n)) if n else None  # colors
        r.string()                         # text
        r.string()                         # mesh_resource
        r.take('B')                        # mesh_use_embedded_materials
        markers.append(m)
    if r.at != len(buff):
        raise ValueError('MarkerArray of %d bytes: %d left after %d markers' % (len(buff), len(buff) - r.at, count))
    return markers
