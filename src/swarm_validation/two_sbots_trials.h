// Trials of the two-connected-s-bot validation rows (two_sbots tool, its gtest): seed Table 4.1
// (two s-bots connected by the front gripper on a slope) and 4.1.3 (two-robot step passing going
// backwards). See two_sbots.cpp.
#pragma once

#include <string>
#include <vector>

namespace two_sbots {

struct SlopeResult {
  std::string label;       ///< full, difficult, slide, topple, "stable, slides back when driving"
  double slide = 0;        ///< [m] down the slope while standing 3 s
  double efficiency = 0;   ///< climb progress / commanded over 8 s at 2.8 cm/s
  double max_tilt = 0;     ///< [rad]
};

/// How the slope trial is set up besides level, angle and trial. The defaults are the tallied rows.
struct SlopeSetup {
  bool pair = true;            ///< two s-bots connected by sbot_1's front gripper; false: sbot_1 alone
  /// The seed's own set-up for this experiment (4.1.1: "ground friction ... set to ... 1.2 N"), i.e.
  /// ODE box friction with a force limit of 1.2 N per contact point, instead of Coulomb treels.
  bool seed_friction = false;
  /// false: both robots face uphill (front first) and the holder below grips the robot above it.
  /// true: both face downhill and climb in reverse (the single s-bot's matching orientation of
  /// Table 4.1, rear uphill); the holder is then above, gripping the robot below it.
  bool rear_uphill = false;
  /// > 0: Coulomb coefficient of the treels on the slope; 0: Table 4.1's polystyrene
  /// (validation::kPolystyreneTrackMu).
  double track_mu = 0;
};

/// One s-bot or two connected s-bots on a slope of `angle` [rad] (tilted gravity): stand 3 s with
/// the motors holding, then climb 8 s at 2.8 cm/s.
SlopeResult pairSlope(const std::string& level, double angle, int trial, const SlopeSetup& setup = {});

/// The Table 4.1 pair rows' limits [deg], from the modal label of the trials at each slope
/// (`deg` ascending, `modal_labels` parallel to it). One rule for the two_sbots tool and sbot_validate.
struct SlopeLimits {
  double full = 0;     ///< steepest slope up to which every modal label is "full" (full manoeuvrability)
  double hold = 0;     ///< steepest slope up to which it neither slides nor topples
  double upright = 0;  ///< steepest slope before the first modal "topple" (limit of stable position)
  double topple = 0;   ///< first slope whose modal label is "topple"; 0: none in the list
};
SlopeLimits slopeLimits(const std::vector<double>& deg, const std::vector<std::string>& modal_labels);

struct StepResult {
  std::string label;  ///< pass, fail, topple
  double x_holder = 0, z_holder = 0, x_held = 0, z_held = 0;
};

/// Reverse up a step `h` [m] high: one s-bot, or a pair whose holder lifts itself with its arm.
StepResult stepBackward(const std::string& level, double h, int trial, bool pair, bool verbose);

}  // namespace two_sbots
