#include "marker_publisher.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <urdf_parser/urdf_parser.h>

#include "sbot_sim/core/terrain.h"

#include "ros_conversions.h"

namespace sbot_node {

namespace {

/// The terrain is re-sent to every subscriber this often [s sim], in case a display was reset.
constexpr double kTerrainRefresh = 5.0;
/// The height map is drawn with at most this many cells per side.
constexpr int kMaxHeightMapCells = 100;
constexpr double kTrailWidth = 0.008;  // [m]

std_msgs::ColorRGBA rgba(double r, double g, double b, double a = 1.0) {
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(r);
  c.g = static_cast<float>(g);
  c.b = static_cast<float>(b);
  c.a = static_cast<float>(a);
  return c;
}

/// A saturated colour of hue h in [0, 1).
std_msgs::ColorRGBA hue(double h, double a = 1.0) {
  h = 6.0 * (h - std::floor(h));
  const double x = 1.0 - std::fabs(std::fmod(h, 2.0) - 1.0);
  const int sector = static_cast<int>(h);
  const double v[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
  const double* c = v[std::min(sector, 5)];
  return rgba(0.15 + 0.85 * c[0], 0.15 + 0.85 * c[1], 0.15 + 0.85 * c[2], a);
}

/// Well separated hues for consecutive robot indices (golden-ratio sequence).
std_msgs::ColorRGBA robotColour(int index, double a = 1.0) { return hue(0.61803398875 * index + 0.05, a); }

visualization_msgs::Marker makeMarker(const std::string& frame, const ros::Time& stamp, const std::string& ns,
                                      int id, int type) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.frame_locked = false;
  return m;
}

}  // namespace

MarkerPublisher::MarkerPublisher(ros::NodeHandle nh, ros::NodeHandle pnh) {
  pnh.param("marker_rate", rate_, 10.0);
  pnh.param("trail_length", trail_length_, 200);
  if (!std::isfinite(rate_) || rate_ < 0) {
    ROS_WARN("simulator: ~marker_rate must be >= 0 Hz (0 disables /sim/markers), got %g: using 10", rate_);
    rate_ = 10;
  }
  if (trail_length_ < 0) {
    ROS_WARN("simulator: ~trail_length must be >= 0, got %d: using 200", trail_length_);
    trail_length_ = 200;
  }
  if (!enabled()) return;
  ros::NodeHandle sim(nh, "sim");
  pub_ = sim.advertise<visualization_msgs::MarkerArray>(
      "markers", 2, [this](const ros::SingleSubscriberPublisher& p) { onConnect(p); },
      ros::SubscriberStatusCallback());
}

std::size_t MarkerPublisher::trailPoints(const std::string& robot) const {
  auto it = trails_.find(robot);
  return it == trails_.end() ? 0 : it->second.points.size();
}

void MarkerPublisher::update(sbot::World& world, double sim_time) {
  if (!enabled()) return;
  const auto tick = static_cast<std::int64_t>(std::floor(sim_time * rate_ + 1e-6));
  if (tick == last_tick_) return;
  last_tick_ = tick;
  last_stamp_ = ros::Time(sim_time);

  if (trail_length_ > 0) {
    for (sbot::Robot* r : world.robots()) {
      Trail& trail = trails_[r->name()];
      trail.index = r->index();
      trail.points.push_back(toPoint(r->basePose().position));
      while (static_cast<int>(trail.points.size()) > trail_length_) trail.points.pop_front();
    }
  }
  terrain(world);  // built once, for the connect callback
  if (pub_.getNumSubscribers() == 0) return;
  const bool with_terrain = sim_time - last_terrain_time_ >= kTerrainRefresh - 1e-9;
  if (with_terrain) last_terrain_time_ = sim_time;
  pub_.publish(build(world, last_stamp_, with_terrain));
}

void MarkerPublisher::onConnect(const ros::SingleSubscriberPublisher& pub) {
  // The terrain is static: send it once to the newcomer (the periodic array carries the robots).
  if (!terrain_built_ || terrain_.markers.empty()) return;
  visualization_msgs::MarkerArray msg = terrain_;
  for (auto& m : msg.markers) m.header.stamp = last_stamp_;
  pub.publish(msg);
}

const std::map<std::string, std_msgs::ColorRGBA>& MarkerPublisher::linkColours(const sbot::RobotDescription& d) {
  const std::string key = d.urdf_path + "|" + d.level;
  auto found = colours_.find(key);
  if (found != colours_.end()) return found->second;
  std::map<std::string, std_msgs::ColorRGBA>& colours = colours_[key];
  try {
    urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(d.urdf_xml);
    if (model) {
      for (const auto& entry : model->links_) {
        const urdf::LinkSharedPtr& link = entry.second;
        if (!link) continue;
        std::vector<urdf::VisualSharedPtr> visuals = link->visual_array;
        if (visuals.empty() && link->visual) visuals.push_back(link->visual);
        for (const auto& v : visuals) {
          if (v && v->material) {
            const urdf::Color& c = v->material->color;
            colours[entry.first] = rgba(c.r, c.g, c.b, c.a);
            break;
          }
        }
      }
    }
  } catch (const std::exception& e) {
    ROS_WARN("simulator: /sim/markers: cannot read the visual materials of %s: %s", d.urdf_path.c_str(), e.what());
  }
  return colours;
}

visualization_msgs::MarkerArray MarkerPublisher::build(sbot::World& world, const ros::Time& stamp,
                                                       bool with_terrain) {
  visualization_msgs::MarkerArray msg;
  if (with_terrain) {
    msg.markers = terrain(world).markers;
    for (auto& m : msg.markers) m.header.stamp = stamp;
  }
  const std_msgs::ColorRGBA fallback = rgba(0.5, 0.5, 0.5);
  for (sbot::Robot* r : world.robots()) {
    const sbot::RobotDescription& d = r->description();
    const auto& colours = linkColours(d);
    const std::string ns = r->name() + "/model";
    int id = 0;
    for (const sbot::LinkDescription& link : d.links) {
      if (link.collisions.empty() || !r->hasLink(link.name)) continue;
      const sbot::Pose link_pose = r->linkPose(link.name);
      auto colour = colours.find(link.name);
      for (const sbot::CollisionShape& shape : link.collisions) {
        int type = visualization_msgs::Marker::SPHERE;
        sbot::Vec3 scale = sbot::Vec3::Zero();
        switch (shape.type) {
          case sbot::CollisionShape::Type::Sphere:
            scale = sbot::Vec3::Constant(2 * shape.radius);
            break;
          case sbot::CollisionShape::Type::Cylinder:  // along local z in URDF, ODE and rviz alike
            type = visualization_msgs::Marker::CYLINDER;
            scale = sbot::Vec3(2 * shape.radius, 2 * shape.radius, shape.length);
            break;
          case sbot::CollisionShape::Type::Box:
            type = visualization_msgs::Marker::CUBE;
            scale = shape.size;
            break;
        }
        visualization_msgs::Marker m = makeMarker(frame_, stamp, ns, id++, type);
        m.pose = toPose(link_pose * shape.origin);
        m.scale.x = scale.x();
        m.scale.y = scale.y();
        m.scale.z = scale.z();
        m.color = colour != colours.end() ? colour->second : fallback;
        msg.markers.push_back(m);
      }
    }
    auto trail = trails_.find(r->name());
    if (trail != trails_.end() && trail->second.points.size() >= 2) {
      visualization_msgs::Marker m =
          makeMarker(frame_, stamp, r->name() + "/trail", 0, visualization_msgs::Marker::LINE_STRIP);
      m.scale.x = kTrailWidth;
      m.scale.y = m.scale.z = 0;
      m.color = robotColour(trail->second.index, 0.9);
      m.points.assign(trail->second.points.begin(), trail->second.points.end());
      msg.markers.push_back(m);
    }
  }
  return msg;
}

const visualization_msgs::MarkerArray& MarkerPublisher::terrain(const sbot::World& world) {
  if (terrain_built_) return terrain_;
  terrain_built_ = true;
  const ros::Time stamp = last_stamp_;
  const sbot::TerrainConfig& t = world.config().terrain;
  int id = 0;
  for (const sbot::BoxObstacle& box : t.boxes) {
    visualization_msgs::Marker m = makeMarker(frame_, stamp, "terrain/boxes", id++, visualization_msgs::Marker::CUBE);
    m.pose = toPose(sbot::Pose(box.center, sbot::quatFromRPY(0, box.pitch, box.yaw)));
    m.scale.x = box.size.x();
    m.scale.y = box.size.y();
    m.scale.z = box.size.z();
    m.color = box.surface == "wall" ? rgba(0.55, 0.45, 0.35, 0.8) : rgba(0.6, 0.6, 0.55, 0.9);
    terrain_.markers.push_back(m);
  }
  if (t.type == sbot::TerrainConfig::Type::Rough) {
    try {
      const sbot::HeightMap map = sbot::makeHeightMap(t);
      const double lo = map.heights.empty() ? 0 : *std::min_element(map.heights.begin(), map.heights.end());
      const double hi = map.heights.empty() ? 0 : *std::max_element(map.heights.begin(), map.heights.end());
      const int nx = std::max(1, std::min(kMaxHeightMapCells, map.cols - 1));
      const int ny = std::max(1, std::min(kMaxHeightMapCells, map.rows - 1));
      const double x0 = -map.size_x / 2, y0 = -map.size_y / 2;
      const double dx = map.size_x / nx, dy = map.size_y / ny;
      // Sample just inside the edges: HeightMap::at is 0 outside the map.
      const double eps = 1e-9;
      auto vertex = [&](int i, int j) {
        const double x = std::min(std::max(x0 + i * dx, x0 + eps), -x0 - eps);
        const double y = std::min(std::max(y0 + j * dy, y0 + eps), -y0 - eps);
        return sbot::Vec3(x, y, map.at(x, y));
      };
      auto shade = [&](double z) {
        const double s = hi > lo ? (z - lo) / (hi - lo) : 0.5;
        return rgba(0.35 + 0.45 * s, 0.3 + 0.4 * s, 0.22 + 0.3 * s);
      };
      visualization_msgs::Marker m =
          makeMarker(frame_, stamp, "terrain/heightmap", 0, visualization_msgs::Marker::TRIANGLE_LIST);
      m.color = rgba(1, 1, 1);
      m.points.reserve(static_cast<std::size_t>(nx) * ny * 6);
      m.colors.reserve(m.points.capacity());
      for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
          const sbot::Vec3 a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
          for (const sbot::Vec3* v : {&a, &b, &c, &a, &c, &d}) {  // counter-clockwise seen from above
            m.points.push_back(toPoint(*v));
            m.colors.push_back(shade(v->z()));
          }
        }
      }
      terrain_.markers.push_back(m);
    } catch (const std::exception& e) {
      ROS_WARN("simulator: /sim/markers: cannot build the height map markers: %s", e.what());
    }
  }
  return terrain_;
}

}  // namespace sbot_node
