// Data attached to every ODE geom (dGeomSetData): who owns it and what it is made of. Lets the
// contact callback and ray casts find the robot and the surface label without map look-ups.
#pragma once

#include <string>

namespace sbot {

class Robot;

struct GeomInfo {
  Robot* robot = nullptr;        ///< null for terrain and obstacles
  std::string material;          ///< contact material / optical surface label
  std::string link;              ///< URDF link (robots) or obstacle name (static geometry)
  bool drive_wheel = false;      ///< on a driven treels wheel (Robot::driveWheelLoad measures its contacts)
  int track = -1;                ///< the driven wheel's track: 0 left, 1 right; -1 for any other geom
};

}  // namespace sbot
