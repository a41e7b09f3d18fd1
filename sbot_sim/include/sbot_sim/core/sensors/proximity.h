// IR proximity sensors (seed 2.2.6, Table 2.8; sbot.h getProximitySensor / getAllProximitySensors).
//
// 15 sensors, frames ir_0..ir_14 on the turret (numbering and placement: sbot_parameters.yaml),
// sensing along the frame's +x. Reading: unsigned in [0, 8191].
//
// Response (distance -> reading). The seed gives two calibrations that disagree:
//   * its log-log regression y = exp(a + b ln x), a = 8.44352, b = -0.777545 (eq. 2.4/2.5), fitted
//     to 33 bench measurements; with x in mm it gives 94 / 222 / 775 / 1329 at 150 / 50 / 10 / 5 mm
//     (+372 %, +344 %, -22 %, -64 % against the API), with x in cm 566 / 1329 / 4645 / 7962
//     (+2728 %, +2558 %, +364 %, +115 %);
//   * the s-bot API's documented hardware points (sbot.h, 2.2.6): 15 cm -> 20, 5 cm -> 50,
//     1 cm -> 1000, 0.5 cm -> 3700.
// A single power law cannot pass through the API points (their log-log slope is -0.83 between 15
// and 5 cm but -1.86 / -1.89 below 5 cm), and the API points are what controllers written for the
// real robot rely on. We therefore use PIECEWISE LOG-LOG INTERPOLATION THROUGH THE FOUR API POINTS
// (LogLogResponse, proximityResponse()): exact (0 % error) at the four points, extrapolated with
// the end segments' slopes: below 0.5 cm with slope -1.888 (saturates at 8191 at 3.3 mm; the
// minimum sensing distance 0.2 cm, Table 2.8, reads 8191), above 15 cm with slope -0.834 (20 cm ->
// 15.7); beyond the 20 cm maximum sensing distance nothing is detected (0).
//
// Models (chosen per level by the sidecar `extra: ir_model`):
//   * raytrace (Basic / Medium / Detailed, 2.2.6 item 2): per sensor 5 rays, one central ray along
//     +x and 4 peripheral rays on a cone (Table 2.8 "ray-tracing cone angle 30 deg", which we read
//     as the cone's full apex angle, i.e. 15 deg off axis, narrower than the ~40 deg sensitivity
//     field as the seed describes to shrink the dead spot). The peripheral rays lie on the
//     diagonals (45, 135, 225, 315 deg about the axis): a downward ray is then 10.6 deg below the
//     horizon and reaches the floor only 29 cm away from a sensor 5.4 cm high, beyond the 20 cm
//     range even when the robot pitches by a few degrees (with a "+" pattern the floor would be at
//     20.9 cm). Rays ignore the sensor's own robot and see every other body (robots, walls,
//     obstacles, terrain). Distances below 0.2 cm count as 0.2 cm. The raw value is the MEAN
//     DISTANCE OF THE RAYS THAT HIT (2.2.6 "compute an average distance value") [m].
//   * lut (Fast / Simple, 2.2.6 item 1): a sample-based look-up table of readings against the
//     relative position (gap, bearing) of OTHER S-BOTS in 2D (no walls, obstacles or shadowing, as
//     the seed says). The table (sbot_description/config/ir_lut.yaml) was sampled with the
//     ray-traced model above against a Simple s-bot, averaged over 16 headings of the target; see
//     IrLookupTable. Against an s-bot the ray-traced readings beyond ~3 cm are lower than against a
//     flat wall (-19 % at 5 cm): the two lower rays pass under the neighbour's turret. When several
//     s-bots are in view the largest reading wins. The table's reading is converted back to an
//     equivalent distance (response().distance, may exceed 20 cm for weak readings) as raw value.
//
// Noise (Table 2.8, 2.2.6 "uniform noise of 10 % has been added to the distance measurements"):
// d' = d (1 + U(-0.1, 0.1)) drawn from the robot's stream "ir", applied AFTER the world effects
// (effects act on the noise-free physical distance; the noise belongs to the sensor electronics).
// A 10 % distance error is about +-19 % in reading below 5 cm (slope -1.9). The reading is
// round(response.signal(d')), clamped to [0, 8191]; the 20 cm cut applies to detection only, not
// after effects/noise (a wall at 19.5 cm with +10 % noise reads ~15, not 0). A sensor that detects
// nothing reads 0 and neither calls the effects nor draws noise.
// The SensorSample passed to the effects: channel "ir", index = sensor, value = distance [m],
// surface and incidence of the nearest ray hit (ray-traced; "robot" and 0 for the table).
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "sbot_sim/core/link_ref.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/world.h"

namespace sbot {

class Robot;

namespace sensors {

constexpr int kProximitySensors = 15;

/// Ray bundle of one IR sensor (Tables 2.8 / 2.9).
struct IrRayModel {
  double range_min = 0.002;        ///< [m] Table 2.8
  double range_max = 0.20;         ///< [m] Table 2.8
  double cone_angle = 0.52359878;  ///< [rad] full apex angle of the ray cone, Table 2.8 (30 deg)
  int rays = 5;                    ///< Table 2.8
  double pattern_azimuth = M_PI / 4;  ///< azimuth of the first peripheral ray about the axis [rad]
  std::vector<Vec3> directions() const;  ///< in the sensor frame
};

/// The proximity model of a level from its sidecar `extra` (ir_range_min_m, ir_range_max_m,
/// ir_cone_angle_rad, ir_rays); Table 2.8 values where absent.
IrRayModel proximityRayModel(const RobotDescription& d);
/// Reading against distance through the API points (see file comment). Range from `model`.
LogLogResponse proximityResponse(const IrRayModel& model = IrRayModel());

/// Result of casting one sensor's ray bundle.
struct BundleHit {
  int hits = 0;                   ///< rays that hit something within range
  double mean_distance = 0;       ///< [m] mean of the hit distances (each at least range_min); inf if none
  RayHit nearest;                 ///< the nearest hit (surface, normal, robot)
  double incidence = 0;           ///< [rad] angle between the nearest hit's ray and the surface normal
};
/// Cast `directions` (sensor frame) from `sensor` (world pose), rays of length range_max,
/// ignoring `ignore` (may be null).
BundleHit traceBundle(const World& world, const Pose& sensor, const std::vector<Vec3>& directions,
                      double range_min, double range_max, const Robot* ignore);
/// traceBundle for several sensors with the same cone at once (a ring): one search of the spaces
/// (World::castRayBundles), the same results as traceBundle per sensor.
std::vector<BundleHit> traceBundles(const World& world, const std::vector<Pose>& sensors,
                                    const std::vector<Vec3>& directions, double range_min, double range_max,
                                    const Robot* ignore);

/// Horizontal radius [m] of a level's turret (the widest part, which IR sensors see): the largest
/// xy extent of the `turret` link's collision shapes; 0.057 if the link has none.
double turretRadius(const RobotDescription& d);

/// The sample-based IR table (2.2.6 item 1): noise-free reading [API units] of a sensor against a
/// neighbouring s-bot, as a function of
///   gap     = (horizontal distance from the sensor origin to the neighbour's turret axis) minus the
///             neighbour's turret radius [m]  (rows), and
///   bearing = |angle of the neighbour's axis from the sensor's +x| in the horizontal plane [rad]
///             (columns; the table is symmetric, the ray pattern and the heading-average are).
/// Bilinear interpolation; 0 outside the table (gap beyond the last row, bearing beyond the last
/// column); gaps below 0 (interpenetration) use the first row. Neighbours of another size (Fast
/// s-bots are half size) are looked up at their own gap, i.e. treated as the sampled s-bot at the
/// same surface distance (a documented approximation: the angular width differs).
class IrLookupTable {
 public:
  std::vector<double> gaps;       ///< [m], increasing, rows
  std::vector<double> bearings;   ///< [rad], increasing from 0, columns
  std::vector<std::vector<double>> readings;  ///< [row][column]
  std::string target_level;       ///< the level sampled as the neighbour
  double target_radius = 0.057;   ///< [m] its turret radius
  double sensor_height = 0;       ///< [m] height of the sensor above the neighbour's ground
  int target_yaws = 16;           ///< neighbour headings averaged per sample
  IrRayModel model;               ///< ray model used to sample

  double lookup(double gap, double bearing) const;
  /// Write as YAML (with a header explaining the format and how to regenerate).
  void save(const std::string& path) const;
  /// Read a table written by save(). Throws ConfigError naming the file and field.
  static IrLookupTable load(const std::string& path);
};

/// Sample the table: a neighbour of `target` level at the origin (world without ground plane, so
/// only the s-bot is seen), a virtual sensor at the target level's IR height, pointing along +x,
/// placed at each (gap, bearing); the reading is proximityResponse(mean hit distance) without noise,
/// averaged over `yaws` evenly spaced neighbour headings (misses count as 0).
IrLookupTable generateIrLookupTable(const RobotDescription& target, const std::vector<double>& gaps,
                                    const std::vector<double>& bearings, int yaws = 16,
                                    const IrRayModel& model = IrRayModel());
/// The grid used for sbot_description/config/ir_lut.yaml: gaps 0.1..20 cm, dense near 0 (35 rows);
/// bearings 0..90 deg every 2.5 deg (37 columns).
std::vector<double> defaultLutGaps();
std::vector<double> defaultLutBearings();
/// Path of the shipped table: descriptionDirectory() + "/config/ir_lut.yaml".
std::string defaultIrLookupTablePath();
/// The shipped table, loaded once per process (thread-safe). Throws ConfigError if missing.
const IrLookupTable& defaultIrLookupTable();

class ProximitySensors {
 public:
  enum class Model { RayTraced, LookupTable };
  /// `lut` is required for Model::LookupTable (and must outlive this object).
  ProximitySensors(World& world, Robot& robot, Model model, const IrLookupTable* lut = nullptr);

  /// getAllProximitySensors: all 15 readings [0,8191] (noisy).
  std::array<unsigned, kProximitySensors> readAll();
  /// getProximitySensor(sensor): one reading [0,8191]; throws std::out_of_range outside [0,14].
  unsigned read(int sensor);
  /// Noise-free, effect-free raw distance [m] the sensor sees (inf if nothing). For tests/tools.
  double rawDistance(int sensor) const;

  Model model() const { return model_; }
  const LogLogResponse& response() const { return response_; }
  const IrRayModel& rayModel() const { return ray_model_; }

 private:
  struct Raw {
    double distance;  // inf if nothing
    std::string surface;
    double incidence;
  };
  Raw raw(int sensor) const;
  static Raw rawOf(const BundleHit& hit);
  Raw rawLut(int sensor) const;
  unsigned finish(int sensor, const Raw& raw);

  World& world_;
  Robot& robot_;
  Model model_;
  const IrLookupTable* lut_;
  IrRayModel ray_model_;
  std::vector<Vec3> directions_;
  LogLogResponse response_;
  double noise_;
  std::array<LinkRef, kProximitySensors> links_;
};

}  // namespace sensors
}  // namespace sbot
