#include "two_sbots_trials.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include "sbot_sim/core/actuators/gripper.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/swarm/swarm_graph.h"
#include "sbot_sim/core/world.h"
#include "experiments.h"  // kToppledTilt, kUprightTilt, applyStudyKnobs

namespace two_sbots {

using namespace sbot;

namespace {

double tiltOf(const Robot& r) {
  const Vec3 up = r.basePose().orientation * Vec3::UnitZ();
  return std::acos(std::max(-1.0, std::min(1.0, up.z())));
}

}  // namespace

SlopeResult pairSlope(const std::string& level, double angle, int trial, const SlopeSetup& setup) {
  WorldConfig c;
  c.seed = 7000 + trial;
  validation::applyStudyKnobs(c);  // the solver study knobs, as sbot_validate (before the surface)
  if (setup.seed_friction) {
    constexpr double kSeedFrictionN = 1.2;  // 4.1.1 / Table 2.13: 12e4 dyne
    c.contact.coulomb = false;
    c.contact.mu = kSeedFrictionN;
    c.contact.material_mu["track"] = kSeedFrictionN;
  } else if (setup.track_mu > 0) {
    c.contact.material_mu["track"] = setup.track_mu;
  } else {
    validation::onPolystyrene(c);
  }
  World w(c);
  const double g = c.gravity;
  w.setGravity(Vec3(-g * std::sin(angle), 0, -g * std::cos(angle)));
  std::mt19937 rng(trial * 131 + static_cast<int>(angle * 1000));
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  const RobotDescription& d = loadLevel(level);
  // Uphill = +x. sbot_1 (holder) grips sbot_0 in front of it: above it facing uphill, below it
  // facing downhill (rear uphill; the pair then climbs in reverse).
  const double facing = setup.rear_uphill ? -1.0 : 1.0;  // +1: fronts uphill
  const double yaw = setup.rear_uphill ? M_PI : 0.0;
  const bool pair = setup.pair;
  w.addRobot(d, {0, 0, yaw + u(rng)}, "sbot_1");
  std::unique_ptr<actuators::FrontGripper> grip;
  if (pair) {
    w.addRobot(d, {facing * 0.3, 0, yaw + u(rng)}, "sbot_0");
    swarm::createStaticLink(w, {"sbot_1", "sbot_0", swarm::kFrontGripper});
    grip = std::make_unique<actuators::FrontGripper>(w, w.robot("sbot_1"));
    grip->setElevation(0);
  }
  std::vector<Robot*> rs = w.robots();
  for (Robot* r : rs) r->setSpeed(0, 0);
  SlopeResult res{"full"};
  bool toppled = false;
  auto run = [&](double seconds) {
    const int n = static_cast<int>(seconds / c.step);
    for (int i = 0; i < n && !toppled; ++i) {
      w.step();
      if (grip) grip->update(c.step);
      for (Robot* r : rs) {
        res.max_tilt = std::max(res.max_tilt, tiltOf(*r));
        if (tiltOf(*r) > sbot::validation::kToppledTilt) toppled = true;
      }
    }
  };
  auto meanX = [&] {
    double x = 0;
    for (Robot* r : rs) x += r->basePose().position.x();
    return x / rs.size();
  };
  run(0.2);
  const double x0 = meanX();
  run(3.0);
  const double x1 = meanX();
  res.slide = x0 - x1;
  const double hold_tilt = res.max_tilt;
  if (!toppled) {
    for (Robot* r : rs) r->setSpeed(facing * 10, facing * 10);
    run(8.0);
    res.efficiency = (meanX() - x1) / (10 * 0.0028 * 8.0);
  }
  if (toppled) res.label = "topple";
  else if (res.slide > 0.01) res.label = "slide";
  else if (res.efficiency < 0 ) res.label = "stable, slides back when driving";
  else if (res.efficiency < 0.85 || res.max_tilt - hold_tilt > 8 * M_PI / 180) res.label = "difficult";
  else res.label = "full";
  return res;
}

// A step of `h` at x <= 0 (plateau toward -x); the robots face +x on the ground and reverse onto it.
StepResult stepBackward(const std::string& level, double h, int trial, bool pair, bool verbose) {
  WorldConfig c;
  c.seed = 8000 + trial;
  c.terrain.type = TerrainConfig::Type::Composite;
  c.terrain.boxes.push_back({"step", Vec3(-1.0, 0, h / 2), Vec3(2.0, 1.0, h), 0, 0, "ground"});
  c.contact.material_mu["track"] = validation::kLabFloorTrackMu;  // Table 4.3's apparatus
  validation::applyStudyKnobs(c);  // the solver study knobs, as sbot_validate
  World w(c);
  std::mt19937 rng(trial * 977 + static_cast<int>(h * 1e4));
  std::uniform_real_distribution<double> u(-1, 1);
  const RobotDescription& d = loadLevel(level);
  w.addRobot(d, {0.09 + 0.005 * u(rng), 0.005 * u(rng), 0.02 * u(rng)}, "sbot_1");
  std::unique_ptr<actuators::FrontGripper> grip;
  if (pair) {
    w.addRobot(d, {0.4, 0, 0}, "sbot_0");
    swarm::createStaticLink(w, {"sbot_1", "sbot_0", swarm::kFrontGripper});
    grip = std::make_unique<actuators::FrontGripper>(w, w.robot("sbot_1"));
    grip->setElevation(0);
  }
  Robot& a = w.robot("sbot_1");
  Robot* b = pair ? &w.robot("sbot_0") : nullptr;
  StepResult res{"fail"};
  bool toppled = false;
  const int speed = -15;
  // [deg] arm up: braced on the held robot's weight, the holder tips forward about its own front
  // wheels and its rear rises onto the step (0.16 N m against the gripper's 0.5; the other way, arm
  // down, would have to lift its front about its rear, ~0.4 N m, and does not move).
  constexpr int kLiftElevation = 20;
  int phase = 0;
  double phase_t = 0;
  const double T = 40.0;
  for (int i = 0; i < static_cast<int>(T / c.step); ++i) {
    const double t = i * c.step;
    const Pose pa = a.basePose();
    if (pair) {
      // Phase 0: reverse to the step. 1: arm up (lifts the holder's rear) while reversing.
      // 2: holder's rear wheels on the step: arm back to level, keep reversing. 3: the held robot at
      // the step: arm up (lifts it) and pull.
      const Pose pb = b->basePose();
      switch (phase) {
        case 0:
          if (pa.position.x() < 0.065 || t > 12) { phase = 1; phase_t = t; grip->setElevation(kLiftElevation); }
          break;
        case 1:
          if (pa.position.z() > h + 0.012 || t - phase_t > 8) { phase = 2; phase_t = t; grip->setElevation(0); }
          break;
        case 2:
          if (pb.position.x() < 0.075 || t - phase_t > 10) { phase = 3; phase_t = t; grip->setElevation(50); }
          break;
        case 3:
          if (pb.position.z() > h + 0.012 && t - phase_t > 1.0) { phase = 4; grip->setElevation(0); }
          break;
        default: break;
      }
      // While the holder lifts itself the held robot stands (motors holding) as the arm's fulcrum.
      a.setSpeed(speed, speed);
      b->setSpeed(phase == 1 ? 0 : speed, phase == 1 ? 0 : speed);
      if (verbose && i % 50 == 0)
        std::printf("  t %.1f phase %d holder x %.3f z %.3f tilt %.0f | held x %.3f z %.3f tilt %.0f | elev %d\n", t,
                    phase, pa.position.x(), pa.position.z(), tiltOf(a) * 180 / M_PI, pb.position.x(), pb.position.z(),
                    tiltOf(*b) * 180 / M_PI, grip->getElevation());
    } else {
      a.setSpeed(speed, speed);
    }
    w.step();
    if (grip) grip->update(c.step);
    // The same toppled and upright tilts as the single-robot tables (validation::kToppledTilt).
    if (tiltOf(a) > validation::kToppledTilt || (b && tiltOf(*b) > validation::kToppledTilt)) {
      toppled = true;
      break;
    }
    auto onTop = [h](const Robot& r) {
      return r.basePose().position.x() < -0.10 && r.basePose().position.z() > h && tiltOf(r) < validation::kUprightTilt;
    };
    const bool a_up = onTop(a);
    const bool b_up = !b || onTop(*b);
    if (a_up && b_up) {
      res.label = "pass";
      break;
    }
  }
  if (toppled) res.label = "topple";
  res.x_holder = a.basePose().position.x();
  res.z_holder = a.basePose().position.z();
  if (b) {
    res.x_held = b->basePose().position.x();
    res.z_held = b->basePose().position.z();
  }
  return res;
}

SlopeLimits slopeLimits(const std::vector<double>& deg, const std::vector<std::string>& modal_labels) {
  SlopeLimits l;
  bool full_run = true, hold_run = true;
  for (std::size_t k = 0; k < deg.size() && k < modal_labels.size(); ++k) {
    const std::string& m = modal_labels[k];
    full_run &= m == "full";
    hold_run &= m != "slide" && m != "topple" && m.find("slides") == std::string::npos;
    if (full_run) l.full = deg[k];
    if (hold_run) l.hold = deg[k];
    if (m == "topple" && l.topple == 0) l.topple = deg[k];
    if (l.topple == 0) l.upright = deg[k];
  }
  return l;
}

}  // namespace two_sbots
