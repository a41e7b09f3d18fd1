// What diagnose.cpp shares with diagnose_stepwise.cpp (not part of the calibration's API).
#pragma once

#include <string>

namespace sbot::calib::detail {

/// `v` with `prec` significant digits (std::setprecision), as the verdicts print numbers.
std::string fmt(double v, int prec = 4);

}  // namespace sbot::calib::detail
