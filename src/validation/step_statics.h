// Statics of a robot reversing onto a step (Table 4.3, backward), in the side view of one track.
//
// Reversing, the rear and then the centre wheels climb the step; the robot then stands nose down on
// its centre wheels (on the step) and its front wheels (on the floor). When the front wheel reaches
// the step's face, its support moves from its bottom to the step's corner, sqrt(r^2 - (r - h)^2)
// behind its axle, and the robot tips forward onto its gripper unless its centre of mass lies behind
// that corner. The trials follow this within ~1 mm (report, Table 4.3), so it says which centre of
// mass a measured backward-step limit implies. Rigid bodies; no drive, no compliance.
//
// Coordinates: the robot's x forward, z up, relative to the centre axle, at zero pitch [m].
#pragma once

namespace sbot {
namespace validation {

struct SideView {
  double centre_radius = 0;  ///< [m] centre wheel
  double front_radius = 0;   ///< [m] front wheel
  double front_axle_x = 0;   ///< [m] front axle ahead of the centre axle (> 0)
  double front_axle_z = 0;   ///< [m] front axle above the centre axle (< 0: below)
  double com_x = 0;          ///< [m] centre of mass ahead of the centre axle
  double com_z = 0;          ///< [m] centre of mass above the centre axle
};

/// Nose-down pitch [rad] with the centre wheel on a step `h` [m] high and the front wheel on the floor.
double pitchOnStep(const SideView& s, double h);

/// How far [m] the step's corner lies ahead of the centre of mass (horizontally) when the front wheel
/// touches the corner of a step `h` [m] high; > 0: the robot rests on the corner and stays upright.
double cornerMargin(const SideView& s, double h);

/// The lowest step [m] (in [0, front_radius)) on which the robot tips over the corner; front_radius
/// when it tips on none.
double cornerTipHeight(const SideView& s);

/// The centre of mass ahead of the centre axle [m] (at the height s.com_z) at which the robot starts
/// to tip on a step `h` [m] high.
double comXForCornerTip(SideView s, double h);

/// The height of the centre of mass above the centre axle [m] (at its ahead offset s.com_x) at which
/// the robot starts to tip on a step `h` [m] high: the other way to move it behind the corner.
double comZForCornerTip(SideView s, double h);

/// Static tipping angle [rad] on a slope, facing downhill, over the front wheel's contact.
double frontTipSlope(const SideView& s);

}  // namespace validation
}  // namespace sbot
